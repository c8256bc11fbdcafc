"""The pointer kernel path (``UserModel.from_one_form``'s default, ``kernel_path="pointer"``): the
trajectory and sweep kernels, the variational Lyapunov lane blocks and the period map (periodic
orbits, continuation) compiled once for every model, the model's functions compiled alone and
called through their addresses. Its results are those of the inlined path bit for bit (the gear
pair against ``GearPair``, the same physics in a one form inlined, whose kernels the warm-up
compiles; the Duffing oscillator against its own one form inlined, ``kernel_path="lane-form"``;
also in a fresh process that loads the callbacks and kernels from numba's cache), within the
integrator's error of DOP853 and, for an exponent, of the analytic one of a linear limit;
models of other sizes run on the same compiled kernels. The user gear pair's sweep lanes and
bifurcation diagram against GearPair's are in tests/test_one_form.py."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pytest

import geardyn
from geardyn.core.kernel_source import KERNEL_PATHS, KernelSource
from geardyn.errors import ParameterError
from geardyn.solvers._pointer_kernels import PointerLyapunov, PointerMonodromy
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


def test_the_pointer_path_equals_gear_pair_bitwise():
    """Sweep lanes (impacting among them) and ``simulate`` of the user gear pair on the pointer
    path: bitwise GearPair's (the one form inlined), every result field of the lanes (the
    bifurcation diagram of the same lanes is compared in tests/test_one_form.py)."""
    pair = geardyn.GearPair(**COEFFS)
    pointer = gear_pair(**COEFFS, kernel_path="pointer")
    assert pointer.kernel.kernel_path == "pointer" in KERNEL_PATHS
    run = geardyn.RunSettings(transient=300.0, samples=6, steps_per_period=64)
    ref, got = (run_lanes(m, _rows(m), m.initial_state(), run=run) for m in (pair, pointer))
    assert got.crossings.sum() > 0  # flagged steps: the split step ran
    for name in LaneResults.__dataclass_fields__:
        np.testing.assert_array_equal(getattr(got, name), getattr(ref, name), err_msg=name)
    sa = geardyn.simulate(pair.with_omega(0.9), run=geardyn.RunSettings(transient=50.0,
                                                                        samples=5))
    sb = geardyn.simulate(pointer.with_omega(0.9), run=geardyn.RunSettings(transient=50.0,
                                                                           samples=5))
    for name in ("x", "v", "F", "poincare", "edge_crossings"):
        np.testing.assert_array_equal(sb[name].values, sa[name].values, err_msg=name)


@pytest.mark.parametrize(("omega", "periods"), [(0.9, 400), (1.3, 2000)])
def test_a_long_located_trajectory_of_the_pointer_path_equals_gear_pairs_bitwise(omega,
                                                                                      periods):
    """``simulate`` of the pointer model with its edges located, over many periods of impacts
    (split steps): bitwise GearPair's (the one form inlined), every recorded column, the
    crossings counted and the unresolved steps."""
    models = [geardyn.GearPair(**COEFFS), gear_pair(**COEFFS, kernel_path="pointer")]
    run = geardyn.RunSettings(transient=0.0, samples=periods, steps_per_period=128,
                              locate_edges=True)
    ref, c = (geardyn.simulate(m.with_omega(omega), run=run) for m in models)
    assert c["edge_crossings"].values.sum() > 10  # impacts: the split step ran
    for name in ("x", "v", "F", "poincare", "edge_crossings"):
        np.testing.assert_array_equal(c[name].values, ref[name].values, err_msg=name)
    assert c.attrs["unresolved_steps"] == ref.attrs["unresolved_steps"]


def test_the_pointer_path_agrees_with_dop853():
    """Simulation and sweep lanes of an impacting gear pair against DOP853 at tight tolerance
    (on GearPair's functions, the same physics: the reference does not go through the pointer
    path)."""
    coeffs = dict(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.1)
    run = geardyn.RunSettings(transient=0.0, samples=4, steps_per_period=512)
    for om in (0.8, 1.7):
        pointer = gear_pair(**coeffs, phi_k=0.9, phi_e=-0.4, Omega=om, kernel_path="pointer")
        twin = geardyn.GearPair(**coeffs, kappa_phase=0.9, error_phase=-0.4, Omega=om)
        T = 2.0 * math.pi / om
        ref = geardyn.reference_solution(twin, twin.initial_state(), T * np.arange(1, 5))
        ds = geardyn.simulate(pointer, run=run)
        np.testing.assert_allclose(ds["poincare"].values[1:], ref, atol=2e-8)
        lanes = run_lanes(pointer, pointer.params[None, :], pointer.initial_state(), run=run)
        np.testing.assert_allclose(lanes.samples[0], ref, atol=2e-8)
        assert lanes.crossings.sum() > 0 if om == 0.8 else True


def test_models_of_other_sizes_run_on_the_same_compiled_kernels():
    """A model without events or observables (the Duffing oscillator) on the pointer path, on
    the gear pair's compiled sweep (no new compile of the shared kernels): its sweep lanes
    bitwise the same one form inlined (``kernel_path="lane-form"``), run lane by lane by the
    inlined trajectory kernel (a lane of an inlined sweep is its trajectory bit for bit:
    tests/test_catt_lane_forms.py; the Duffing oscillator's inlined sweep is not compiled)."""
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
    assert np.all(r.status == geardyn.Status.OK)
    for j, w in enumerate(om):
        ref = geardyn.simulate(inlined, omega=float(w), run=run)
        assert ref.attrs["status"] == geardyn.Status.OK
        np.testing.assert_array_equal(r.samples[j], ref["poincare"].values[1:], err_msg=str(w))
        np.testing.assert_array_equal(r.final[j], ref["poincare"].values[-1], err_msg=str(w))


def test_the_pointer_path_is_the_one_forms_default_and_lane_form_the_opt_out():
    """``from_one_form`` without ``kernel_path`` takes the pointer path; ``"lane-form"``
    inlines the model's functions in every kernel; a sweep records which ran (the inlined one
    form's record: GearPair's sweep, whose kernels the warm-up compiles)."""
    default = geardyn.UserModel.from_one_form(
        duffing_one, params={"delta": 0.3, "gamma": 0.1, "Omega": 1.2}, states=("x", "v"))
    assert default.kernel.kernel_path == "pointer"
    assert _duffing().kernel.kernel_path == "lane-form"
    run = geardyn.RunSettings(transient=0.0, samples=2, steps_per_period=64)
    for m, path in ((default, "pointer"), (geardyn.GearPair(), "lane-form")):
        ds = geardyn.bifurcation(m, "Omega", [1.1, 1.3], run=run)
        assert ds.attrs["kernel_path"] == path


def test_the_kernel_path_is_checked_naming_the_field():
    with pytest.raises(ParameterError, match="kernel_path"):
        gear_pair(**COEFFS, kernel_path="fast")
    with pytest.raises(ValueError, match="one form"):
        KernelSource(geardyn.GearPair().kernel.rhs, path="pointer")


def test_a_pointer_model_keeps_the_model_contract():
    report = check_model(gear_pair(**COEFFS, Omega=1.3, kernel_path="pointer"))
    assert report.ok, str(report)


#: The Lyapunov runs of the tests: short, from the lanes' start states (impacting lanes among
#: them: their flagged lanes split with the tangent vector).
LYAP_RUN = geardyn.RunSettings(transient=60.0, steps_per_period=64)
LYAP = geardyn.LyapunovSettings(duration=120.0)


def _exponents(m: geardyn.Model) -> tuple[np.ndarray, ...]:
    return geardyn.lyapunov_lanes(m, _rows(m), run=LYAP_RUN, settings=LYAP, with_status=True)


def test_the_pointer_lyapunov_lane_blocks_equal_the_inlined_one_form_bitwise():
    """``lyapunov_lanes``, ``geardyn.lyapunov`` (k = 1) and ``bifurcation(..., lyapunov=True)``
    on the pointer path (the shared lane blocks calling the model's variational step and flagged
    lanes through their addresses): bitwise those of the same one form inlined, the variational
    tangent, impacting lanes among them. The inlined one form is the built-in gear pair's (the
    same physics, bitwise the user's one form: the sweep and trajectory tests above), whose
    lane blocks the warm-up compiles."""
    inlined = geardyn.GearPair(**COEFFS)
    pointer = gear_pair(**COEFFS, kernel_path="pointer")
    kern = kernels_for(pointer.kernel, "lyapunov")
    assert isinstance(kern, PointerLyapunov)
    got, ref = _exponents(pointer), _exponents(inlined)
    for name, a, b in zip(("exponents", "stderr", "unresolved", "status"), got, ref,
                          strict=True):
        np.testing.assert_array_equal(a, b, err_msg=name)
    assert np.all(np.isfinite(got[0])) and np.all(got[3] == 0)
    assert kern._shared._lyap_var_worker_form0.signatures  # the shared lane blocks ran
    lanes = run_lanes(pointer, _rows(pointer), pointer.initial_state(),
                      run=LYAP_RUN.replace(samples=4))
    assert lanes.crossings.sum() > 0  # impacting lanes: flagged lanes split with the tangent
    one = [geardyn.lyapunov(m.with_omega(0.9), run=LYAP_RUN, settings=LYAP, with_error=True)
           for m in (pointer, inlined)]
    assert one[0] == one[1] and one[0].tangent.startswith("variational")
    om = np.linspace(0.6, 2.4, 4)
    run = geardyn.RunSettings(transient=60.0, samples=8, steps_per_period=64)
    a = geardyn.bifurcation(pointer, "Omega", om, run=run, lyapunov=True)
    b = geardyn.bifurcation(inlined, "Omega", om, run=run, lyapunov=True)
    for name in ("lyapunov", "lyapunov_err", "lyapunov_unresolved"):
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)


def _spectra(m: geardyn.Model, block_rows: int) -> tuple[np.ndarray, ...]:
    """Both exponents (k = 2) of 40 lanes (:data:`LANES` five times) of the variational lane
    blocks of ``m`` (``lyapunov_block_lanes``, as ``geardyn.lyapunov(..., spectrum=True)``
    calls them for one lane), blocks of ``block_rows`` rows (2 k + 1 a lane)."""
    kern = kernels_for(m.kernel, "lyapunov")
    P = np.tile(_rows(m), (5, 1))
    L, k, n_per = P.shape[0], 2, 64
    omega = np.ascontiguousarray(P[:, m.omega_index])
    n_tr = np.round(LYAP_RUN.transient * omega / (2.0 * math.pi)).astype(np.int64) * n_per
    n_st = np.full(L, 20 * n_per, np.int64)
    out, err = np.full((L, k), np.nan), np.full((L, k), np.nan)
    used, status, unres, n_fd = (np.zeros(L, np.int64) for _ in range(4))
    kern.lyapunov_block_lanes(P, np.tile(m.initial_state(), (L, 1)), np.ones(2), np.zeros(L),
                              2.0 * math.pi / omega / n_per, omega, np.full(L, n_per, np.int64),
                              n_tr, n_st, 10, k, 1e6, out, err, used, status, unres,
                              m.n_events, 4, block_rows, 1, True, n_fd)
    return out, err, used, status, unres, n_fd


def test_the_pointer_lyapunov_spectrum_equals_the_inlined_one_form_bitwise():
    """Spectra (k = 2 tangent vectors) on the pointer path: the shared lane blocks' spectrum
    workers, the model's variational step called once per pass of a block step, bitwise those
    of the same one form inlined, whatever the blocks (one pass of the lanes' 2 vectors, or two
    passes where 40 lanes of 2 vectors outnumber a block's 64 slots), impacting lanes among
    them (split steps with the tangent vectors); no inlined spectrum worker compiled for it.
    ``geardyn.lyapunov(..., spectrum=True)`` too. The inlined one form is the built-in gear
    pair's, as above (its spectrum workers compiled for this test alone)."""
    inlined = geardyn.GearPair(**COEFFS)
    pointer = gear_pair(**COEFFS, kernel_path="pointer")
    kern = kernels_for(pointer.kernel, "lyapunov")
    workers = [f"_lyap_spec_worker_form{j}" for j in range(3)]

    def compiled(module) -> int:
        return sum(len(getattr(module, name).signatures) for name in workers)

    before = compiled(kern._inlined())
    got = [_spectra(pointer, rows) for rows in (64, 200)]  # 12 lanes a block; 40 in one
    assert compiled(kern._inlined()) == before and compiled(kern._shared) > 0
    ref = _spectra(inlined, 64)
    for g in got:
        for name, a, b in zip(("exponents", "stderr", "used", "status", "unresolved",
                               "difference steps"), g, ref, strict=True):
            np.testing.assert_array_equal(a, b, err_msg=name)
    assert np.all(np.isfinite(ref[0])) and np.all(ref[3] == 0)
    one = [geardyn.lyapunov(m.with_omega(0.9), spectrum=True, run=LYAP_RUN, settings=LYAP,
                            with_error=True) for m in (pointer, inlined)]
    np.testing.assert_array_equal(one[0].value, one[1].value)
    np.testing.assert_array_equal(one[0].stderr, one[1].stderr)
    assert one[0].tangent.startswith("variational") and one[0].value.shape == (2,)


#: The orbit fields compared bit for bit.
ORBIT_FIELDS = ("x", "states", "monodromy", "multipliers", "eigenvectors", "observables",
                "crossings", "residuals", "trace_integral", "event_min", "event_max")
#: A short continuation of the gear pair's period-1 orbit (impacting: two mesh crossings).
CONTINUATION = dict(param="Omega", start=0.85, stop=1.0,
                    settings=geardyn.ContinuationSettings(max_points=8))


def _orbits(m: geardyn.Model) -> tuple:
    """Periodic orbits (impacting and not) and a short continuation of ``m``."""
    orbits = [geardyn.periodic_orbit(m.with_omega(om)) for om in (0.8, 1.1, 1.6)]
    return orbits, geardyn.continuation(m, **CONTINUATION)


def test_the_pointer_periodic_orbit_and_continuation_equal_gear_pairs_bitwise():
    """``periodic_orbit`` (Newton shooting on the period map and its monodromy) and
    ``continuation`` on the pointer path (the shared period map calling the model's array
    forms through their addresses): bitwise those of the one form inlined (GearPair's, whose
    monodromy kernel the warm-up compiles)."""
    inlined = geardyn.GearPair(**COEFFS)
    pointer = gear_pair(**COEFFS, kernel_path="pointer")
    kern = kernels_for(pointer.kernel, "monodromy")
    assert isinstance(kern, PointerMonodromy)
    assert not isinstance(kernels_for(inlined.kernel, "monodromy"), PointerMonodromy)
    (got, branch), (ref, ref_branch) = _orbits(pointer), _orbits(inlined)
    for a, b in zip(got, ref, strict=True):
        assert a.status == b.status == 0 and a.iterations == b.iterations
        for name in ORBIT_FIELDS:
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert sum(int(o.crossings.sum()) for o in got) > 0  # impacting orbits among them
    assert kern._shared.period_map.signatures  # the shared period map ran
    assert branch.sizes["point"] > 2 and int(branch["mesh_crossings"].sum()) > 0
    assert list(branch.data_vars) == list(ref_branch.data_vars)
    for name in branch.data_vars:
        np.testing.assert_array_equal(branch[name].values, ref_branch[name].values,
                                      err_msg=name)
    np.testing.assert_array_equal(branch["Omega"].values, ref_branch["Omega"].values)


def test_a_model_without_events_gets_its_exponent_on_the_same_lane_blocks():
    """The unforced Duffing oscillator (no switching functions) at its stable equilibrium
    x = 1 on the pointer path: the largest exponent is -delta / 2, that of its linearisation
    x'' + delta x' + 2 (x - 1) = 0 (underdamped), to the finite window's O(1 / T); on the gear
    pair's compiled lane blocks (its own compile is its callbacks: none of its inlined Lyapunov
    lane blocks compiled)."""
    pair = gear_pair(**COEFFS, kernel_path="pointer")
    geardyn.lyapunov_lanes(pair, _rows(pair)[:2], run=LYAP_RUN, settings=LYAP)
    kp = kernels_for(pair.kernel, "lyapunov")
    compiled = len(kp._shared._lyap_var_worker_form0.signatures)
    duff = _duffing("pointer").with_params(gamma=0.0)
    kd = kernels_for(duff.kernel, "lyapunov")
    assert kd._shared is kp._shared and kd.part is not kp.part and kd.part.N_SWITCHING == 0
    delta = duff.coefficients().delta
    out = geardyn.lyapunov_lanes(duff, duff.lane_params("Omega", [0.7, 1.2]), y0=(1.0, 0.0),
                                 run=geardyn.RunSettings(transient=50.0, steps_per_period=64),
                                 settings=geardyn.LyapunovSettings(duration=2000.0))
    np.testing.assert_allclose(out, -0.5 * delta, atol=2e-3)
    assert len(kd._shared._lyap_var_worker_form0.signatures) == compiled
    assert not kd._inlined()._lyap_var_worker_form1.signatures


@numba.njit(cache=True)
def atan_rhs(t, y, p, s, c):
    """A one-form rhs with an operation the dual numbers lack (atan2)."""
    return (y[1], -p.k * math.atan2(y[0], 1.0) - 0.1 * y[1] + p.F * c)


def test_a_rhs_the_duals_cannot_take_is_named_on_the_pointer_path():
    """The model's Lyapunov part (its tangent callbacks) compiles first and is refused naming
    ``settings.tangent``, numba's typing error (the operation) chained, on every call (no
    half-made part kept)."""
    m = geardyn.UserModel.from_one_form(atan_rhs, params={"k": 1.0, "F": 0.2, "Omega": 1.1},
                                        states=("x", "v"), initial_state=(0.1, 0.0),
                                        kernel_path="pointer")
    for _ in range(2):
        with pytest.raises(ParameterError, match="settings.tangent") as info:
            geardyn.lyapunov_lanes(m, m.lane_params("Omega", [1.1]),
                                   settings=geardyn.LyapunovSettings(duration=20.0))
        assert "atan2" in str(info.value.__cause__)
    assert kernels_for(m.kernel, "lyapunov")._part is None


#: A fresh process on the pointer path: argv[1] the examples folder, argv[2] the lanes' rows
#: (.npy), argv[3] the results (.npz). Prints JSON: the cache hits of the part's callbacks and
#: of the sweep's, trajectory's and period map's entries, the bound callees their loaders
#: brought.
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
e = geardyn.lyapunov_lanes(m, np.load(sys.argv[2]),
                           run=geardyn.RunSettings(transient=60.0, steps_per_period=64),
                           settings=geardyn.LyapunovSettings(duration=120.0), with_status=True)
out = {name: getattr(r, name) for name in LaneResults.__dataclass_fields__}
out.update({"sim_" + name: s[name].values for name in ("x", "v", "F", "poincare")})
out.update({f"lyapunov_{i}": v for i, v in enumerate(e)})
o = geardyn.periodic_orbit(m.with_omega(0.8))
b = geardyn.continuation(m, "Omega", 0.85, 1.0,
                         settings=geardyn.ContinuationSettings(max_points=8))
out.update({"orbit_" + name: getattr(o, name) for name in ("x", "states", "monodromy")})
out.update({"branch_" + name: b[name].values for name in ("section_point", "multiplier_abs")})
np.savez(sys.argv[3], **out)
kl = kernels_for(m.kernel, "lyapunov")
blocks = [f for f in vars(kl._shared).values() if hasattr(f, "stats")
          and f.py_func.__module__ == kl._shared.__name__]
k = kernels_for(m.kernel)
sweeps = [f for f in vars(k._sweep).values() if hasattr(f, "stats") and f.signatures
          and f.py_func.__module__ == k._sweep.__name__]
km = kernels_for(m.kernel, "monodromy")._shared
print(json.dumps({"callbacks": [cb.cache_hits for cb in k.part.CALLBACKS],
                  "period_map": sum(km.period_map.stats.cache_hits.values()),
                  "period_map_compiled": sum(km.period_map.stats.cache_misses.values()),
                  "lyapunov_callbacks": [cb.cache_hits for cb in kl.part.CALLBACKS],
                  "lane_blocks": sum(sum(f.stats.cache_hits.values()) for f in blocks),
                  "lane_blocks_compiled": sum(sum(f.stats.cache_misses.values())
                                              for f in blocks),
                  "sweep": sum(sum(f.stats.cache_hits.values()) for f in sweeps),
                  "compiled": sum(sum(f.stats.cache_misses.values()) for f in sweeps),
                  "trajectory": sum(k._sweep.trajectory.stats.cache_hits.values()),
                  "loaded": len(_bound_calls._LOADED), "bind": _bound_calls.ENABLED}))
"""


def test_a_fresh_process_loads_the_pointer_path_from_the_cache(tmp_path):
    """A second process loads the model's C callbacks and the shared sweep, trajectory and
    period map from numba's cache (bound callees brought by their callers' loaders) and gets
    GearPair's results bit for bit (the orbit's and the branch's: this process's)."""
    pair = geardyn.GearPair(**COEFFS)
    pointer = gear_pair(**COEFFS, kernel_path="pointer")
    run = geardyn.RunSettings(transient=300.0, samples=6, steps_per_period=64)
    run_lanes(pointer, _rows(pointer), pointer.initial_state(), run=run)  # cached here
    geardyn.simulate(pointer.with_omega(0.9), run=geardyn.RunSettings(transient=50.0, samples=5))
    exponents = _exponents(pointer)
    orbit = geardyn.periodic_orbit(pointer.with_omega(0.8))
    branch = geardyn.continuation(pointer, **CONTINUATION)
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
    assert hits["lyapunov_callbacks"] == [1] * 5, hits
    assert hits["lane_blocks"] >= 1 and hits["lane_blocks_compiled"] == 0, hits
    assert hits["loaded"] >= 1 or not hits["bind"], hits  # bound callees (the block run, ...)
    assert hits["period_map"] >= 1 and hits["period_map_compiled"] == 0, hits
    got = np.load(tmp_path / "out.npz")
    ref = run_lanes(pair, _rows(pair), pair.initial_state(), run=run)
    for name in LaneResults.__dataclass_fields__:
        np.testing.assert_array_equal(got[name], getattr(ref, name), err_msg=name)
    sim = geardyn.simulate(pair.with_omega(0.9), run=geardyn.RunSettings(transient=50.0,
                                                                         samples=5))
    for name in ("x", "v", "F", "poincare"):
        np.testing.assert_array_equal(got["sim_" + name], sim[name].values, err_msg=name)
    for i, ref in enumerate(exponents):
        np.testing.assert_array_equal(got[f"lyapunov_{i}"], ref, err_msg=f"lyapunov {i}")
    for name in ("x", "states", "monodromy"):
        np.testing.assert_array_equal(got["orbit_" + name], getattr(orbit, name), err_msg=name)
    for name in ("section_point", "multiplier_abs"):
        np.testing.assert_array_equal(got["branch_" + name], branch[name].values, err_msg=name)
