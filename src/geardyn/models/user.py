"""A user's own model: any numba-compiled right-hand side, through the same solvers and analyses."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from geardyn.core.kernel_source import KernelSource
from geardyn.core.model import Model, unique_rows


class UserModel(Model):
    """Wrap a compiled ``rhs(t, y, dydt, p)`` (writing dydt in place) as a geardyn model.

    Parameters
    ----------
    rhs
        ``numba.njit`` function ``rhs(t, y, dydt, p)``. Define it in an importable module (not
        ``__main__``) and its kernels are cached on disk; otherwise they are compiled once per
        process.
    n_states, params, state_names, param_names
        State size, coefficient vector (passed to ``rhs`` as ``p``) and names.
    period
        Forcing period of a periodically forced model, or None for an autonomous one. When
        ``param_names`` contains ``"Omega"`` the period is 2 pi / Omega instead and sweeps over
        ``"Omega"`` work.
    events
        Optional compiled ``events(t, y, g, p)``: switching functions whose zero crossings are
        kinks of ``rhs`` (e.g. ``x - b`` and ``x + b`` for a dead zone); the solvers locate them.
        ``events(t, y, g, p, s, c)`` takes the forcing phase too (sin and cos, as the solver
        gives it to the built-in models; see :mod:`geardyn.core.model`).
    n_events, observe, observable_names
        Number of switching functions; optional compiled ``observe(t, y, out, p)``.
    natural_frequency
        The fastest natural frequency of the linearised model (rad per time unit), which the
        default step resolves (``STEPS_PER_FASTEST_MODE`` steps per its period): a number, or a
        function of the coefficient vector ``p`` giving it (called once per distinct lane of a
        sweep, so that a sweep over a stiffness refines the step where it is stiffer). Default
        None: unknown, and the default step is ``MIN_STEPS_PER_PERIOD`` per forcing period,
        which is accurate only for modes slower than about Omega / 1.5; give it (or
        ``steps_per_period``) for a stiffer model.
    """

    def __init__(
        self,
        rhs: Callable,
        n_states: int,
        params: Sequence[float] | np.ndarray = (),
        period: float | None = None,
        state_names: Sequence[str] | None = None,
        param_names: Sequence[str] | None = None,
        events: Callable | None = None,
        n_events: int = 0,
        observe: Callable | None = None,
        observable_names: Sequence[str] = (),
        name: str = "UserModel",
        natural_frequency: float | Callable[[np.ndarray], float] | None = None,
    ):
        for fn, label in ((rhs, "rhs"), (events, "events"), (observe, "observe")):
            if fn is not None and not hasattr(fn, "py_func"):
                raise TypeError(f"{label} must be a numba.njit-compiled function")
        if n_states < 1:
            raise ValueError(f"n_states must be >= 1 (got {n_states})")
        p = np.asarray(params, dtype=float).ravel()
        if not np.all(np.isfinite(p)):
            raise ValueError("params must be finite")
        self.name = name
        self.state_names = tuple(state_names or (f"y{i}" for i in range(n_states)))
        if len(self.state_names) != n_states:
            raise ValueError(f"state_names has {len(self.state_names)} names for {n_states} states")
        names = list(param_names or (f"p{i}" for i in range(p.size)))
        if len(names) != p.size:
            raise ValueError(f"param_names has {len(names)} names for {p.size} parameters")
        if events is not None and n_events < 1:
            raise ValueError("events given: set n_events to the number of switching functions")
        self.event_names = tuple(f"event{j}" for j in range(n_events if events else 0))
        self.observable_names = tuple(observable_names) if observe is not None else ()
        if "Omega" in names:
            self.omega_index = names.index("Omega")
        elif period is not None:
            if not (period > 0 and math.isfinite(period)):
                raise ValueError(f"period must be > 0 (got {period!r})")
            names.append("Omega")  # hidden forcing frequency, after the user's parameters
            p = np.append(p, 2.0 * math.pi / period)
            self.omega_index = p.size - 1
        else:
            self.omega_index = None
        self.param_names = tuple(names)
        self.params = p
        if natural_frequency is not None and not callable(natural_frequency) and not (
                math.isfinite(natural_frequency) and natural_frequency > 0):
            raise ValueError(f"natural_frequency must be > 0 or a function of p "
                             f"(got {natural_frequency!r})")
        self.natural_frequency = natural_frequency
        self.kernel = KernelSource(rhs, events, observe, plain=True)

    def fastest_natural_frequency(self, P: np.ndarray | None = None) -> np.ndarray:
        """``natural_frequency`` in every lane of ``P`` (NaN when it was not given; see the
        class docstring)."""
        P = np.atleast_2d(self.params if P is None else np.asarray(P, dtype=float))
        w = self.natural_frequency
        if w is None:
            return Model.fastest_natural_frequency(self, P)
        if not callable(w):
            return np.full(P.shape[0], float(w))
        rows, inverse = unique_rows(P)
        return np.array([float(w(r)) for r in rows])[inverse]
