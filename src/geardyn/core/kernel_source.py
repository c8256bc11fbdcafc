"""The kernel interface of a model: its compiled functions, as the kernel generator takes them.

:class:`KernelSource` names a model's numba-compiled ``rhs``, ``events`` and ``observe`` (see
:class:`geardyn.core.model.Model` for their arguments); :mod:`geardyn.solvers.kernels` splices
them into the kernel templates. This module belongs to the core: it imports nothing of geardyn
outside :mod:`geardyn.core`.
"""

from __future__ import annotations

import inspect
import sys
from dataclasses import dataclass
from typing import Any

from geardyn.core import _noop
from geardyn.core.one_form import OneForm

__all__ = ["DECLARED_PATHS", "FORM_GENERAL", "FORM_LOAD", "FORM_QUIET", "KERNEL_PATHS",
           "LANE_FORMS", "KernelSource", "events_take_phase", "warn_slow_path"]

#: The lane forms of a model's lane-scalar functions (``rhs_lane(..., form)``): the sweep kernel
#: compiles its fused step loop once per form, with ``form`` a constant there, and runs a queue
#: of lanes in the form ``rhs_lane_form`` gives all of them (else FORM_GENERAL). FORM_GENERAL
#: must serve every lane; the others are a model's specialisations without inner loops or libm
#: calls, which the vectoriser needs (for the reduced CATT device's one form: the load quiet
#: or fluctuating, see :func:`geardyn.core.one_form.loud`). A model may leave any but
#: FORM_GENERAL unused.
FORM_GENERAL, FORM_QUIET, FORM_LOAD = 0, 1, 2
LANE_FORMS = 3

#: How the sweep kernels step a block of lanes, fastest first (:attr:`KernelSource.kernel_path`,
#: a dataset's ``kernel_path`` attribute): ``"lane-form"``, one fused loop over the block with
#: the model's lane-scalar functions (the one form, or ``<rhs>_lane`` twins); ``"lane-block"``,
#: the model's lane-block functions (``<rhs>_lanes``); ``"per-lane"``, its array function one
#: lane at a time (a plain ``rhs(t, y, dydt, p)``: several times slower on a sweep);
#: ``"pointer"``, declared by a one-form model (``KernelSource.path``): a fused block loop
#: compiled once for every model, calling the model's part (its trial step for a block of
#: slots, its split step, its functions; compiled alone) through their addresses
#: (:mod:`geardyn.solvers._pointer_kernels`: seconds of the model's own compile, not tens).
KERNEL_PATHS = ("lane-form", "lane-block", "per-lane", "pointer")
#: The kernel paths a model may declare (``KernelSource.path``).
DECLARED_PATHS = ("pointer",)
_SLOW_WARNED: set[type] = set()


@dataclass(frozen=True)
class KernelSource:
    """A model's compiled functions (numba dispatchers) in the kernel interface."""

    rhs: Any
    events: Any = None
    observe: Any = None
    #: True for a user's ``rhs(t, y, dy, p)`` / ``observe(t, y, out, p)`` without the forcing
    #: phase arguments; the generated kernel adapts them. ``events`` is adapted wherever it
    #: takes ``(t, y, g, p)`` (:func:`events_take_phase`), plain or not.
    plain: bool = False
    #: Set where the functions are in the one form (:mod:`geardyn.core.one_form`):
    #: ``rhs(t, y, p, s, c) -> tuple`` etc.; the generated kernel writes every layout from them.
    one_form: OneForm | None = None
    #: A declared kernel path (one of :data:`DECLARED_PATHS`; a one form without ``quiet``
    #: coefficients only: the pointer path's trial step takes one lane form), else None: the
    #: path follows from the functions (:attr:`kernel_path`).
    path: str | None = None

    def __post_init__(self) -> None:
        if self.path is not None and (self.path not in DECLARED_PATHS or self.one_form is None
                                      or self.one_form.quiet):
            raise ValueError(f"kernel path {self.path!r}: a model in the one form without quiet "
                             f"coefficients may declare {', '.join(map(repr, DECLARED_PATHS))}")

    @property
    def kernel_path(self) -> str:
        """The sweep kernels' path for these functions, one of :data:`KERNEL_PATHS`: the
        declared one (:attr:`path`), else what the generated core module decides from the
        functions it is given."""
        if self.path is not None:
            return self.path
        if self.one_form is not None:
            return "lane-form"
        funcs = self.functions()
        return ("lane-form" if "rhs_lane" in funcs else
                "lane-block" if "rhs_lanes" in funcs else "per-lane")

    def functions(self) -> dict[str, Any]:
        if self.one_form is not None:
            return {f"one_{name}": fn for name, fn in
                    (("rhs", self.rhs), ("events", self.events), ("observe", self.observe))
                    if fn is not None}
        prefix = "user_" if self.plain else ""
        events = self.events if self.events is not None else _noop.no_events
        funcs = {
            f"{prefix}rhs": self.rhs,
            ("events" if events_take_phase(events) else "user_events"): events,
            f"{prefix}observe": (
                self.observe if self.observe is not None
                else (_noop.no_observables_plain if self.plain else _noop.no_observables)
            ),
        }
        if not self.plain and "events" in funcs:
            funcs.update(_lane_functions(funcs))
            funcs.update(_lane_scalar_functions(funcs))
        return funcs


def warn_slow_path(model: Any) -> None:
    """A :class:`~geardyn.errors.SlowPathWarning`, once per model class, where ``model`` runs
    its sweeps on the ``"per-lane"`` path (:data:`KERNEL_PATHS`) because its functions are a
    user's plain ones (``plain``), naming what to declare for the fast one."""
    import warnings

    from geardyn.errors import SlowPathWarning

    kind, source = type(model), getattr(model, "kernel", None)
    if (not isinstance(source, KernelSource) or not source.plain or kind in _SLOW_WARNED
            or source.kernel_path != "per-lane"):
        return
    _SLOW_WARNED.add(kind)
    warnings.warn(f"{model.name} ({kind.__name__}) runs its sweeps one lane at a time (a plain "
                  "rhs(t, y, dydt, p): several times slower); declare it in the one form, "
                  "UserModel.from_one_form(...) (docs/model.md), for the vectorised path",
                  SlowPathWarning, stacklevel=3)


def events_take_phase(events: Any) -> bool:
    """Whether a compiled ``events`` takes the forcing phase, ``events(t, y, g, p, s, c)`` (the
    interface); ``events(t, y, g, p)`` (a model whose switching functions do not depend on the
    forcing) is adapted by the generated kernel."""
    py = getattr(events, "py_func", events)
    return len(inspect.signature(py).parameters) != 4


def _lane_functions(funcs: dict[str, Any]) -> dict[str, Any]:
    """The lane-block forms of a model's functions, where its module defines them: for ``rhs``
    named ``f``, a compiled ``f_lanes`` beside it becomes ``rhs_lanes`` (and so for ``events``
    and ``observe``). The sweep kernel runs them on a block of lanes in structure-of-arrays
    layout (see :mod:`._kernel_template`); without them it calls the per-lane functions."""
    out = {}
    for alias in ("rhs", "events", "observe"):
        py = getattr(funcs[alias], "py_func", None)
        mod = sys.modules.get(getattr(py, "__module__", ""), None)
        fn = getattr(mod, f"{py.__name__}_lanes", None) if py is not None else None
        if fn is not None and hasattr(fn, "py_func"):
            out[f"{alias}_lanes"] = fn
    if out and len(out) < 3:
        return {}  # all three or none: the kernel mixes no layouts
    return out


def _lane_scalar_functions(funcs: dict[str, Any]) -> dict[str, Any]:
    """The lane-scalar forms of a model's functions, where its module defines them: for ``rhs``
    named ``f``, ``f_lane`` (with ``f_lane_form`` and the state size ``f_lane_states``) becomes
    ``rhs_lane`` (``rhs_lane_form``), and so ``events_lane``, ``observe_lane``: lane k of a
    block, state and results as tuples, so that the sweep kernel fuses a grid step of every
    slot into one loop (see :mod:`._kernel_template`). All or none."""
    out = {}
    for alias, suffix in (("rhs", "_lane"), ("events", "_lane"), ("observe", "_lane"),
                          ("rhs", "_lane_form")):
        py = getattr(funcs[alias], "py_func", None)
        mod = sys.modules.get(getattr(py, "__module__", ""), None)
        fn = getattr(mod, f"{py.__name__}{suffix}", None) if py is not None else None
        if fn is not None and hasattr(fn, "py_func"):
            out[f"{alias}{suffix}"] = fn
    return out if len(out) == 4 else {}
