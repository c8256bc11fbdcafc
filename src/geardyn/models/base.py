"""The model interface, kept under its earlier name: :class:`Model` lives in
:mod:`geardyn.core.model` (the core layer), and is re-exported here."""

from geardyn.core.model import Model, unique_rows

__all__ = ["Model", "unique_rows"]
