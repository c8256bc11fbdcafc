"""Step-convergence study of SpurPair's table form (the step of geardyn.fault_dataset): the
19/48 pair of bench/fault_dataset.py with a 1.5 mm root crack, 50 N m, at ``--speeds`` rpm; the
dataset's signal (the mesh force F sampled at ``--rate`` Hz by linear interpolation of the grid,
``--duration`` s from the start) at n steps per period of the contact mode (n = ``--per-mode``)
against the same at 2n. Prints the RMS and the largest difference relative to the RMS of the
signal about its mean, and the same for the Fourier form (default harmonics) against the table
form at 2 x 100 steps per mode (the series' own error, for scale).

    .venv/bin/python bench/table_step.py [--speeds 1000 2000 3000] [--per-mode 25 50 100]
"""

from __future__ import annotations

import argparse
import math

import numpy as np

import geardyn
from geardyn.gears import GearMesh, RootCrack, SpurGear

MESH = GearMesh(SpurGear(19, 3.2e-3, math.radians(20.0), 0.016, name="pinion"),
                SpurGear(48, 3.2e-3, math.radians(20.0), 0.016, name="wheel"))


def signal(model: geardyn.SpurPair, per_mode: float, duration: float, rate: float) -> np.ndarray:
    """F sampled at k / rate over ``duration`` at ``per_mode`` steps per contact-mode period."""
    w = float(model.fastest_natural_frequency()[0])
    n = max(64, math.ceil(per_mode * w / model.omega))
    periods = math.ceil(duration * model.omega / (2.0 * math.pi)) + 1
    ds = geardyn.simulate(model, run=geardyn.RunSettings(transient=0.0, samples=periods,
                                                         steps_per_period=n))
    assert ds.attrs["status"] == 0
    t = ds["time"].values - ds["time"].values[0]
    f = ds["F"].values
    tk = np.arange(round(duration * rate)) / rate
    if not MEAN[0]:
        return np.interp(tk, t, f)
    c = np.concatenate(([0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(t))))
    half = 0.5 / rate
    return (np.interp(tk + half, t, c) - np.interp(tk - half, t, c)) * rate


MEAN = [False]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speeds", type=float, nargs="+", default=[1000.0, 2000.0, 3000.0])
    ap.add_argument("--per-mode", type=float, nargs="+", default=[25.0, 50.0, 100.0])
    ap.add_argument("--duration", type=float, default=0.1)
    ap.add_argument("--rate", type=float, default=20_000.0)
    ap.add_argument("--mean", action="store_true")
    a = ap.parse_args()
    MEAN[0] = a.mean

    def build(form: str) -> geardyn.SpurPair:
        return geardyn.SpurPair.from_geometry(
            MESH, bore_radius=(0.012, 0.035), speed=1000, torque=50.0, faults=RootCrack("1.5 mm"),
            inertia=(4.3659e-4, 8.3602e-3), backlash=10e-6, speed_unit="rpm",
            stiffness_form=form)

    table, fourier = build("table"), build("fourier")
    for rpm in a.speeds:
        m = table.with_params(speed=rpm)
        row = []
        for n in a.per_mode:
            s1 = signal(m, n, a.duration, a.rate)
            s2 = signal(m, 2 * n, a.duration, a.rate)
            rms = float(np.std(s2))
            row.append(f"{n:g}/mode {np.sqrt(np.mean((s1 - s2) ** 2)) / rms:.1e} "
                       f"(max {np.max(np.abs(s1 - s2)) / rms:.1e})")
        ref = signal(m, 200.0, a.duration, a.rate)
        sf = signal(fourier.with_params(speed=rpm), 100.0, a.duration, a.rate)
        gap = np.sqrt(np.mean((sf - ref) ** 2)) / float(np.std(ref))
        print(f"{rpm:g} rpm: table, step against half step: " + "; ".join(row)
              + f"; Fourier H={fourier.n_harmonics} against table: {gap:.1e}", flush=True)


if __name__ == "__main__":
    main()
