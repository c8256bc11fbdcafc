"""The pointer kernel path (``UserModel.from_one_form(..., kernel_path="pointer")``): the
trajectory and sweep kernels compiled once for every model, the model's functions compiled alone
and called through their addresses. Its results are those of the inlined path bit for bit (the
gear pair against ``GearPair`` and against the same one form inlined; also in a fresh process
that loads the callbacks and kernels from numba's cache) and within the integrator's error of
DOP853; models of other sizes run on the same compiled kernels."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import geardyn
from geardyn.core.kernel_source import KERNEL_PATHS, KernelSource
from geardyn.errors import ParameterError
from geardyn.solvers.ensemble import LaneResults, run_lanes
from geardyn.solvers.kernels import kernels_for
from geardyn.testing import check_model

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "examples"))
from duffing_model import duffing_one  # noqa: E402
from gear_pair_model import gear_pair  # noqa: E402

COEFFS = dict(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
#: Omega, phi_k, phi_e of the lanes: impacting and not, with the phases of the forcing terms.
LANES = ((0.5, 0.0, 0.0), (0.8, 0.3, 0.0), (1.1, 0.0, -0.7), (1.6, 0.3, -0.7), (2.1, 0.0, 0.0),
         (2.7, 0.3, 0.0), (0.9, 0.0, -0.7), (1.3, 0.3, -0.7))


def _rows(m: geardyn.Model) -> np.ndarray:
    if isinstance(m, geardyn.GearPair):
        return np.array([m.with_params(Omega=om, kappa_phase=kp, error_phase=ep).params
                         for om, kp, ep in LANES])
    return np.array([m.with_params(Omega=om, phi_k=kp, phi_e=ep).params for om, kp, ep in LANES])


def _duffing(kernel_path: str = "lane-form") -> geardyn.UserModel:
    return geardyn.UserModel.from_one_form(
        duffing_one, params={"delta": 0.3, "gamma": 0.1, "Omega": 1.2}, states=("x", "v"),
        initial_state=(1.0, 0.0), natural_frequency=math.sqrt(2.0), name="Duffing",
        kernel_path=kernel_path)


def test_the_pointer_path_equals_gear_pair_and_the_inlined_one_form_bitwise():
    pair, inlined = geardyn.GearPair(**COEFFS), gear_pair(**COEFFS)
    pointer = gear_pair(**COEFFS, kernel_path="pointer")
    assert pointer.kernel.kernel_path == "pointer" in KERNEL_PATHS
    run = geardyn.RunSettings(transient=300.0, samples=6, steps_per_period=64)
    results = [run_lanes(m, _rows(m), m.initial_state(), run=run)
               for m in (pair, inlined, pointer)]
    assert results[2].crossings.sum() > 0  # flagged steps: the split step ran
    for ref in results[:2]:
        for name in LaneResults.__dataclass_fields__:
            np.testing.assert_array_equal(getattr(results[2], name), getattr(ref, name),
                                          err_msg=name)
    om = np.linspace(0.5, 2.5, 9)
    a = geardyn.bifurcation(pair, "Omega", om, run=geardyn.RunSettings(transient=200.0,
                                                                       samples=10))
    b = geardyn.bifurcation(pointer, "Omega", om, run=geardyn.RunSettings(transient=200.0,
                                                                          samples=10))
    assert b.attrs["kernel_path"] == "pointer"
    for name in ("poincare", "contact", "force_peak", "force_rms", "dynamic_factor"):
        np.testing.assert_array_equal(b[name].values, a[name].values, err_msg=name)
    sa = geardyn.simulate(pair.with_omega(0.9), run=geardyn.RunSettings(transient=50.0,
                                                                        samples=5))
    sb = geardyn.simulate(pointer.with_omega(0.9), run=geardyn.RunSettings(transient=50.0,
                                                                           samples=5))
    for name in ("x", "v", "F", "poincare", "edge_crossings"):
        np.testing.assert_array_equal(sb[name].values, sa[name].values, err_msg=name)


def test_the_pointer_path_agrees_with_dop853():
    """Simulation and sweep lanes of an impacting gear pair against DOP853 at tight tolerance
    (on the same one form inlined: the reference does not go through the pointer path)."""
    coeffs = dict(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.1, phi_k=0.9, phi_e=-0.4)
    run = geardyn.RunSettings(transient=0.0, samples=4, steps_per_period=512)
    for om in (0.8, 1.7):
        pointer = gear_pair(**coeffs, Omega=om, kernel_path="pointer")
        twin = gear_pair(**coeffs, Omega=om)
        T = 2.0 * math.pi / om
        ref = geardyn.reference_solution(twin, twin.initial_state(), T * np.arange(1, 5))
        ds = geardyn.simulate(pointer, run=run)
        np.testing.assert_allclose(ds["poincare"].values[1:], ref, atol=2e-8)
        lanes = run_lanes(pointer, pointer.params[None, :], pointer.initial_state(), run=run)
        np.testing.assert_allclose(lanes.samples[0], ref, atol=2e-8)
        assert lanes.crossings.sum() > 0 if om == 0.8 else True


def test_models_of_other_sizes_run_on_the_same_compiled_kernels():
    """A model without events or observables (the Duffing oscillator) on the pointer path:
    bitwise its inlined sweep, on the gear pair's compiled sweep and trajectory (no new
    compile of the shared kernels)."""
    pair = gear_pair(**COEFFS, kernel_path="pointer")
    duff, inlined = _duffing("pointer"), _duffing()
    kp, kd = kernels_for(pair.kernel), kernels_for(duff.kernel)
    assert kp._sweep is kd._sweep and kp._shared is kd._shared and kp.part is not kd.part
    run = geardyn.RunSettings(transient=60.0, samples=4, steps_per_period=64)
    run_lanes(pair, pair.lane_params("Omega", [0.9, 1.1]), pair.initial_state(), run=run)
    compiled = len(kp._sweep._sweep_worker_form0.signatures)
    om = np.array([0.9, 1.2, 1.5])
    r = run_lanes(duff, duff.lane_params("Omega", om), duff.initial_state(), run=run)
    assert len(kd._sweep._sweep_worker_form0.signatures) == compiled
    ref = run_lanes(inlined, inlined.lane_params("Omega", om), inlined.initial_state(), run=run)
    for name in LaneResults.__dataclass_fields__:
        np.testing.assert_array_equal(getattr(r, name), getattr(ref, name), err_msg=name)


def test_the_kernel_path_is_checked_naming_the_field():
    with pytest.raises(ParameterError, match="kernel_path"):
        gear_pair(**COEFFS, kernel_path="fast")
    with pytest.raises(ValueError, match="one form"):
        KernelSource(geardyn.GearPair().kernel.rhs, path="pointer")


def test_a_pointer_model_keeps_the_model_contract():
    report = check_model(gear_pair(**COEFFS, Omega=1.3, kernel_path="pointer"))
    assert report.ok, str(report)


#: A fresh process on the pointer path: argv[1] the examples folder, argv[2] the lanes' rows
#: (.npy), argv[3] the results (.npz). Prints JSON: the cache hits of the part's callbacks and
#: of the sweep's and trajectory's entries, the bound callees their loaders brought.
_FRESH = """
import json, sys
import numpy as np
sys.path.insert(0, sys.argv[1])
import geardyn
from geardyn import _bound_calls
from geardyn.solvers.ensemble import LaneResults, run_lanes
from geardyn.solvers.kernels import kernels_for
from gear_pair_model import gear_pair

m = gear_pair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2, kernel_path="pointer")
run = geardyn.RunSettings(transient=300.0, samples=6, steps_per_period=64)
r = run_lanes(m, np.load(sys.argv[2]), m.initial_state(), run=run)
s = geardyn.simulate(m.with_omega(0.9), run=geardyn.RunSettings(transient=50.0, samples=5))
out = {name: getattr(r, name) for name in LaneResults.__dataclass_fields__}
out.update({"sim_" + name: s[name].values for name in ("x", "v", "F", "poincare")})
np.savez(sys.argv[3], **out)
k = kernels_for(m.kernel)
sweeps = [f for f in vars(k._sweep).values() if hasattr(f, "stats") and f.signatures
          and f.py_func.__module__ == k._sweep.__name__]
print(json.dumps({"callbacks": [cb.cache_hits for cb in k.part.CALLBACKS],
                  "sweep": sum(sum(f.stats.cache_hits.values()) for f in sweeps),
                  "compiled": sum(sum(f.stats.cache_misses.values()) for f in sweeps),
                  "trajectory": sum(k._shared.trajectory.stats.cache_hits.values()),
                  "loaded": len(_bound_calls._LOADED), "bind": _bound_calls.ENABLED}))
"""


def test_a_fresh_process_loads_the_pointer_path_from_the_cache(tmp_path):
    """A second process loads the model's C callbacks and the shared sweep and trajectory from
    numba's cache (bound callees brought by their callers' loaders) and gets GearPair's results
    bit for bit."""
    pair = geardyn.GearPair(**COEFFS)
    pointer = gear_pair(**COEFFS, kernel_path="pointer")
    run = geardyn.RunSettings(transient=300.0, samples=6, steps_per_period=64)
    run_lanes(pointer, _rows(pointer), pointer.initial_state(), run=run)  # cached here
    geardyn.simulate(pointer.with_omega(0.9), run=geardyn.RunSettings(transient=50.0, samples=5))
    np.save(tmp_path / "rows.npy", _rows(pointer))
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["PYTHONPATH"] = os.pathsep.join([str(Path(geardyn.__file__).parents[1]),
                                         env.get("PYTHONPATH", "")])
    examples = Path(__file__).resolve().parent.parent / "examples"
    out = subprocess.run([sys.executable, "-c", _FRESH, str(examples), str(tmp_path / "rows.npy"),
                          str(tmp_path / "out.npz")], env=env, capture_output=True, text=True,
                         timeout=900)
    assert out.returncode == 0, out.stderr[-3000:]
    hits = json.loads(out.stdout.strip().splitlines()[-1])
    assert hits["callbacks"] == [1] * 5 and hits["trajectory"] >= 1, hits
    assert hits["sweep"] >= 1 and hits["compiled"] == 0, hits
    assert hits["loaded"] >= 1 or not hits["bind"], hits  # bound callees (the block run, ...)
    got = np.load(tmp_path / "out.npz")
    ref = run_lanes(pair, _rows(pair), pair.initial_state(), run=run)
    for name in LaneResults.__dataclass_fields__:
        np.testing.assert_array_equal(got[name], getattr(ref, name), err_msg=name)
    sim = geardyn.simulate(pair.with_omega(0.9), run=geardyn.RunSettings(transient=50.0,
                                                                         samples=5))
    for name in ("x", "v", "F", "poincare"):
        np.testing.assert_array_equal(got["sim_" + name], sim[name].values, err_msg=name)
