"""Benchmark of a grazing (contact-loss) curve of the paper's device: the reduced CATT device
(Tables 1 and 2, xi1 = xi2 = 0.05, consistent interpretation), the drive flank of the
planet-ring mesh ``pq``, followed in (Omega, T_D) over the paper's Omega range [0.1, 4] and
T_D in [0, 20 kN m]. The box holds two components of the curve (a scan of T_D at Omega = 0.5,
1, 2 and 3.5 finds contact changes at 1 and 3.5 only): one from Omega = 3.5 (the period-1 orbit
loses contact at T_D ~ 1.9 kN m; the curve leaves the box at Omega ~ 2.45 and ~ 4.05) and the
resonance tongue from Omega = 1 (Omega ~ 0.91 to ~ 1.07). Both are timed, together. Warm: the
kernels are compiled first (one untimed run).
Also the gear pair's contact-loss curve (Omega in [0.5, 2], Fa in [0, 0.5]) for scale.

    .venv/bin/python bench/grazing.py [--repeat 3] [--write]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

import geardyn

#: The target: a grazing curve of the paper's device over its Omega range.
TARGET_S = 30.0


def catt_curves():
    p = geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05)
    m = geardyn.CATTDevice(p, interpretation="consistent")
    return [geardyn.grazing_curve(m, "Omega", "T_D", (0.1, 4.0), (0.0, 20000.0), mesh="pq",
                                  flank="drive", at=at) for at in ((3.5, 1940.0), (1.0, 2700.0))]


def pair_curve():
    m = geardyn.GearPair(zeta=0.05, kappa=0.0, Fm=0.1, Fa=0.05)
    return geardyn.grazing_curve(m, "Omega", "Fa", (0.5, 2.0), (0.0, 0.5), at=(0.8, 0.05))


def timed(fn, repeat: int) -> tuple[float, list[float], object]:
    fn()  # warm: compiled kernels loaded
    walls, out = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        walls.append(time.perf_counter() - t)
    return statistics.median(walls), walls, out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--write", action="store_true", help="record in bench/RESULTS.md")
    a = ap.parse_args()
    t_catt, walls, curves = timed(catt_curves, a.repeat)
    print(f"CATT (reduced) pq drive flank, two curves: {t_catt:.2f} s median of {a.repeat} "
          f"({', '.join(f'{w:.2f}' for w in walls)})")
    for ds in curves:
        om = ds["Omega"].values
        mu = np.hypot(ds["multiplier_real"].values, ds["multiplier_imag"].values).max(axis=1)
        print(f"  {ds.sizes['point']} points, Omega {om.min():.3f}..{om.max():.3f}, T_D "
              f"{ds['T_D'].values.min():.0f}..{ds['T_D'].values.max():.0f} N m, status "
              f"{ds.attrs['status']}, max |mu| {mu.max():.3f}; "
              f"{ds.attrs['steps_per_period']} steps per period; {ds.attrs['message']}")
    t_pair, _, gp = timed(pair_curve, a.repeat)
    print(f"GearPair drive flank: {t_pair:.2f} s median of {a.repeat}; "
          f"{gp.sizes['point']} points")
    if a.write:
        import _results as results

        results.record(
            "grazing-curve", f"grazing curve of the paper's device over its Omega range <= "
            f"{TARGET_S:.0f} s",
            f"{t_catt:.2f} s wall, median of {a.repeat} (reduced CATT, pq drive flank in "
            f"(Omega, T_D in [0, 20 kN m]): the box's two curves, "
            + ", ".join(f"{c.sizes['point']} points over Omega {c['Omega'].values.min():.2f}.."
                        f"{c['Omega'].values.max():.2f}" for c in curves)
            + f"; gear pair curve {t_pair:.2f} s, {gp.sizes['point']} points)",
            results.against(t_catt, TARGET_S), "PYTHONPATH=src .venv/bin/python "
            "bench/grazing.py --repeat 3 --write")


if __name__ == "__main__":
    main()
