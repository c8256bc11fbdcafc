"""Frequency-response curves by brute force: up and down continued sweeps side by side.

:func:`frequency_response` sweeps the forcing frequency up and down by continuation
(:func:`geardyn.continued_sweeps`: each point starts from the previous one's final state, so a
sweep follows one attractor until it disappears and then jumps), and reports per point and
mesh the classic gear-dynamics quantities:

* the dynamic transmission error (DTE), i.e. the mesh deflection delta (the midpoint of the
  mesh's dead-zone switching functions, (delta - b + delta + b) / 2): its mean ``dte_mean``,
  the RMS of its alternating part ``dte_rms`` (about the mean), its peak alternating value
  ``dte_peak`` = max |delta - mean|, its amplitude ``dte_amplitude`` = (max - min) / 2 and
  its largest magnitude ``dte_max`` = max |delta| (extremes refined by a parabola through the
  largest sample and its neighbours). They are measured over one period of the attractor (k
  forcing periods for a period-k motion, ``samples`` forcing periods when it has no period),
  integrated once more from the sweep's final state at its final time on the sweep's own grid
  (fixed-step RK4, the edges located), every grid point counted (the rectangle rule, spectrally
  accurate on a periodic signal);
* the dynamic mesh force's peak and RMS and the dynamic factor (peak / static mesh force), as
  the sweep reports them (over its sampled stretch).

Jumps: ``hysteresis`` marks the points where the up and down sweeps disagree (``dte_rms`` of
some mesh differing by more than ``band_tol`` relative where at least one sweep is periodic,
or the contact regime differing, or the period where both sweeps found one): there two
attractors coexist. (Where neither sweep found a period, their RMS values are two finite
samplings of non-periodic motion and differ anyway: no evidence of coexistence.) Each sweep
leaves a band of coexistence by a jump: per band, sweep and mesh, the grid step touching the
band (from the point before it to the point after it) where ``dte_rms`` changes most, if by
more than ``jump_tol`` relative to the larger value. The jump lies between the step's two grid
points (``jump_lo``, ``jump_hi``): it is located to one grid step (``resolution``), reported
at the midpoint (``jump_omega``). A band that reaches an end of the grid may have its jump
outside it (``band_at_grid_end`` = 1); a steep but single-valued change (a resonance on a
coarse grid) is no jump.

Physical axes: where the model has physical units (a :class:`~geardyn.CATTDevice`, whose time
unit is 1/omega_n, or a :class:`~geardyn.DimensionalCATT`, in seconds) the dataset has the mesh
frequency in Hz and the input (carrier) speed in rpm as coordinates along ``Omega``: with the
sun held fixed the sun mesh's frequency is z_sun times the carrier speed.

Overlaying a continuation branch: a branch dataset (dim ``point`` along the branch, the
parameter ``Omega`` a variable) is drawn over the curves by
:func:`geardyn.plotting.frc.plot_frc` (``branches``), its variables read under these names or
those of :func:`geardyn.continuation`'s branches (``deflection_rms`` for ``dte_rms``,
``deflection_amplitude`` for ``dte_amplitude``, ``deflection_max`` for ``dte_max``;
``dynamic_factor`` alike), stability from ``stable`` (bool) or ``stability`` ("stable", ...),
one line per ``branch`` number.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import xarray as xr

from geardyn.analysis.bifurcation import ContinuedSweep, continued_sweeps
from geardyn.analysis.dataset import model_attrs
from geardyn.core.model import Model
from geardyn.core.results import finish
from geardyn.core.settings import SWEEP_DIRECTIONS, RunSettings, check_omega, resolve_run
from geardyn.core.status import Status, status_attrs
from geardyn.solvers.kernels import kernels_for

__all__ = ["BAND_TOL", "JUMP_TOL", "SWEEPS", "frequency_response", "mesh_deflections",
           "physical_axes"]

#: The two sweeps, in the order of the ``sweep`` dimension.
SWEEPS = SWEEP_DIRECTIONS
#: Relative change of dte_rms at a band's edge that counts as a jump.
JUMP_TOL = 0.1
#: Relative difference of dte_rms between the sweeps that counts as hysteresis.
BAND_TOL = 0.01


# ---------------------------------------------------------------------------- axes, deflections
def physical_axes(model: Model, omega: np.ndarray) -> dict[str, tuple[np.ndarray, dict]] | None:
    """Mesh frequency [Hz] and input (carrier) speed [rpm] at the forcing frequencies
    ``omega`` (the model's own units), or None when the model has no physical time unit; a
    model with ``speed_axes(omega)`` (the planetary gear set: input speed of the sun, from its
    geometry) gives its own."""
    caps = model.capabilities
    if caps.physical_axes:  # the model names its own (PlanetaryGearSet)
        return model.speed_axes(omega)  # type: ignore[attr-defined]
    if not caps.paper_device:
        return None
    params = model.params_in  # type: ignore[attr-defined]
    w = np.asarray(omega, dtype=float)
    if model.time_unit != "s":  # the mesh-coordinate form: time in 1 / omega_n
        w = w * float(model.omega_n)  # type: ignore[attr-defined]
    f = w / (2.0 * math.pi)
    z = int(params.sun.teeth)
    return {"mesh_frequency": (f, {"units": "Hz", "long_name": "mesh frequency"}),
            "input_speed": (60.0 * f / z, {
                "units": "rpm", "long_name": "input (carrier) speed",
                "meaning": f"mesh frequency / z_sun (z_sun = {z}, the sun held fixed) x 60"})}


def mesh_deflections(model: Model, G: np.ndarray) -> np.ndarray:
    """Mesh deflection of each mesh from the switching functions ``G`` (..., events): the
    midpoint of its drive (delta - b) and back (delta + b) edges."""
    return np.stack([(G[..., d] + G[..., b]) / 2.0 for _, d, b in model.meshes], axis=-1)


#: The DTE statistics, in the order :func:`_dte_stats` returns them.
DTE_STATS = ("dte_mean", "dte_rms", "dte_peak", "dte_amplitude", "dte_max")


def _dte_stats(model: Model, p: np.ndarray, y: np.ndarray, t0: float, n: int, periods: int,
               bound: float) -> tuple[np.ndarray, ...]:
    """:data:`DTE_STATS` of each mesh deflection (mean, RMS about the mean, max |delta -
    mean|, (max - min) / 2, max |delta|) over ``periods`` forcing periods from state ``y`` at
    time ``t0`` and forcing phase 0 (the sweep's final state), ``n`` steps a period; NaN when
    the run diverges. The run starts at the whole forcing period nearest ``t0`` (the forcing
    phase is exact; a second excitation's phase is that of this time, see the ``dte_window``
    attribute)."""
    k = kernels_for(model.kernel)
    omega = float(p[model.omega_index])
    h = 2.0 * math.pi / omega / n
    i0 = n * int(round(t0 * omega / (2.0 * math.pi)))
    steps = periods * n
    _, _, G, _, status, _, _ = k.trajectory(p, y, h, omega, n, i0, steps, 1, True, bound,
                                            model.n_events, model.n_observables)
    if status != Status.OK:
        return tuple(np.full(len(model.meshes), np.nan) for _ in DTE_STATS)
    d = mesh_deflections(model, G[:-1])  # one whole number of periods: the last repeats
    mean = np.mean(d, axis=0)
    alt = d - mean
    top, bottom = _refined_max(d), -_refined_max(-d)
    return (mean, np.sqrt(np.mean(alt * alt, axis=0)), np.maximum(top - mean, mean - bottom),
            0.5 * (top - bottom), np.maximum(np.abs(top), np.abs(bottom)))


def _refined_max(a: np.ndarray) -> np.ndarray:
    """The largest value of each column of ``a`` (samples over whole periods, so periodic),
    refined by the parabola through the largest sample and its two neighbours (the extremum of
    a smooth signal: error O(h^3) instead of the samples' O(h^2))."""
    out = np.empty(a.shape[1])
    n = a.shape[0]
    for m in range(a.shape[1]):
        i = int(np.argmax(a[:, m]))
        y0, y1, y2 = a[(i - 1) % n, m], a[i, m], a[(i + 1) % n, m]
        curv = y0 - 2.0 * y1 + y2
        out[m] = y1 - (y0 - y2) ** 2 / (8.0 * curv) if curv < 0 else y1
    return out


# ---------------------------------------------------------------------------- jumps, band
def _relative(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.abs(a - b) / np.maximum(np.maximum(np.abs(a), np.abs(b)), 1e-300)


def _band_runs(band: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) index of each run of True in ``band``."""
    runs, start = [], None
    for j, b in enumerate(band):
        if b and start is None:
            start = j
        if start is not None and (not b or j == band.size - 1):
            runs.append((start, j if b else j - 1))
            start = None
    return runs


def _jumps(rms: np.ndarray, band: np.ndarray, tol: float) -> list[tuple[int, int, int]]:
    """(lower index, upper index, mesh) of the jumps of one sweep (values ascending): per band
    of coexistence and mesh, the step touching the band (from its last point before to its
    first point after) where ``rms`` (Omega, mesh) changes most, if by more than ``tol``
    relative."""
    rel = _relative(rms[1:], rms[:-1])  # step j: from point j to j + 1
    out = []
    for first, last in _band_runs(band):
        steps = np.arange(max(first - 1, 0), min(last + 1, rel.shape[0]))
        if steps.size == 0:
            continue
        for m in range(rms.shape[1]):
            r = np.where(np.isfinite(rel[steps, m]), rel[steps, m], -np.inf)
            j = int(steps[int(np.argmax(r))])
            if rel[j, m] > tol:
                out.append((j, j + 1, m))
    return out


# ---------------------------------------------------------------------------- the analysis
def frequency_response(
    model: Model,
    omega: Sequence[float] | np.ndarray,
    run: RunSettings | None = None,
    *,
    jump_tol: float = JUMP_TOL,
    band_tol: float = BAND_TOL,
    progress: Callable[[int, int], None] | None = None,
    **settings: Any,
) -> xr.Dataset:
    """Frequency-response curves of ``model`` by up and down sweeps by continuation.

    Parameters
    ----------
    omega
        The forcing frequencies (the model's ``Omega``), at least 2, any order (sorted here).
    run
        :class:`~geardyn.RunSettings` of the sweeps (``transient`` of the first point,
        ``continued_transient``, ``converge``, ``samples``, ``steps_per_period``, ...), or its
        fields as keywords (deprecated, one DeprecationWarning naming the equivalent ``run=``).
    jump_tol, band_tol
        Relative thresholds of a jump and of the hysteresis band (see the module docs).
    progress
        ``progress(done, total)``, points of both sweeps.

    Returns
    -------
    xarray.Dataset (``geardyn_kind = "frequency-response"``) with dims ``sweep`` ("up",
    "down"), ``Omega``, ``mesh`` and ``jump``: ``dte_mean``, ``dte_rms``, ``dte_peak``,
    ``dte_amplitude``, ``dte_max``,
    ``force_rms``, ``force_peak``, ``dynamic_factor`` (sweep, Omega, mesh), ``period``,
    ``status`` (sweep, Omega), ``contact`` (sweep, Omega, mesh), ``hysteresis`` (Omega), the
    jump table ``jump_sweep``, ``jump_mesh``, ``jump_omega``, ``jump_lo``, ``jump_hi``,
    ``jump_from``, ``jump_to`` (jump); ``mesh_frequency`` [Hz] and
    ``input_speed`` [rpm] along ``Omega`` where the model has physical units; ``resolution``
    (the largest grid step) and the settings in ``attrs``.
    """
    run = resolve_run(run, settings, aliases={"tol": "period_tol"},
                      where="frequency_response")
    om = np.sort(np.asarray(omega, dtype=float).ravel())
    if om.size < 2:
        raise ValueError("omega: give at least 2 forcing frequencies")
    check_omega(om, "omega")
    if np.any(np.diff(om) <= 0):
        raise ValueError("omega: the frequencies must be distinct")
    if not model.meshes:
        raise ValueError(f"{model.name} has no backlash mesh: no transmission error to report")
    if not (jump_tol > 0 and band_tol > 0):
        raise ValueError("jump_tol and band_tol must be > 0")
    sweeps = [ContinuedSweep(model, "Omega", om, d, run=run) for d in SWEEPS]
    up, down = continued_sweeps(sweeps, run, progress=progress)
    ds = _dataset(model, om, (up, down), run)
    _mark_band_and_jumps(ds, jump_tol, band_tol)
    ds.attrs.update(run.attrs())
    ds.attrs.update(model=model.name, param="Omega",
                    time_unit=model.time_unit, jump_tol=jump_tol, band_tol=band_tol,
                    resolution=float(np.max(np.diff(om))),
                    dte_window=_window_text(model, om))
    ds.attrs.update(model_attrs(model))
    return finish(ds, "frequency-response")


def _dataset(model: Model, om: np.ndarray, runs: tuple[xr.Dataset, xr.Dataset],
             run: RunSettings) -> xr.Dataset:
    n_mesh = len(model.meshes)
    shape = (len(SWEEPS), om.size, n_mesh)
    stats = {k: np.full(shape, np.nan) for k in DTE_STATS}
    P = model.lane_params("Omega", om)
    for s, sw in enumerate(runs):
        final = _final_states(sw)
        for j in range(om.size):
            if sw["status"].values[j] != Status.OK:
                continue
            k = int(sw["period"].values[j])
            every = int(sw["section_periods"].values[j])
            periods = k * every if k > 0 else run.samples
            out = _dte_stats(model, P[j], final[j], float(sw["final_time"].values[j]),
                             int(sw["steps_per_period"].values[j]), periods, run.bound)
            for name, v in zip(DTE_STATS, out, strict=True):
                stats[name][s, j] = v
    ds = xr.Dataset(coords={"sweep": ("sweep", list(SWEEPS)),
                            "Omega": ("Omega", om, {"long_name": "forcing (mesh) frequency",
                                                    "units": _omega_units(model)}),
                            "mesh": ("mesh", [m[0] for m in model.meshes])})
    axes = physical_axes(model, om)
    if axes is not None:
        ds = ds.assign_coords({k: ("Omega", v, a) for k, (v, a) in axes.items()})
    units = deflection_units(model)
    dims = ("sweep", "Omega", "mesh")
    ds["dte_mean"] = (dims, stats["dte_mean"], {
        "long_name": "mean mesh deflection (transmission error)", **units})
    ds["dte_rms"] = (dims, stats["dte_rms"], {
        "long_name": "RMS dynamic transmission error (mesh deflection about its mean)",
        **units})
    ds["dte_peak"] = (dims, stats["dte_peak"], {
        "long_name": "peak dynamic transmission error, max |deflection - mean|", **units})
    ds["dte_amplitude"] = (dims, stats["dte_amplitude"], {
        "long_name": "DTE amplitude, (max - min) / 2 of the mesh deflection", **units})
    ds["dte_max"] = (dims, stats["dte_max"], {
        "long_name": "largest |mesh deflection|", **units})
    for name in ("force_rms", "force_peak", "dynamic_factor", "contact"):
        if name in runs[0]:
            ds[name] = (dims, np.stack([r[name].values for r in runs]), runs[0][name].attrs)
    ds["period"] = (("sweep", "Omega"), np.stack([r["period"].values for r in runs]),
                    runs[0]["period"].attrs)
    ds["status"] = (("sweep", "Omega"), np.stack([r["status"].values for r in runs]),
                    status_attrs())
    return ds


#: Unit names of the length scales that have one.
_LENGTH_UNITS = {1.0: "m", 1e-3: "mm", 1e-6: "um", 1e-9: "nm"}


def deflection_units(model: Model) -> dict[str, object]:
    """The attributes of a mesh deflection in the model's state units: ``units``, and where the
    model integrates lengths over a scale L (``length_scale`` [m] of the planetary gear set;
    b_c of the CATT device, X = x / b_c) ``length_scale`` and ``length_scale_units`` ("m"): a
    value times ``length_scale`` is metres, and ``units`` names that unit (``"um"`` for 1 um,
    else ``"<L> m"``). Metres for a model in SI units (time in seconds), else dimensionless
    ("1")."""
    scale = model.length_scale
    if scale is None and model.time_unit != "s" and model.capabilities.paper_device:
        scale = model.params_in.b_c  # type: ignore[attr-defined]
    if scale is not None:
        L = float(scale)
        return {"units": _LENGTH_UNITS.get(L, f"{L:g} m"), "length_scale": L,
                "length_scale_units": "m"}
    return {"units": "m" if model.time_unit == "s" else "1"}


def _window_text(model: Model, om: np.ndarray) -> str:
    text = ("one period of the attractor (samples forcing periods when it has none), from the "
            "sweep's final state at forcing phase 0")
    others = model.other_frequencies(model.lane_params("Omega", om))
    if others is not None and np.any(np.isfinite(others)):
        text += ("; the second excitation's phase approximated by the whole forcing period "
                 "nearest the final time (within half a forcing period)")
    return text


def _omega_units(model: Model) -> str:
    return "rad/s" if model.time_unit == "s" else "1"


def _final_states(sw: xr.Dataset) -> np.ndarray:
    """The final state of each point: its last Poincare sample (the state at final_time)."""
    return sw["poincare"].values[:, -1, :]


def _mark_band_and_jumps(ds: xr.Dataset, jump_tol: float, band_tol: float) -> None:
    """Add ``hysteresis`` (Omega) and the jump table (dim ``jump``) to ``ds``."""
    om = ds["Omega"].values
    rms = ds["dte_rms"].values
    k = ds["period"].values
    periodic = (k[0] > 0) | (k[1] > 0)  # two samplings of chaos differ: no evidence
    differ = periodic & np.any(_relative(rms[0], rms[1]) > band_tol, axis=-1)
    differ |= (k[0] != k[1]) & (k[0] > 0) & (k[1] > 0)  # 0: not settled, not another attractor
    if "contact" in ds:
        differ |= np.any(ds["contact"].values[0] != ds["contact"].values[1], axis=-1)
    ok = np.all(ds["status"].values == Status.OK, axis=0)
    ds.attrs["band_at_grid_end"] = int(bool((differ & ok)[0] or (differ & ok)[-1]))
    ds["hysteresis"] = ("Omega", differ & ok, {
        "long_name": "up and down sweeps disagree (coexisting attractors)",
        "meaning": f"dte_rms differs by > band_tol = {band_tol:g} (relative) where a sweep "
                   "is periodic, or the contact regime differs, or the period where both "
                   "sweeps found one"})
    band = differ & ok
    rows = []
    for s, name in enumerate(SWEEPS):
        for lo, hi, m in _jumps(rms[s], band, jump_tol):
            before, after = (lo, hi) if name == "up" else (hi, lo)
            rows.append((name, ds["mesh"].values[m], 0.5 * (om[lo] + om[hi]), om[lo], om[hi],
                         rms[s, before, m], rms[s, after, m]))
    cols = list(zip(*rows, strict=True)) if rows else [[] for _ in range(7)]
    ds.coords["jump"] = ("jump", np.arange(len(rows)))
    ds["jump_sweep"] = ("jump", np.array(cols[0], dtype=str))
    ds["jump_mesh"] = ("jump", np.array(cols[1], dtype=str))
    ds["jump_omega"] = ("jump", np.array(cols[2], dtype=float), {
        "long_name": "jump frequency (midpoint of the grid step it lies in)",
        "meaning": "located to one grid step: between jump_lo and jump_hi"})
    ds["jump_lo"] = ("jump", np.array(cols[3], dtype=float))
    ds["jump_hi"] = ("jump", np.array(cols[4], dtype=float))
    ds["jump_from"] = ("jump", np.array(cols[5], dtype=float), {
        "long_name": "dte_rms before the jump (in the sweep's direction)"})
    ds["jump_to"] = ("jump", np.array(cols[6], dtype=float), {
        "long_name": "dte_rms after the jump"})
