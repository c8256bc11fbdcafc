"""The explorer's computations, each a call of geardyn's public API: the diagram of a window
(:func:`geardyn.bifurcation`), one orbit (:func:`geardyn.simulate`, the amplitude spectrum
and its labelled peaks, :func:`geardyn.periodic_orbit` for the Floquet multipliers) and, for a
model built from geometry, its mesh stiffness (the table and the series the model uses). No
physics here: only the calls and the arrays the figures draw.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import xarray as xr

from geardyn.explore.state import DiagramRequest

__all__ = ["DiagramView", "MeshStiffness", "OrbitView", "StiffnessView", "compute_diagram",
           "compute_orbit", "diagram_view", "stiffness_view"]

#: Highest spectrum order shown (multiples of Omega) and peaks labelled.
SPECTRUM_MAX_ORDER = 8.0
SPECTRUM_LABELS = 8


def compute_diagram(req: DiagramRequest,
                    progress: Callable[[int, int], None] | None = None) -> xr.Dataset:
    """The bifurcation dataset of the request's window (``progress(done, total)`` after each
    chunk; an exception raised by it ends the computation)."""
    from geardyn.analysis.bifurcation import bifurcation

    ds = bifurcation(req.model, req.param, req.window.values(), req.run,
                     continuation=None if req.continuation == "none" else req.continuation,
                     progress=progress)
    ds.attrs.update(req.attrs)
    return ds


@dataclass
class DiagramView:
    """Flat arrays of a diagram for a scatter plot and the contact bands."""

    param: str
    state: str
    x: np.ndarray  # parameter value of every point
    y: np.ndarray  # the Poincare point's state (unbounded values: at the top, class -1)
    period_class: np.ndarray  # legend class (see geardyn.plotting.bifurcation.PERIOD_CLASSES)
    values: np.ndarray  # the window's values
    width: float  # spacing of the values (band cell width)
    contact: dict[str, np.ndarray]  # mesh -> regime per value
    period: np.ndarray  # period per value


def diagram_view(ds: xr.Dataset, state: str | None = None) -> DiagramView:
    """The points and bands :func:`geardyn.plotting.plot_bifurcation` draws, as arrays."""
    from geardyn.plotting.bifurcation import period_class, resolve_sweep_state

    param = str(ds.attrs["param"])
    name = resolve_sweep_state(ds, state)
    pts = ds["poincare"].sel(state=name).transpose(param, "sample").values
    values = ds[param].values.astype(float)
    period = ds["period"].values
    classes = np.broadcast_to(period_class(period)[:, None], pts.shape)
    xx = np.broadcast_to(values[:, None], pts.shape)
    keep = np.isfinite(pts)
    x, y, cls = xx[keep], pts[keep], classes[keep]
    lost = ~keep.any(axis=1) & (period == -1)  # unbounded, no finite point: marked on top
    if np.any(lost):
        top = float(np.max(y)) if y.size else 1.0
        x = np.concatenate([x, values[lost]])
        y = np.concatenate([y, np.full(int(lost.sum()), top)])
        cls = np.concatenate([cls, np.full(int(lost.sum()), -1)])
    contact = {str(m): ds["contact"].sel(mesh=m).values.astype(str) for m in ds["mesh"].values}
    width = float(abs(values[1] - values[0])) if values.size > 1 else 1.0
    return DiagramView(param, name, x, y, cls, values, width, contact, period)


@dataclass
class OrbitView:
    """One orbit of the diagram: the arrays of its four panels and its summary."""

    param: str
    value: float
    omega: float
    state: str
    velocity: str | None
    time: np.ndarray
    x: np.ndarray
    v: np.ndarray
    section_x: np.ndarray
    section_v: np.ndarray
    frequency: np.ndarray
    amplitude: np.ndarray
    peaks: list[tuple[float, float, str]]
    period: int
    contact: dict[str, str]
    status: str
    multipliers: np.ndarray | None = None
    stability: str = "unknown"
    floquet_message: str = ""
    notes: list[str] = field(default_factory=list)

    def summary(self) -> str:
        """One paragraph of text: value, period, contact regime, multipliers."""
        period = {0: "no period found", -1: "unbounded"}.get(self.period,
                                                                f"period {self.period}")
        contact = ", ".join(f"{k}: {v}" for k, v in self.contact.items()) or "n/a"
        text = (f"{self.param} = {self.value:.6g}: {period}; contact loss {contact}; "
                f"integration {self.status}")
        if self.multipliers is not None:
            mult = ", ".join(_complex_text(z) for z in self.multipliers)
            text += f"; Floquet multipliers ({self.stability}): {mult}"
        elif self.floquet_message:
            text += f"; Floquet multipliers: {self.floquet_message}"
        return text


def _complex_text(z: complex) -> str:
    z = complex(z)
    if abs(z.imag) < 1e-12 * max(1.0, abs(z)):
        return f"{z.real:.4g}"
    return f"{z.real:.4g}{z.imag:+.4g}i"


@dataclass(frozen=True)
class OrbitRequest:
    """One orbit: the diagram's model at ``value`` of ``param``, and what the diagram found
    there (period and contact regime)."""

    model: Any
    param: str
    value: float
    run: Any
    state: str
    period: int
    contact: dict[str, str]


def orbit_request(req: DiagramRequest, ds: xr.Dataset, x: float) -> OrbitRequest:
    """The orbit nearest to ``x`` on the parameter axis of the diagram ``ds``."""
    param = str(ds.attrs["param"])
    values = ds[param].values.astype(float)
    i = int(np.argmin(np.abs(values - x)))
    contact = {str(m): str(ds["contact"].sel(mesh=m).values[i]) for m in ds["mesh"].values}
    return OrbitRequest(req.model, param, float(values[i]), req.run, req.plot_state,
                        int(ds["period"].values[i]), contact)


def compute_orbit(req: OrbitRequest) -> OrbitView:
    """Simulate the orbit (the diagram's transient and samples), its spectrum with named peaks,
    and, where the diagram found a period, its Floquet multipliers by Newton shooting."""
    from geardyn.analysis.spectrum import amplitude_spectrum, label_peaks
    from geardyn.core.status import Status
    from geardyn.plotting.simulation import resolve_state, velocity_of
    from geardyn.solvers.simulate import simulate

    model = req.model
    if req.param != "Omega":
        model = model.with_params(**{req.param: req.value})
    omega = req.value if req.param == "Omega" else model.omega
    ds = simulate(model, omega=omega, run=req.run)
    name = resolve_state(ds, req.state)
    vel = velocity_of(ds, name)
    x = ds[name].values
    v = ds[vel].values if vel is not None else np.gradient(x, ds["time"].values)
    sx = ds["poincare"].sel(state=name).values if name in ds["state"].values else np.array([])
    sv = (ds["poincare"].sel(state=vel).values if vel is not None and vel in ds["state"].values
          else np.array([]))
    status = Status(int(ds.attrs["status"])).name.lower()
    view = OrbitView(req.param, req.value, float(omega), name, vel, ds["time"].values, x, v, sx,
                     sv, np.array([]), np.array([]), [], req.period, req.contact, status)
    try:
        spec = amplitude_spectrum(ds, name).sel(frequency=slice(0.0, SPECTRUM_MAX_ORDER))
        view.frequency, view.amplitude = spec["frequency"].values[1:], spec.values[1:]
        peaks = label_peaks(spec, threshold=1e-3, max_peaks=SPECTRUM_LABELS)
        view.peaks = [(float(f), float(a), str(s)) for f, a, s in zip(
            peaks["frequency"].values, peaks["amplitude"].values, peaks["label"].values,
            strict=True)]
    except ValueError as exc:  # diverged or too short: no spectrum, said so
        view.notes.append(f"spectrum: {exc}")
    _floquet(view, model, omega, req, ds)
    return view


def _floquet(view: OrbitView, model, omega: float, req: OrbitRequest, ds: xr.Dataset) -> None:
    """Floquet multipliers of the period-k orbit where the diagram found period k."""
    from geardyn.analysis.orbits import periodic_orbit

    if req.period < 1:
        view.floquet_message = "none (no periodic orbit found at this point)"
        return
    guess = ds["poincare"].values[-1]
    if not np.all(np.isfinite(guess)):
        view.floquet_message = "none (the run diverged)"
        return
    try:
        orb = periodic_orbit(model, omega=omega, period=req.period, guess=guess, run=req.run)
    except (ValueError, ArithmeticError) as exc:
        view.floquet_message = f"not computed ({exc})"
        return
    if orb.converged:
        view.multipliers = np.asarray(orb.multipliers)
        view.stability = orb.stability
    else:
        view.floquet_message = f"shooting did not converge ({orb.message})"


@dataclass
class MeshStiffness:
    """One mesh's drive and coast stiffness [N/m] over the forcing period: the table the model
    was built from and the truncated Fourier series it integrates, at the table's angles
    (``cycle``: mesh cycles from t = 0); ``faulty`` where a fault's tooth takes part."""

    mesh: str
    cycle: np.ndarray
    drive: np.ndarray
    coast: np.ndarray
    drive_series: np.ndarray
    coast_series: np.ndarray
    faulty: bool


@dataclass
class StiffnessView:
    """The stiffness panel of a model built from geometry: every mesh's stiffness over the
    forcing period (:class:`MeshStiffness`), the series' harmonics and the faults' line."""

    meshes: list[MeshStiffness]
    harmonics: int
    faults: str

    def title(self) -> str:
        return (f"mesh stiffness over the forcing period: the table and the model's series "
                f"({self.harmonics} harmonics)")


def stiffness_view(model: Any) -> StiffnessView | None:
    """The stiffness panel's arrays of a model that carries potential-energy stiffness tables,
    as its class declares (``capabilities.stiffness_tables``): a :class:`~geardyn.SpurPair`'s
    (``"pair"``: its ``stiffness`` table and ``stiffness_at`` series at ``table_phase()``; one
    mesh, ``"mesh"``) or a :class:`~geardyn.PlanetaryGearSet`'s built with them (``"meshes"``:
    ``period_stiffness``; a faulty mesh's table spans the faulty gear's revolution); None for a
    model without them."""
    tables = model.capabilities.stiffness_tables
    if tables == "meshes" and model.mesh_tables is not None:
        drive, coast = model.period_stiffness("drive"), model.period_stiffness("coast")
        faults = model.faults
        faulty = () if faults is None else faults.meshes(model.n_planets)
        meshes = [MeshStiffness(name, d[0], d[1], c[1], d[2], c[2], name in faulty)
                  for name, d, c in zip(model.mesh_names, drive, coast, strict=True)]
        return StiffnessView(meshes, model.fourier.shape[1] // 2,
                             "none" if faults is None else faults.describe())
    if tables != "pair":
        return None
    table = model.stiffness
    theta = model.table_phase()
    faults = str(table.attrs.get("faults", "none"))
    mesh = MeshStiffness(
        "mesh", np.asarray(table["cycle"].values, dtype=float),
        np.asarray(table["mesh_stiffness"].values, dtype=float),
        np.asarray(table["mesh_stiffness_coast"].values, dtype=float),
        model.stiffness_at(theta, "drive"), model.stiffness_at(theta, "coast"),
        faults != "none")
    return StiffnessView([mesh], int(model.n_harmonics), faults)

