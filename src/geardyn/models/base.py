"""The model interface's earlier home: :class:`Model` and ``unique_rows`` live in
:mod:`geardyn.core.model`; importing them from here is deprecated (a DeprecationWarning)."""

from geardyn.core.moved import moved

__getattr__ = moved(__name__, {"Model": "geardyn.core.model",
                               "unique_rows": "geardyn.core.model"})
