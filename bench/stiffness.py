"""Potential-energy mesh stiffness of the 19/48 spur pair (m 3.2 mm, 20 deg, b 16 mm, bores
12/35 mm), the xarray Dataset included: one mesh cycle at 360 pinion angles (target <= 50 ms),
and the hunting period (lcm(19, 48) = 912 mesh cycles, 360 angles each) with a 2 mm root crack
on one pinion tooth (target <= 1 s), and with four faulty teeth at once (a root crack, a spall,
Archard wear, a missing tooth; no target). ``--helical``: instead, the same teeth as a helical
pair (m_n 3.2 mm, beta 20 deg) by 20 thin slices, one mesh cycle at 360 angles, against the
spur pair's target of 50 ms (the healthy slices from Chebyshev interpolants, the default), with
the quadrature at every contact (``exact=True``) and the spur cycle in the same run.

Wall time: the median of ``--repeat`` calls of
:func:`geardyn.gears.potential_energy_stiffness` (:func:`geardyn.gears.helical_stiffness`)
after one warm-up call.

    .venv/bin/python bench/stiffness.py [--repeat 21] [--angles 360] [--helical] [--write]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

from geardyn.gears import (
    BrokenTooth,
    GearMesh,
    HelicalGear,
    HelicalMesh,
    RootCrack,
    Spall,
    SpurGear,
    Wear,
    helical_stiffness,
    potential_energy_stiffness,
)

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _results as results  # noqa: E402

TARGET_S = 0.050
HUNTING_TARGET_S = 1.0
HUNTING = 19 * 48  # lcm(19, 48) mesh cycles
FOUR_FAULTS = (RootCrack("2 mm", "45 deg", tooth=0),
               Spall("2 mm", "4 mm", "0.2 mm", gear="wheel", tooth=5),
               Wear("20 um", tooth=7, profile="archard"),
               BrokenTooth(gear="wheel", tooth=30))


def _mesh() -> GearMesh:
    return GearMesh(SpurGear(19, "3.2 mm", "20 deg", "16 mm", name="pinion"),
                    SpurGear(48, "3.2 mm", "20 deg", "16 mm", name="wheel"))


def measure(repeat: int, angles: int, **options: object) -> tuple[float, float]:
    """(median wall seconds of one call, mean mesh stiffness [N/m])."""
    mesh = _mesh()
    ds = potential_energy_stiffness(mesh, bore_radius=(0.012, 0.035), angles=angles, **options)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        potential_energy_stiffness(mesh, bore_radius=(0.012, 0.035), angles=angles, **options)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), float(ds.mesh_stiffness.mean())


HELICAL_SLICES = 20


def measure_helical(repeat: int, angles: int, exact: bool = False) -> tuple[float, float]:
    """(median wall seconds of one :func:`helical_stiffness` call, mean mesh stiffness)."""
    mesh = HelicalMesh(HelicalGear(19, "3.2 mm", "20 deg", "20 deg", "16 mm", name="pinion"),
                       HelicalGear(48, "3.2 mm", "20 deg", "20 deg", "16 mm", name="wheel"))
    kw = dict(bore_radius=(0.012, 0.035), angles=angles, slices=HELICAL_SLICES, exact=exact)
    ds = helical_stiffness(mesh, **kw)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        helical_stiffness(mesh, **kw)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), float(ds.mesh_stiffness.mean())


def helical_main(args: argparse.Namespace) -> None:
    """The helical case alone (``--helical``), its own row with ``--write``."""
    wall, mean = measure_helical(args.repeat, args.angles)
    exact, exact_mean = measure_helical(args.repeat, args.angles, exact=True)
    spur, _ = measure(args.repeat, args.angles)
    measured = (f"{wall * 1e3:.1f} ms wall, median of {args.repeat} ({args.angles} angles,"
                f" 19/48 teeth at m_n 3.2 mm, beta 20 deg, eps_beta 0.544, {HELICAL_SLICES}"
                f" slices, drive and coast flank, healthy slices from Chebyshev interpolants;"
                f" mean stiffness {mean:.4e} N/m, {abs(mean / exact_mean - 1):.1e} from"
                f" quadrature at every contact (exact=True), which took {exact * 1e3:.1f} ms;"
                f" the spur pair's cycle in the same run {spur * 1e3:.2f} ms)")
    print(measured)
    if args.write:
        command = (f".venv/bin/python bench/stiffness.py --helical --repeat {args.repeat}"
                   " --write")
        results.record("pe-stiffness-helical",
                       f"helical pair by {HELICAL_SLICES} slices, one mesh cycle at 360 angles"
                       " <= 50 ms (the spur pair's target)", measured,
                       results.against(wall, TARGET_S), command)


def main(argv: list[str] | None = None) -> None:
    """Run the benchmark; ``--write`` records the figure in bench/RESULTS.md."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=21)
    ap.add_argument("--angles", type=int, default=360)
    ap.add_argument("--helical", action="store_true")
    ap.add_argument("--write", action="store_true")
    args = ap.parse_args(argv)
    if args.helical:
        helical_main(args)
        return
    wall, mean = measure(args.repeat, args.angles)
    measured = (f"{wall * 1e3:.2f} ms wall, median of {args.repeat} ({args.angles} angles,"
                f" 19/48 pair; mean stiffness {mean:.4e} N/m)")
    print(measured)
    hunt_repeat = max(1, args.repeat // 4)
    hunt, hunt_mean = measure(hunt_repeat, args.angles, cycles=HUNTING,
                              faults=RootCrack("2 mm", "45 deg", tooth=0))
    hunted = (f"{hunt:.3f} s wall, median of {hunt_repeat} ({HUNTING} mesh cycles x"
              f" {args.angles} angles, 2 mm crack on pinion tooth 0; mean {hunt_mean:.4e} N/m)")
    print(hunted)
    many, many_mean = measure(hunt_repeat, args.angles, cycles=HUNTING, faults=FOUR_FAULTS)
    several = (f"{many:.3f} s wall, median of {hunt_repeat} ({HUNTING} mesh cycles x"
               f" {args.angles} angles; 2 mm crack on pinion tooth 0, 2 x 4 x 0.2 mm spall on"
               f" wheel tooth 5, 20 um Archard wear on pinion tooth 7, wheel tooth 30 missing;"
               f" mean {many_mean:.4e} N/m)")
    print(several)
    if args.write:
        command = f".venv/bin/python bench/stiffness.py --repeat {args.repeat} --write"
        results.record("pe-stiffness",
                       "potential-energy mesh stiffness, one mesh cycle at 360 angles <= 50 ms",
                       measured, results.against(wall, TARGET_S), command)
        results.record("pe-stiffness-hunting",
                       "potential-energy stiffness, 19/48 hunting period, one cracked tooth"
                       " <= 1 s", hunted, results.against(hunt, HUNTING_TARGET_S), command)
        results.record("pe-stiffness-faults",
                       "potential-energy stiffness, 19/48 hunting period, four faulty teeth"
                       " (no target)", several, "-", command)


if __name__ == "__main__":
    main()
