"""Time histories of one model at one forcing frequency, as a labelled xarray Dataset."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from geardyn.core.model import Model
from geardyn.core.moved import moved
from geardyn.core.plan import LanePlan, LaneSettings
from geardyn.core.results import finish
from geardyn.core.settings import INTEGRATOR, RunSettings, check_omega, resolve_run
from geardyn.core.status import Status, status_meaning
from geardyn.solvers.kernels import kernels_for

#: Names whose home is now the core layer (deprecated here).
__getattr__ = moved(__name__, {
    **dict.fromkeys(("MIN_STEPS_PER_PERIOD", "STEPS_PER_FASTEST_MODE",
                     "STEPS_PER_OTHER_FORCING", "steps_per_period_rule",
                     "default_steps_per_period"), "geardyn.core.plan"),
    "DEFAULT_BOUND": "geardyn.core.settings"})

#: simulate's own defaults of the run settings (a time history from the start, 64 periods).
SIMULATE_DEFAULTS = {"transient": 0.0, "samples": 64}


def simulate(
    model: Model,
    omega: float | None = None,
    run: RunSettings | None = None,
    *,
    y0: np.ndarray | None = None,
    record_every: int = 1,
    sample_interval: float | None = None,
    **settings: Any,
) -> xr.Dataset:
    """Integrate ``model`` and return its time history.

    Parameters
    ----------
    omega
        Forcing frequency (dimensionless Omega for the built-in models); default: the model's.
    run
        :class:`~geardyn.RunSettings`: ``transient`` (time discarded first, in the model's time
        unit, rounded up to whole forcing periods), ``samples`` (forcing periods recorded),
        ``steps_per_period`` (default :func:`~geardyn.core.plan.default_steps_per_period`),
        ``locate_edges``, ``bound``; planned as a one-lane
        :class:`~geardyn.core.plan.LanePlan` (the step rule's own count, not the sweep's
        ladder). Without ``run``: transient 0 and 64 periods. The keywords ``transient``,
        ``periods`` (the samples), ``steps_per_period``, ``locate_edges`` and ``bound`` still
        build it but are deprecated (one DeprecationWarning naming the equivalent
        ``run=geardyn.RunSettings(...)``, these defaults included).
    record_every
        Record every n-th grid point (must divide ``steps_per_period``).
    sample_interval
        For autonomous models only: the time between Poincare (stroboscopic) samples.

    Returns
    -------
    xarray.Dataset with dims ``time``, ``sample``, ``state``: one variable per state and per
    observable (mesh forces) over ``time``; ``poincare`` (sample, state), the states once per
    forcing period; ``status`` (:class:`~geardyn.Status`). Attributes record the settings.
    """
    run = resolve_run(run, settings, SIMULATE_DEFAULTS, aliases={"periods": "samples"},
                      where="simulate")
    periods, bound = run.samples, run.bound
    locate_edges = run.locate_edges
    if omega is not None:
        if float(omega) != 0.0:  # 0: the autonomous model
            check_omega(float(omega), "omega")
        model = model.with_omega(float(omega))
    om = model.omega
    if om == 0.0:
        if not sample_interval or sample_interval <= 0:
            raise ValueError("an autonomous model needs sample_interval > 0")
        lanes = LaneSettings(ladder=False, interval=float(sample_interval))
    else:
        check_omega(om)
        lanes = LaneSettings(ladder=False, sample_every=1)
    plan = LanePlan.build(model, np.asarray(model.params, dtype=float)[None, :], run, lanes)
    period, n, h = float(plan.period[0]), int(plan.steps_per_period[0]), float(plan.step[0])
    if record_every < 1 or n % record_every:
        raise ValueError(f"record_every ({record_every}) must divide steps_per_period ({n})")
    n_tr = int(plan.transient_periods[0])
    y = np.asarray(model.initial_state() if y0 is None else y0, dtype=float).copy()
    if y.shape != (model.n_states,):
        raise ValueError(f"y0 must have {model.n_states} entries ({', '.join(model.state_names)})")
    k = kernels_for(model.kernel)
    p = np.ascontiguousarray(model.params, dtype=float)
    n_ev, n_obs = model.n_events, model.n_observables
    status = Status.OK
    unresolved = 0
    if n_tr:
        Yt, _, _, _, status, u, _ = k.trajectory(p, y, h, om, n, 0, n_tr * n, n_tr * n,
                                                 locate_edges, bound, n_ev, n_obs)
        unresolved += u
        y = Yt[-1].copy()
    i0 = n_tr * n
    if status == Status.OK:
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
    units = _state_units(model)
    for j, name in enumerate(model.state_names):
        ds[name] = ("time", Y[:, j], {"units": units[j]})
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
        integrator=INTEGRATOR,
        steps_per_period=n,
        step=h,
        locate_edges=int(bool(locate_edges)),
        transient=n_tr * period,
        transient_periods=n_tr,
        periods=periods,
        record_every=record_every,
        bound=bound,
        status=int(status),
        status_meaning=status_meaning(),
        unresolved_steps=int(unresolved),
        time_unit=model.time_unit,
    )
    ds.attrs.update(model.dataset_attrs())
    if "omega_n" in ds.attrs:
        ds.attrs["omega_n_units"] = "rad/s"
    other = model.other_frequencies(np.atleast_2d(model.params))[0]
    if other.size and np.isfinite(other[0]):  # a second excitation (the load fluctuation)
        ds.attrs["Lambda"] = float(other[0])
    return finish(ds, "simulation")


def _state_units(model: Model) -> list[str]:
    """The unit of each state: ``model.state_units`` split at ", " where it names one per state
    (``"m, m/s"``), else the same for every state."""
    parts = model.state_units.split(", ")
    return parts if len(parts) == model.n_states else [model.state_units] * model.n_states
