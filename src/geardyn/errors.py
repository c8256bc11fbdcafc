"""Exceptions raised by geardyn, each naming the field or parameter value at fault."""

from __future__ import annotations


class GeardynError(Exception):
    """Base class of every error geardyn raises on purpose."""


class ParameterError(GeardynError, ValueError):
    """A parameter is missing, of the wrong kind or outside its physical range.

    ``field`` is the dotted path of the offending field (``"sun_mesh.mean_stiffness"``) and
    ``value`` the value that was given.
    """

    def __init__(self, field: str, value: object, reason: str):
        self.field = field
        self.value = value
        self.reason = reason
        super().__init__(f"{field}: {reason} (got {value!r})")


class StudyError(GeardynError, ValueError):
    """A study file cannot be read or holds something geardyn does not understand."""


class GeardynWarning(UserWarning):
    """Base class of every warning geardyn issues (filter them by it)."""


class SlowPathWarning(GeardynWarning):
    """A model runs its sweeps on a slower kernel path than it could; the message names what to
    declare for the fast one (once per model class, see
    :func:`geardyn.core.kernel_source.warn_slow_path`)."""


class UnknownParameterError(ParameterError, KeyError):
    """A parameter name that is not known; also a ``KeyError`` (a lookup by name failed)."""

    def __str__(self) -> str:  # KeyError would quote the message
        return Exception.__str__(self)
