"""What a sensor fixed on the ring of a planetary stage sees: the planets' mesh forces weighted
by a window in the angle between each planet and the sensor.

Transfer model (the model family of McFadden & Smith, Proc. IMechE C 199 (1985) 287-292, and
Inalpolat & Kahraman, J. Sound Vib. 323 (2009) 677-696): planet n sits at the angle
phi(t) + psi_n relative to the ring (phi the carrier's angle relative to the ring, psi_n the
planet's angle on the carrier); its ring-planet mesh force F_n(t) reaches a sensor at the ring
angle theta_s through a transfer that depends only on where the planet is,

    s(t) = sum_n w(phi(t) + psi_n - theta_s) F_n(t),

w a 2 pi-periodic window, largest with the planet under the sensor and falling to 0 (Hann) or
nearly 0 (Gaussian) a ``width`` away (:func:`planet_window`). Path lengths, phase delays and
the housing's own resonances are not modelled: the window is the whole transfer.

Sidebands (derived in ``docs/sensor.md``): with w = sum_k c_k e^{ik alpha} and the mesh force of
identical planets on a held ring F_n(t) = sum_m A_m e^{i m Z_r (phi + psi_n)}, the signal has
carrier orders q = m Z_r + k with amplitude c_k A_m sum_n e^{i q psi_n}. For N equally spaced
planets the sum is N where q is a multiple of N and 0 elsewhere: only the orders q = 0 (mod N)
survive (:func:`surviving_orders`), so the sidebands of mesh harmonic m are at
k = -(m Z_r mod N) + j N, asymmetric about m Z_r unless 2 m Z_r is a multiple of N.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from geardyn.errors import ParameterError

__all__ = ["WINDOWS", "carrier_angle", "label_sidebands", "planet_window",
           "planetary_sensor_signal", "sensor_signal", "sensor_spectrum", "surviving_orders"]

#: Window shapes of :func:`planet_window`.
WINDOWS = ("hann", "gaussian")


def _check_width(width: float) -> float:
    w = float(width)
    if not (math.isfinite(w) and 0.0 < w <= 2.0 * math.pi):
        raise ParameterError("width", width, "must be an angle in (0, 2 pi] rad")
    return w


def planet_window(angle: np.ndarray | float, width: float, window: str = "hann") -> np.ndarray:
    """The transfer weight w at the planet-to-sensor ``angle`` [rad] (any real, wrapped to
    [-pi, pi)): ``"hann"``, cos^2(pi a / width) for |a| < width / 2, else 0 (``width`` the full
    width at zero, <= 2 pi); ``"gaussian"``, exp(-a^2 / (2 sigma^2)) with sigma = ``width`` / 2
    on the wrapped angle (a kink at a = pi, negligible for sigma << pi)."""
    w = _check_width(width)
    a = np.mod(np.asarray(angle, dtype=float) + math.pi, 2.0 * math.pi) - math.pi
    if window == "hann":
        return np.where(np.abs(a) < 0.5 * w, np.cos(math.pi * a / w) ** 2, 0.0)
    if window == "gaussian":
        return np.exp(-0.5 * (2.0 * a / w) ** 2)
    raise ParameterError("window", window, f"must be one of {', '.join(WINDOWS)}")


def sensor_signal(forces: np.ndarray, carrier_angle: np.ndarray, planet_angles: np.ndarray,
                  sensor_angle: float = 0.0, width: float = math.pi / 2,
                  window: str = "hann") -> np.ndarray:
    """s = sum_n w(phi + psi_n - theta_s) F_n: the sensor signal (the units of ``forces``).

    ``forces`` (..., time, planet): each planet's ring-planet mesh force; ``carrier_angle``
    phi [rad] (..., time), the carrier's angle relative to the ring (broadcast against the
    forces' leading dims, so many lanes go through at once); ``planet_angles`` psi_n [rad];
    ``sensor_angle`` theta_s [rad]; ``width`` and ``window`` as :func:`planet_window`.
    Returns (..., time)."""
    F = np.asarray(forces, dtype=float)
    psi = np.asarray(planet_angles, dtype=float).ravel()
    if F.ndim < 2 or F.shape[-1] != psi.size:
        raise ParameterError("forces", F.shape, f"must end in (time, planet) with "
                             f"{psi.size} planets (one per planet angle)")
    phi = np.asarray(carrier_angle, dtype=float)
    if phi.shape[-1:] != F.shape[-2:-1]:
        raise ParameterError("carrier_angle", phi.shape, f"must end in the {F.shape[-2]} times"
                             " of the forces")
    if not math.isfinite(float(sensor_angle)):
        raise ParameterError("sensor_angle", sensor_angle, "must be a finite angle [rad]")
    weight = planet_window(phi[..., None] + psi - float(sensor_angle), width, window)
    return np.sum(weight * F, axis=-1)


def surviving_orders(ring_teeth: int, n_planets: int, harmonic: int, span: int
                     ) -> list[int]:
    """Sideband offsets k in [-span, span] of mesh harmonic ``harmonic`` that survive for
    ``n_planets`` identical, equally spaced planets: (harmonic Z_r + k) = 0 (mod N)."""
    for name, v in (("ring_teeth", ring_teeth), ("n_planets", n_planets),
                    ("harmonic", harmonic)):
        if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < 1:
            raise ParameterError(name, v, "must be a whole number >= 1")
    q0 = harmonic * ring_teeth
    return [k for k in range(-span, span + 1) if (q0 + k) % n_planets == 0]


def carrier_angle(model, time: np.ndarray, omega: np.ndarray | float | None = None
                  ) -> np.ndarray:
    """phi [rad]: the carrier's angle relative to the ring of a
    :class:`~geardyn.PlanetaryGearSet` built from geometry at the model times ``time`` (its
    time unit), at the forcing frequency ``omega`` (default the model's Omega; an array of one
    per lane broadcasts against ``time``'s leading dims): phi = +-(mesh angle) / Z_r with the
    mesh angle = mesh_order Omega t, 0 at t = 0 (the first planet at psi_1 there); + unless the
    sun is held (then the planets turn against psi relative to the ring). A model whose class
    does not declare the ring sensor (``capabilities.fault_dataset``), or one built without
    geometry, is a :class:`~geardyn.errors.ParameterError` naming ``model``."""
    declared = model.capabilities.fault_dataset
    geo = model.geometry if declared is not None and declared.signal == "ring_sensor" else None
    if geo is None:
        raise ParameterError("model", type(model).__name__, "needs a PlanetaryGearSet built "
                             "from geometry (the ring's teeth)")
    om = np.asarray(model.omega if omega is None else omega, dtype=float)
    t = np.asarray(time, dtype=float)
    scale = (-1.0 if model.held == "sun" else 1.0) * model.mesh_order / int(geo.ring.teeth)
    return scale * (float(om) if om.ndim == 0 else om[..., None]) * t


def planetary_sensor_signal(ds: xr.Dataset, model, sensor_angle: float = 0.0,
                            width: float = math.pi / 2, window: str = "hann") -> xr.Dataset:
    """The sensor signal of a :func:`~geardyn.simulate` run ``ds`` of a
    :class:`~geardyn.PlanetaryGearSet` built from geometry
    (:meth:`~geardyn.PlanetaryGearSet.from_geometry`: the ring's teeth): the ring-planet
    forces ``F_r1`` .. ``F_rN`` through :func:`sensor_signal`, the carrier angle by
    :func:`carrier_angle` at the run's Omega.

    Returns a Dataset over ``time`` (the run's, in the model's time unit) with ``signal`` [N],
    ``carrier_angle`` [rad], ``carrier_revolutions`` and the forces (``force``, (time,
    planet)); attributes the window, its width, the sensor angle, Z_r, N, the planet angles
    psi_n [rad] and the carrier
    frequency in the time unit (``carrier_frequency``, cycles per unit time)."""
    t = np.asarray(ds["time"].values, dtype=float)
    phi = carrier_angle(model, t, float(ds.attrs["Omega"]))
    names = [f"F_r{n + 1}" for n in range(model.n_planets)]
    missing = [n for n in names if n not in ds]
    if missing:
        raise ParameterError("ds", ", ".join(missing), "not in the simulation: give a "
                             "geardyn.simulate run of this model")
    z_r = int(model.geometry.ring.teeth)
    omega_mesh = float(ds.attrs["Omega"]) * model.mesh_order  # mesh rad per time unit
    forces = np.stack([np.asarray(ds[n].values, dtype=float) for n in names], axis=-1)
    psi = np.asarray(model.psi, dtype=float)
    s = sensor_signal(forces, phi, psi, sensor_angle, width, window)
    out = xr.Dataset(
        {"signal": ("time", s, {"units": "N", "long_name": "sensor signal",
                                "meaning": "sum_n w(phi + psi_n - theta_s) F_rn"}),
         "carrier_angle": ("time", phi, {"units": "rad",
                                         "long_name": "carrier angle relative to the ring"}),
         "carrier_revolutions": ("time", phi / (2.0 * math.pi)),
         "force": (("time", "planet"), forces, {"units": "N",
                                                "long_name": "ring-planet mesh force"})},
        coords={"time": ("time", t, dict(ds["time"].attrs)),
                "planet": ("planet", np.arange(1, len(names) + 1))})
    out.attrs.update(window=window, width=float(width), sensor_angle=float(sensor_angle),
                     ring_teeth=z_r, n_planets=int(model.n_planets), planet_angles=psi.tolist(),
                     carrier_frequency=abs(omega_mesh) / z_r / (2.0 * math.pi),
                     transfer="McFadden & Smith 1985; Inalpolat & Kahraman 2009 (window model)")
    return out


def sensor_spectrum(signal: np.ndarray, carrier_revolutions: float) -> xr.Dataset:
    """One-sided amplitude spectrum of ``signal`` sampled uniformly over
    ``carrier_revolutions`` (a whole number: the orders fall on the bins) carrier revolutions,
    the last sample excluded if it closes the span (pass the samples of [0, R)). Coordinate
    ``order`` (carrier orders: frequency / carrier frequency); ``amplitude`` in the signal's
    units (a cosine A cos(q phi) gives A at order q)."""
    x = np.asarray(signal, dtype=float).ravel()
    rev = float(carrier_revolutions)
    if not (rev >= 1.0 and abs(rev - round(rev)) < 1e-9):
        raise ParameterError("carrier_revolutions", carrier_revolutions,
                             "must be a whole number >= 1 (orders on the bins)")
    n = x.size
    if n < 4:
        raise ParameterError("signal", n, "needs at least 4 samples")
    amp = np.abs(np.fft.rfft(x)) / n
    amp[1:] *= 2.0
    if n % 2 == 0:
        amp[-1] /= 2.0
    order = np.arange(amp.size) / round(rev)
    return xr.Dataset({"amplitude": ("order", amp, {"long_name": "amplitude"})},
                      coords={"order": ("order", order, {"long_name": "carrier order"})},
                      attrs={"carrier_revolutions": round(rev)})


def label_sidebands(spec: xr.Dataset, ring_teeth: int, harmonics: int = 2, span: int = 8,
                    rel: float = 0.02) -> list[tuple[float, float, str]]:
    """(order, amplitude, label) of the peaks of ``spec`` (:func:`sensor_spectrum`) at the
    carrier orders m Z_r + k (m = 1 .. ``harmonics``, |k| <= ``span``) above ``rel`` times the
    largest of them, labelled ``"mZr"`` (k = 0) or ``"mZr+k"``, ``"mZr-k"``, e.g. ``"1Zr-3"``."""
    amp, order = spec["amplitude"].values, spec["order"].values
    rev = int(spec.attrs.get("carrier_revolutions", 1))
    found = []
    for m in range(1, harmonics + 1):
        for k in range(-span, span + 1):
            q = m * ring_teeth + k
            i = q * rev
            if 0 < i < amp.size:
                found.append((float(order[i]), float(amp[i]),
                              f"{m}Zr" + ("" if k == 0 else f"{k:+d}")))
    top = max((a for _, a, _ in found), default=0.0)
    return [f for f in found if f[1] >= rel * top and f[1] > 0.0]
