"""Time histories of one model at one forcing frequency, as a labelled xarray Dataset."""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from geardyn.models.base import Model
from geardyn.solvers.kernels import kernels_for

#: Fewest RK4 steps per forcing period.
MIN_STEPS_PER_PERIOD = 64
#: Default largest step as a fraction of the period of the model's fastest natural mode.
STEPS_PER_FASTEST_MODE = 100
#: Fewest steps per period of a forcing other than Omega (the CATT load fluctuation Lambda):
#: at 8 the error of a response forced at Lambda = 40 (far above every natural frequency) is
#: about 1e-7 of the motion, like that of the natural-mode rule (docs/numerics.md).
STEPS_PER_OTHER_FORCING = 8
#: States beyond this magnitude count as diverged.
DEFAULT_BOUND = 1.0e6


def default_steps_per_period(model: Model, omega: float | None = None,
                             others: np.ndarray | None = None,
                             params: np.ndarray | None = None) -> int:
    """Steps per forcing period: at least ``MIN_STEPS_PER_PERIOD``, enough that a step is at
    most 1/``STEPS_PER_FASTEST_MODE`` of the fastest natural period
    (:meth:`~geardyn.Model.fastest_natural_frequency` of the coefficients ``params``, default the
    model's own, when the model knows it), and at least ``STEPS_PER_OTHER_FORCING`` per period
    of every other forcing acting (``others``, rad per time unit; default the model's own,
    :meth:`~geardyn.Model.other_frequencies`). See ``docs/numerics.md`` for the accuracy."""
    p = np.array(model.params if params is None else params, dtype=float).ravel()
    omega = (float(p[model.omega_index]) if model.omega_index is not None else 0.0) \
        if omega is None else float(omega)
    if model.omega_index is not None:
        p[model.omega_index] = omega
    f = model.other_frequencies(p[None, :]) if others is None else others
    n = float(steps_per_period_rule(model, p[None, :], np.array([omega]), f)[0])
    return math.ceil(n)  # an OverflowError when it is not finite


def steps_per_period_rule(model: Model, P: np.ndarray, omega: np.ndarray,
                          others: np.ndarray | None = None) -> np.ndarray:
    """The rule of :func:`default_steps_per_period` for every lane (row) of the coefficient
    matrix ``P`` at the forcing frequencies ``omega`` (one per lane), vectorised: each lane's
    step follows its own fastest natural frequency and other forcings (``others``, shape
    ``(lanes, m)``, NaN where one does not act; default ``model.other_frequencies(P)``).
    Returns whole numbers as floats (inf where Omega is too small for any count)."""
    P = np.atleast_2d(np.asarray(P, dtype=float))
    om = np.broadcast_to(np.asarray(omega, dtype=float), (P.shape[0],))
    n = np.full(P.shape[0], float(MIN_STEPS_PER_PERIOD))
    forced = np.isfinite(om) & (om != 0.0)
    w = np.asarray(model.fastest_natural_frequency(P), dtype=float)
    ok = forced & np.isfinite(w) & (w > 0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        n = np.where(ok, np.maximum(n, np.ceil(STEPS_PER_FASTEST_MODE * w / om)), n)
        f = model.other_frequencies(P) if others is None else others
        f = np.abs(np.asarray(f, dtype=float).reshape(P.shape[0], -1))
        f = np.where(np.isfinite(f), f, 0.0)
        fmax = f.max(axis=1) if f.shape[1] else np.zeros(P.shape[0])
        act = forced & (fmax > 0)
        n = np.where(act, np.maximum(n, np.ceil(STEPS_PER_OTHER_FORCING * fmax / om)), n)
    return n


def simulate(
    model: Model,
    omega: float | None = None,
    transient: float = 0.0,
    periods: int = 64,
    steps_per_period: int | None = None,
    y0: np.ndarray | None = None,
    record_every: int = 1,
    locate_edges: bool = True,
    bound: float = DEFAULT_BOUND,
    sample_interval: float | None = None,
) -> xr.Dataset:
    """Integrate ``model`` and return its time history.

    Parameters
    ----------
    omega
        Forcing frequency (dimensionless Omega for the built-in models); default: the model's.
    transient
        Time discarded first, in the model's time unit (tau for dimensionless models), rounded
        up to whole forcing periods.
    periods
        Forcing periods recorded after the transient.
    steps_per_period
        RK4 steps per period (default :func:`default_steps_per_period`).
    record_every
        Record every n-th grid point (must divide ``steps_per_period``).
    locate_edges
        Locate dead-zone edge crossings inside steps (keeps 4th order; see the kernel docs).
    sample_interval
        For autonomous models only: the time between Poincare (stroboscopic) samples.

    Returns
    -------
    xarray.Dataset with dims ``time``, ``sample``, ``state``: one variable per state and per
    observable (mesh forces) over ``time``; ``poincare`` (sample, state), the states once per
    forcing period; ``status`` (0 ok, 1 diverged). Attributes record the integrator settings.
    """
    if omega is not None:
        model = model.with_omega(float(omega))
    om = model.omega
    if om == 0.0:
        if not sample_interval or sample_interval <= 0:
            raise ValueError("an autonomous model needs sample_interval > 0")
        period = float(sample_interval)
    else:
        if not math.isfinite(om) or om < 0:
            raise ValueError(f"omega must be a positive finite number (got {om!r})")
        period = 2.0 * math.pi / om
    n = int(steps_per_period or default_steps_per_period(model, om))
    if n < 4:
        raise ValueError(f"steps_per_period must be >= 4 (got {n})")
    if record_every < 1 or n % record_every:
        raise ValueError(f"record_every ({record_every}) must divide steps_per_period ({n})")
    if periods < 1:
        raise ValueError(f"periods must be >= 1 (got {periods})")
    if transient < 0 or not math.isfinite(transient):
        raise ValueError(f"transient must be a finite time >= 0 (got {transient!r})")
    h = period / n
    n_tr = math.ceil(transient / period - 1e-9)
    y = np.asarray(model.initial_state() if y0 is None else y0, dtype=float).copy()
    if y.shape != (model.n_states,):
        raise ValueError(f"y0 must have {model.n_states} entries ({', '.join(model.state_names)})")
    k = kernels_for(model.kernel)
    p = np.ascontiguousarray(model.params, dtype=float)
    n_ev, n_obs = model.n_events, model.n_observables
    status = 0
    unresolved = 0
    if n_tr:
        Yt, _, _, _, status, u, _ = k.trajectory(p, y, h, om, n, 0, n_tr * n, n_tr * n,
                                                 locate_edges, bound, n_ev, n_obs)
        unresolved += u
        y = Yt[-1].copy()
    i0 = n_tr * n
    if status == 0:
        Y, O, G, ncross, status, u, _ = k.trajectory(p, y, h, om, n, i0, periods * n,
                                                      record_every, locate_edges, bound, n_ev,
                                                      n_obs)
        unresolved += u
    else:
        n_rec = periods * n // record_every + 1
        Y = np.full((n_rec, model.n_states), np.nan)
        O = np.full((n_rec, n_obs), np.nan)
        ncross = np.zeros(n_ev, dtype=np.int64)
    t = (i0 + np.arange(Y.shape[0]) * record_every) * h
    per = n // record_every
    poincare = Y[::per]
    ds = xr.Dataset(
        coords={
            "time": ("time", t, {"units": model.time_unit, "long_name": "time"}),
            "sample": ("sample", np.arange(poincare.shape[0])),
            "state": ("state", list(model.state_names)),
        }
    )
    for j, name in enumerate(model.state_names):
        ds[name] = ("time", Y[:, j], {"units": model.state_units})
    for j, name in enumerate(model.observable_names):
        ds[name] = ("time", O[:, j], {"units": model.observable_units,
                                      "long_name": f"dynamic mesh force {name}"})
    ds["poincare"] = (("sample", "state"), poincare,
                      {"long_name": "states once per forcing period (stroboscopic section)"})
    ds["poincare_time"] = ("sample", t[::per], {"units": model.time_unit})
    if n_ev:
        ds["edge_crossings"] = ("event", np.asarray(ncross), {
            "long_name": "dead-zone edge crossings while recording"})
        ds = ds.assign_coords(event=("event", list(model.event_names)))
    ds.attrs.update(
        model=model.name,
        Omega=om,
        period=period,
        integrator="RK4, fixed step aligned to the forcing period",
        steps_per_period=n,
        step=h,
        locate_edges=int(bool(locate_edges)),
        transient=n_tr * period,
        transient_periods=n_tr,
        periods=periods,
        record_every=record_every,
        bound=bound,
        status=int(status),
        status_meaning="0 ok, 1 diverged (|state| > bound or not finite)",
        unresolved_steps=int(unresolved),
        time_unit=model.time_unit,
    )
    for key in ("interpretation",):
        if hasattr(model, key):
            ds.attrs[key] = getattr(model, key)
    if hasattr(model, "omega_n"):
        ds.attrs["omega_n"] = float(model.omega_n)
        ds.attrs["omega_n_units"] = "rad/s"
    other = model.other_frequencies(np.atleast_2d(model.params))[0]
    if other.size and np.isfinite(other[0]):  # a second excitation (the load fluctuation)
        ds.attrs["Lambda"] = float(other[0])
    return ds
