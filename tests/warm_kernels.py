"""Compile the built-in models' kernels once, before the test workers start (``make test``).

Every test worker (pytest-xdist) is a separate process, and numba compiles a kernel in the first
process that needs it and finds no cached copy; two workers that start on the same model compile
its kernels twice, side by side, one core each. This script compiles each built-in model's
kernels that the tests use (``WARM``: sweep, trajectory, Lyapunov lane blocks, monodromy,
run-up), and those of the user models the tests share (``tests/shared_models.py``), in
its own process, the models spread over ``--jobs`` processes (longest first, ``COST``), through
the public API with the argument types the tests use, so that the workers load them from the
on-disk cache instead (a worker that needs a kernel the other is compiling waits for it,
idle). With a warm cache it only loads them (a few seconds). Running it is an optimisation:
the tests do not depend on it.

    python tests/warm_kernels.py --jobs 2
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))


#: What the default test suite runs on each conformance case and shared test model (so that the
#: warm-up compiles no kernel that the tests would not): sweep = bifurcation, trajectory =
#: simulate, lyapunov = one lane of the Lyapunov lane blocks, lanes = lyapunov_lanes on two
#: lanes (the same block workers, where their lanes take the same lane form), spectrum = one lane
#: of them with every exponent (the spectrum's workers), orbit = the monodromy kernel,
#: runup = the run-up kernel (run-ups, fault datasets; tests in both workers use those of the gear
#: pair, the spur pair and the planetary set, whose models share these cases' kernels).
#: The train's (the planetary set's) Lyapunov lane blocks are left out: no test of the default
#: run loads them (~25 s CPU). The one-form gear pair (examples/gear_pair_model.py) takes the
#: pointer path, the one form's default: its cases compile the pointer path's kernels (once for
#: every pointer model: the trajectory, the sweep, the variational lane blocks, k = 1 and the
#: spectrum's, which tests/test_one_form.py, test_codegen.py and test_pointer_path.py load, and
#: the period map of orbits and continuation) and its parts; the same one form inlined
#: (``kernel_path="lane-form"``) is compiled by no test (tests/test_pointer_path.py compares the
#: pointer path with GearPair's kernels, warmed here, and the Duffing oscillator's pointer sweep
#: with its inlined trajectory, one worker): not warmed.
WARM = {
    "CATTDevice-reduced": ("trajectory", "sweep", "lyapunov", "lanes", "orbit"),
    "CATTDevice-general": ("trajectory", "lyapunov", "lanes", "orbit"),
    "DimensionalCATT": ("trajectory", "lyapunov", "orbit"),
    "GearPair": ("trajectory", "sweep", "lyapunov", "lanes", "orbit", "runup"),
    "UserModel": ("trajectory", "lyapunov"),
    "UserModel-one-form": ("trajectory", "sweep", "lyapunov", "spectrum", "orbit"),
    "PlanetaryGearSet": ("trajectory", "sweep", "lyapunov", "orbit", "runup"),
    "SpurPair": ("trajectory", "sweep", "lyapunov", "lanes", "orbit", "runup"),
    "TrainModel": ("trajectory", "sweep", "lyapunov", "orbit"),
    # the user models the tests share (tests/shared_models.py)
    "oscillator": ("trajectory", "sweep", "lyapunov", "orbit"),
    "Lorenz": ("lyapunov", "lanes"),
}

#: CPU seconds of each case's warm-up with an empty cache (2-core AMD EPYC machine, two jobs, the
#: machine shared; the run-up kernels' share estimated from the tests that compiled them: gear
#: pair ~10, planetary set ~19, spur pair ~3). The first case of a process also compiles the
#: kernels' shared functions; the train shares the planetary set's kernels (it runs after it);
#: the one-form gear pair's (the pointer path's kernels, its parts, spectrum workers and
#: monodromy) scaled from the two cases it replaces (the one form inlined, 24, and its pointer
#: path's trajectory and sweep, 30): 88.5 s CPU against their 101.7 s, measured side by side on
#: empty caches at load ~5.
#: The cases start longest first, so that the two processes end together.
COST = {
    "PlanetaryGearSet": 137, "SpurPair": 55, "GearPair": 48, "CATTDevice-reduced": 44,
    "CATTDevice-general": 27, "oscillator": 25, "UserModel-one-form": 47, "Lorenz": 19,
    "DimensionalCATT": 16, "UserModel": 14, "TrainModel": 1,
}


def _shared(case: str) -> tuple:
    """(model, start state) of a shared test model (tests/shared_models.py)."""
    import numpy as np

    from shared_models import lorenz, oscillator

    if case == "Lorenz":
        return lorenz(), np.ones(3)
    return oscillator(zeta=0.05, F=1.0, Omega=1.3), np.zeros(2)


#: The shared test models warmed besides the conformance cases.
SHARED = ("oscillator", "Lorenz")


def _warm(case: str) -> tuple[str, float]:
    """Run each analysis of ``WARM[case]`` once on a tiny workload of the conformance case or
    shared test model ``case``."""
    import numpy as np

    import geardyn
    from conformance_cases import cases
    from geardyn.analysis.runup import steady_record
    from geardyn.errors import SlowPathWarning

    t0 = time.perf_counter()
    model, y0 = _shared(case) if case in SHARED else cases()[case]
    if model.omega_index is None:  # autonomous: lanes of its own coefficients, from y0
        omega, lanes, start = 1.0, np.tile(model.params, (2, 1)), {"y0": y0}
    else:
        omega = float(model.params[model.omega_index])
        lanes, start = model.lane_params("Omega", np.array([omega, 1.05 * omega])), {}
    values = np.array([omega, 1.05 * omega])
    runs = {
        "trajectory": lambda: geardyn.simulate(model, omega=omega,
                                               run=geardyn.RunSettings(transient=0.0, samples=2),
                                               y0=y0),
        "sweep": lambda: geardyn.bifurcation(model, "Omega", values,
                                             run=geardyn.RunSettings(transient=0.0, samples=2)),
        "lyapunov": lambda: geardyn.lyapunov(model, y0=y0, run=geardyn.RunSettings(transient=0.0),
                                             settings=geardyn.LyapunovSettings(duration=1.0)),
        "lanes": lambda: geardyn.lyapunov_lanes(model, lanes, **start,
                                                run=geardyn.RunSettings(transient=0.0),
                                                settings=geardyn.LyapunovSettings(duration=1.0)),
        "spectrum": lambda: geardyn.lyapunov(model, y0=y0, spectrum=True,
                                             run=geardyn.RunSettings(transient=0.0),
                                             settings=geardyn.LyapunovSettings(duration=1.0)),
        "orbit": lambda: geardyn.periodic_orbit(model, omega=omega, guess=y0,
                                                settings=geardyn.NewtonSettings(max_iter=1)),
        "runup": lambda: steady_record(model, 2, 4.0 * omega / (2.0 * np.pi), y0=y0),
    }
    failed = []
    for name in WARM[case]:
        try:
            with warnings.catch_warnings():
                if case in SHARED:  # plain UserModels on purpose: the per-lane path is expected
                    warnings.simplefilter("ignore", SlowPathWarning)
                runs[name]()
        except Exception as exc:  # noqa: BLE001 - the tests will meet it; say it, go on
            failed.append(f"{name}: {exc!r}")
    note = f" (not warmed: {'; '.join(failed)})" if failed else ""
    return case + note, time.perf_counter() - t0


def main(argv: list[str] | None = None) -> int:
    from conformance_cases import IDS

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=2, help="processes (default 2)")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    with ProcessPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        order = sorted((*IDS, *SHARED), key=lambda c: -COST[c])  # the longest first
        for case, seconds in pool.map(_warm, order):
            print(f"warm_kernels: {case} {seconds:.1f} s", flush=True)
    print(f"warm_kernels: {time.perf_counter() - t0:.1f} s in all", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
