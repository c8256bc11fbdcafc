"""Step-convergence study of SpurPair's table form, the step of geardyn.fault_dataset: the
19/48 pair of bench/fault_dataset.py with a 1.5 mm root crack, 50 N m, at ``--speeds`` rpm; the
dataset's clean signal (the mesh force F at the samples k / ``--rate``, grid points of
:func:`geardyn.analysis.runup.steady_record`) over ``--duration`` s at n steps per period of the
contact mode (n = ``--per-mode``, the step then shortened to divide the sample interval)
against the same at 2n. Prints the RMS and the largest difference relative to the signal's RMS
about its mean; and the Fourier form (default harmonics, 100 steps per mode) against the table
form at 200 per mode: the series' own error, for scale.

    .venv/bin/python bench/table_step.py [--speeds 1000 2000 3000] [--per-mode 25 50 100]
"""

from __future__ import annotations

import argparse
import math

import numpy as np

import geardyn
from geardyn.analysis.fault_dataset import clean_signal
from geardyn.analysis.runup import steady_record
from geardyn.gears import GearMesh, RootCrack, SpurGear

MESH = GearMesh(SpurGear(19, 3.2e-3, math.radians(20.0), 0.016, name="pinion"),
                SpurGear(48, 3.2e-3, math.radians(20.0), 0.016, name="wheel"))


def signal(model: geardyn.SpurPair, per_mode: float, duration: float, rate: float) -> np.ndarray:
    """The dataset's clean signal at ``per_mode`` steps per contact-mode period."""
    w = float(model.fastest_natural_frequency()[0])
    n = max(64, math.ceil(per_mode * w / model.omega))
    rec = steady_record(model, round(duration * rate), rate, steps_per_period=n)
    assert rec.status == 0
    return clean_signal(rec, model)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speeds", type=float, nargs="+", default=[1000.0, 2000.0, 3000.0])
    ap.add_argument("--per-mode", type=float, nargs="+", default=[25.0, 50.0, 100.0])
    ap.add_argument("--duration", type=float, default=0.1)
    ap.add_argument("--rate", type=float, default=20_000.0)
    a = ap.parse_args()

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
        print(f"{rpm:g} rpm: table, step against half step, RMS (max) over the signal's RMS: "
              + "; ".join(row) + f"; Fourier H={fourier.n_harmonics} against table: {gap:.2f}",
              flush=True)


if __name__ == "__main__":
    main()
