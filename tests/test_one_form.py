"""The one model form (geardyn.core.one_form): a model's physics written once as per-lane
tuple-valued functions, every kernel layout generated from it. GearPair is written so; a user's
model written so (examples/gear_pair_model.py, examples/duffing_model.py) runs the same code path
and gets contact regimes, forces and frequency-response curves like a built-in."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import geardyn
from geardyn.core.coefficients import Coefficient
from geardyn.core.one_form import call_tuple, coefficient_type
from geardyn.solvers.ensemble import LaneResults, run_lanes
from geardyn.solvers.kernels import kernels_for
from geardyn.testing import check_model
from shared_models import oscillator

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "examples"))
from duffing_model import duffing_one  # noqa: E402
from gear_pair_model import gear_pair  # noqa: E402

COEFFS = dict(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
PHASES = ((0.0, 0.0), (0.3, 0.0), (0.0, -0.7), (0.3, -0.7))
#: Points (t, x, v, forcing phase) where the generated functions are evaluated: in the dead
#: zone, on both sides of it, on an edge.
POINTS = ((0.1, 1.7, 0.3, 0.4), (2.0, -1.3, -0.2, 2.5), (0.7, 0.2, 0.9, -1.1), (0.0, 1.0, 0.0, 0.0))


def _hand(x: float, v: float, s: float, c: float, zeta: float, kappa: float, Fm: float,
          Fa: float, Omega: float, phi_k: float, phi_e: float, b: float
          ) -> tuple[tuple[float, float], tuple[float, float], float]:
    """dy/dt, events and mesh force of the gear pair, written out here in Python floats (the
    operations in the model's order, so the values are those bit for bit)."""
    g = x - b if x > b else (x + b if x < -b else 0.0)
    ck = c * math.cos(phi_k) - s * math.sin(phi_k)
    ce = c * math.cos(phi_e) - s * math.sin(phi_e)
    acc = Fm + Fa * Omega * Omega * ce - 2.0 * zeta * v - (1.0 + kappa * ck) * g
    return (v, acc), (x - b, x + b), (1.0 + kappa * ck) * g + 2.0 * zeta * v


@pytest.mark.parametrize("phases", PHASES)
def test_generated_layouts_equal_the_hand_evaluated_physics(phases):
    kp, ep = phases
    m = geardyn.GearPair(**COEFFS, Omega=1.3, kappa_phase=kp, error_phase=ep)
    gen = kernels_for(m.kernel)
    p = m.params
    PT = np.ascontiguousarray(np.stack([p, p]).T)  # two lanes, coefficients PT[j, k]
    for t, x, v, ph in POINTS:
        s, c = math.sin(ph), math.cos(ph)
        dy_h, g_h, f_h = _hand(x, v, s, c, 0.05, 0.2, 0.1, 0.2, 1.3, kp, ep, 1.0)
        y = np.array([x, v])
        dy, g, o = np.zeros(2), np.zeros(2), np.zeros(1)
        gen.rhs(t, y, dy, p, s, c)
        gen.events(t, y, g, p, s, c)
        gen.observe(t, y, o, p, s, c)
        assert tuple(dy) == dy_h and tuple(g) == g_h and o[0] == f_h
        assert call_tuple(m.kernel.rhs, m.param_names, t, y, p, s, c) == dy_h
        assert gen.rhs_lane(t, (x, v), PT, 1, s, c, 0) == dy_h
        assert gen.events_lane(t, (x, v), PT, 1, s, c) == g_h
        assert gen.observe_lane(t, (x, v), PT, 1, s, c, 0) == (f_h,)
        Y, DY, G, O = np.array([[x, 0.0], [v, 0.0]]), np.zeros((2, 2)), np.zeros((2, 2)), \
            np.zeros((1, 2))
        T, S, C, SC = np.full(2, t), np.array([s, 0.0]), np.array([c, 1.0]), np.zeros((4, 2))
        gen.rhs_lanes(T, Y, DY, PT, 1, S, C, SC)
        gen.events_lanes(T, Y, G, PT, 1, S, C)
        gen.observe_lanes(T, Y, O, PT, 1, S, C, SC)
        assert tuple(DY[:, 0]) == dy_h and tuple(G[:, 0]) == g_h and O[0, 0] == f_h



def test_the_lane_scalar_forms_call_one_compiled_function():
    """Without quiet coefficients, the lane-scalar rhs and observe call one compiled function
    each (``forceinline``: LLVM inlines it, numba types the one form once for every call site),
    which gives the hand-evaluated physics bit for bit."""
    m = geardyn.GearPair(**COEFFS, Omega=1.3)
    gen = kernels_for(m.kernel)
    p = m.params
    PT = np.ascontiguousarray(np.stack([p, p]).T)
    for t, x, v, ph in POINTS:
        s, c = math.sin(ph), math.cos(ph)
        dy_h, _, f_h = _hand(x, v, s, c, 0.05, 0.2, 0.1, 0.2, 1.3, 0.0, 0.0, 1.0)
        assert gen._rhs_lane_one(t, (x, v), PT, 1, s, c) == dy_h
        assert gen._observe_lane_one(t, (x, v), PT, 1, s, c) == (f_h,)
    for fn in (gen._rhs_lane_one, gen._observe_lane_one):
        assert fn.targetoptions["forceinline"]

def test_derived_coefficients_follow_their_parameter_and_cannot_be_set():
    m = geardyn.GearPair(**COEFFS)
    names = m.param_names
    assert m.params[names.index("cos_kappa_phase")] == 1.0
    assert m.params[names.index("sin_error_phase")] == 0.0
    with pytest.raises(ValueError, match="derived from kappa_phase"):
        m.with_params(cos_kappa_phase=0.5)
    with pytest.raises(ValueError, match="derived from error_phase"):
        m.lane_params("sin_error_phase", [0.1])
    P = m.lane_params("kappa_phase", [0.0, 0.3, -1.2])
    assert list(P[:, names.index("cos_kappa_phase")]) == [1.0, math.cos(0.3), math.cos(-1.2)]
    assert list(P[:, names.index("sin_kappa_phase")]) == [0.0, math.sin(0.3), math.sin(-1.2)]
    q = m.with_params(error_phase=0.4).params
    assert q[names.index("cos_error_phase")] == math.cos(0.4)
    u = gear_pair(**COEFFS)
    with pytest.raises(ValueError, match="derived from phi_k"):
        u.with_params(sin_phi_k=0.0)
    assert u.with_params(phi_k=0.3).coefficients().cos_phi_k == math.cos(0.3)


def test_coefficient_type_pickles_by_name():
    import pickle

    cls = coefficient_type(("Omega", "zeta"))
    assert pickle.loads(pickle.dumps(cls)) is cls
    assert cls(1.0, 2.0).zeta == 2.0


def _lanes(m: geardyn.Model) -> np.ndarray:
    omegas = np.array([0.5, 0.8, 1.1, 1.6, 2.1, 2.7, 0.9, 1.3])
    names = dict(zip(("kappa_phase", "error_phase"), ("phi_k", "phi_e"), strict=True))
    rows = []
    for j, om in enumerate(omegas):
        kp, ep = PHASES[j % 4]
        if isinstance(m, geardyn.GearPair):
            rows.append(m.with_params(Omega=om, kappa_phase=kp, error_phase=ep).params)
        else:
            rows.append(m.with_params(Omega=om, **{names["kappa_phase"]: kp,
                                                   names["error_phase"]: ep}).params)
    return np.array(rows)


def test_phased_gear_pair_matches_the_reference_integrator():
    m = geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.1, Omega=0.8, kappa_phase=0.9,
                         error_phase=-0.4)
    T = 2.0 * math.pi / 0.8
    ds = geardyn.simulate(m,
                          run=geardyn.RunSettings(transient=0.0, samples=4, steps_per_period=512))
    ref = geardyn.reference_solution(m, m.initial_state(), T * np.arange(1, 5))
    np.testing.assert_allclose(ds["poincare"].values[1:], ref, atol=2e-8)


def test_user_gear_pair_equals_gear_pair_bitwise():
    """The user's gear pair (examples/gear_pair_model.py, on the pointer path, the one form's
    default) against GearPair: sweep lanes, bifurcation diagram and monodromy bit for bit. Its
    Lyapunov exponents (lane blocks, k = 1 and the spectrum) against GearPair's bit for bit:
    tests/test_pointer_path.py (the spectrum's workers of GearPair compiled there alone)."""
    pair, user = geardyn.GearPair(**COEFFS), gear_pair(**COEFFS)
    assert kernels_for(user.kernel).FUSED
    run = geardyn.RunSettings(transient=300.0, samples=6, steps_per_period=64)
    r_pair = run_lanes(pair, _lanes(pair), pair.initial_state(), run=run)
    r_user = run_lanes(user, _lanes(user), user.initial_state(), run=run)
    for name in LaneResults.__dataclass_fields__:
        np.testing.assert_array_equal(getattr(r_user, name), getattr(r_pair, name),
                                      err_msg=name)
    om = np.linspace(0.5, 2.5, 9)
    a = geardyn.bifurcation(pair, "Omega", om, run=geardyn.RunSettings(transient=200.0, samples=10))
    b = geardyn.bifurcation(user, "Omega", om, run=geardyn.RunSettings(transient=200.0, samples=10))
    for name in ("poincare", "contact", "force_peak", "force_rms", "dynamic_factor"):
        np.testing.assert_array_equal(b[name].values, a[name].values, err_msg=name)
    assert set(a["contact"].values.ravel()) >= {"none", "single"}
    orb_p = geardyn.periodic_orbit(pair.with_omega(0.9))
    orb_u = geardyn.periodic_orbit(user.with_omega(0.9))
    np.testing.assert_array_equal(orb_u.monodromy, orb_p.monodromy)


def test_user_mesh_gets_a_frequency_response_matching_linear_theory():
    # teeth always in contact (Fm >> the response): u = x - b obeys the linear oscillator
    # u'' + 2 zeta u' + u = Fm + Fa Omega^2 cos(Omega t), amplitude |H| = Fa Omega^2 / |1 -
    # Omega^2 + 2 i zeta Omega|; the mesh force u + 2 zeta u' peaks at Fm + |H| |1 + 2 i zeta
    # Omega|, the dynamic factor that over the static force Fm
    zeta, Fm, Fa = 0.1, 2.0, 0.02
    user = gear_pair(zeta=zeta, kappa=0.0, Fm=Fm, Fa=Fa)
    om = np.array([0.5, 0.8, 1.2, 1.6])
    ds = geardyn.frequency_response(user, om,
                                    run=geardyn.RunSettings(transient=300.0, samples=20,
                                                            steps_per_period=256))
    H = np.abs(Fa * om**2 / (1.0 - om**2 + 2j * zeta * om))
    for sweep in range(2):
        assert list(ds["contact"].values[sweep, :, 0]) == ["none"] * om.size
        np.testing.assert_allclose(ds["dte_amplitude"].values[sweep, :, 0], H, rtol=1e-5)
        peak = Fm + H * np.abs(1.0 + 2j * zeta * om)
        np.testing.assert_allclose(ds["dynamic_factor"].values[sweep, :, 0], peak / Fm,
                                   rtol=1e-4)


def _duffing_models(delta: float = 0.3, gamma: float = 0.1, omega: float = 1.2):
    one = geardyn.UserModel.from_one_form(
        duffing_one, params={"delta": delta, "gamma": gamma, "Omega": omega},
        states=("x", "v"), initial_state=(1.0, 0.0), natural_frequency=math.sqrt(2.0),
        name="Duffing")
    # the same double-well Duffing oscillator, x'' + delta x' - x + x^3 = gamma cos(Omega t), in
    # the legacy plain form
    legacy = oscillator(zeta=delta / 2, k=-1.0, beta=1.0, F=gamma, Omega=omega,
                        natural_frequency=math.sqrt(2.0))
    return one, legacy


def test_duffing_one_form_through_simulate_sweep_lyapunov_and_orbits():
    delta = 0.3
    one, legacy = _duffing_models(delta)
    assert kernels_for(one.kernel).FUSED
    y0 = one.initial_state()
    T = 2.0 * math.pi / 1.2
    ds = geardyn.simulate(one,
                          run=geardyn.RunSettings(transient=0.0, samples=5, steps_per_period=256))
    ref = geardyn.reference_solution(one, y0, T * np.arange(1, 6))
    np.testing.assert_allclose(ds["poincare"].values[1:], ref, atol=1e-8)
    # the sweep's lanes equal single simulations bit for bit
    om = np.array([0.9, 1.2, 1.5])
    r = run_lanes(one, one.lane_params("Omega", om), y0,
                  run=geardyn.RunSettings(transient=60.0, samples=4, steps_per_period=64))
    for j, w in enumerate(om):
        d = geardyn.simulate(one, omega=float(w),
                             run=geardyn.RunSettings(transient=60.0, samples=4,
                                                     steps_per_period=64))
        np.testing.assert_array_equal(r.samples[j], d["poincare"].values[1:])
    # Liouville: the exponents sum to the trace of the Jacobian, -delta, and the monodromy's
    # determinant is exp(-delta T); the exponents are those of the orbit's multipliers (a
    # complex pair here: both -delta / 2, which a finite run approaches slowly)
    spec = geardyn.lyapunov(one, spectrum=True, settings=geardyn.LyapunovSettings(duration=400.0))
    assert float(np.sum(spec)) == pytest.approx(-delta, abs=1e-6)
    orb = geardyn.periodic_orbit(one)
    assert orb.status == 0
    assert float(np.linalg.det(orb.monodromy)) == pytest.approx(math.exp(-delta * T),
                                                               rel=1e-7)
    np.testing.assert_allclose(np.sort(spec), np.sort(np.log(np.abs(orb.multipliers)) / T),
                               atol=2e-3)
    np.testing.assert_allclose(orb.x, geardyn.periodic_orbit(legacy).x, atol=1e-9)


@pytest.mark.parametrize("which", ["gear pair", "duffing"])
def test_one_form_models_keep_the_model_contract(which):
    model = gear_pair(**COEFFS, Omega=1.3) if which == "gear pair" else _duffing_models()[0]
    report = check_model(model)
    assert report.ok, str(report)


def test_mesh_declarations_are_checked():
    with pytest.raises(ValueError, match="not one of the events"):
        geardyn.UserModel.from_one_form(duffing_one, {"delta": 0.3, "gamma": 0.1,
                                                      "Omega": 1.0},
                                        ("x", "v"), meshes=[("m", "x-b", "x+b")])
    with pytest.raises(ValueError, match="Python identifiers"):
        geardyn.UserModel.from_one_form(duffing_one, {"de lta": 0.3}, ("x", "v"))


def _one_form_pair(meshes, observable: str, **extra) -> geardyn.UserModel:
    """The gear pair of tests/gear_pair_model.py in the one form, with ``meshes`` and its force
    read as the observable ``observable``."""
    import gear_pair_model as gp

    return geardyn.UserModel.from_one_form(
        gp.pair_rhs, params=dict(Omega=1.0, zeta=0.05, kappa=0.0, Fm=0.1, Fa=0.05,
                                 phi_k=0.0, phi_e=0.0, b=1.0),
        derived={"cos_phi_k": ("phi_k", math.cos), "sin_phi_k": ("phi_k", math.sin),
                 "cos_phi_e": ("phi_e", math.cos), "sin_phi_e": ("phi_e", math.sin)},
        states=("x", "v"), events=gp.pair_events, event_names=("x-b", "x+b"),
        observe=gp.pair_force, observable_names=(observable,), meshes=meshes,
        natural_frequency=1.0, **extra)


def test_mesh_forces_are_what_the_meshes_declare_not_a_count_of_observables():
    """One mesh and one observable: the observable is read as the mesh force only where the
    mesh names it (a fourth entry); a mesh without it reports contact, no forces."""
    def pair(meshes):
        return _one_form_pair(meshes, "energy")

    om = np.linspace(0.8, 1.2, 3)
    plain = geardyn.bifurcation(pair([("mesh", "x-b", "x+b")]), "Omega", om,
                                run=geardyn.RunSettings(transient=50.0, samples=4))
    assert "contact" in plain and "force_peak" not in plain and "dynamic_factor" not in plain
    forced = geardyn.bifurcation(pair([("mesh", "x-b", "x+b", "energy")]), "Omega", om,
                                 run=geardyn.RunSettings(transient=50.0, samples=4))
    assert "force_peak" in forced and "force_rms" in forced


def test_the_contract_refuses_static_forces_of_meshes_without_their_forces():
    """static_forces given, but no mesh names its force observable: the dynamic factor would
    silently be missing from every sweep, so the contract (rule 1) names it."""
    def pair(meshes):
        return _one_form_pair(meshes, "F", static_forces=lambda p: (p.Fm,))

    for meshes, why in (([("mesh", "x-b", "x+b")], "but not their forces"),
                        ([], "declares no meshes")):
        report = check_model(pair(meshes), run=False, raise_on_failure=False)
        assert [r.rule.number for r in report.failed] == [1], str(report)
        assert why in str(report), str(report)
    report = check_model(pair([("mesh", "x-b", "x+b", "F")]), run=False,
                         raise_on_failure=False)
    assert report.ok, str(report)


def test_the_contract_refuses_mesh_forces_without_one_force_per_mesh():
    model = geardyn.GearPair()
    model.observable_names = ("F", "G")
    report = check_model(model, raise_on_failure=False)
    assert not report.ok and "mesh_forces" in str(report)


# ------------------------------------------------------------------------------ declarations
def declared() -> tuple[Coefficient, ...]:
    """Units, meanings and ranges of some of the user gear pair's coefficients; cos/sin of the
    error phase declared here with their function, those of the stiffness phase through
    ``derived``."""
    return (
        Coefficient("Omega", "1", "mesh frequency / natural frequency", minimum=0.0),
        Coefficient("zeta", "1", "damping ratio", minimum=0.0),
        Coefficient("kappa", "1", "relative stiffness variation", exclusive_minimum=-1.0,
                    exclusive_maximum=1.0),
        Coefficient("phi_k", "rad", "phase of the stiffness variation"),
        Coefficient("cos_phi_e", "1", "cos of the error phase", "derived", ("phi_e",),
                    derive=math.cos),
        Coefficient("sin_phi_e", "1", "sin of the error phase", "derived", ("phi_e",),
                    derive=math.sin),
    )


def declared_pair(coefficients=None, derived=None, **params):
    """The user gear pair of ``examples/gear_pair_model.py`` with declared coefficients."""
    import gear_pair_model as gp

    values = dict(Omega=1.0, zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2, phi_k=0.0, phi_e=0.0, b=1.0)
    return geardyn.UserModel.from_one_form(
        gp.pair_rhs, params={**values, **params},
        derived={"cos_phi_k": ("phi_k", math.cos), "sin_phi_k": ("phi_k", math.sin)}
        if derived is None else derived,
        coefficients=declared() if coefficients is None else coefficients, states=("x", "v"),
        events=gp.pair_events, event_names=("x-b", "x+b"), observe=gp.pair_force,
        observable_names=("F",),
        meshes=[("mesh", "x-b", "x+b", "F")], static_forces=lambda p: (p.Fm,),
        natural_frequency=1.0, name="declared pair")


def test_a_user_model_declares_units_meanings_and_ranges():
    m = declared_pair(phi_k=0.3, phi_e=-0.7)
    plain = gear_pair(**COEFFS, phi_k=0.3, phi_e=-0.7)
    assert m.param_names == plain.param_names  # the same vector, so the same kernels
    np.testing.assert_array_equal(m.params, plain.params)
    lay = m.coefficient_layout
    assert lay.slot("phi_k").coefficient.unit == "rad"
    assert lay.vocabulary()["zeta"].describe() == "damping ratio"
    assert lay.slot("Fm").coefficient == Coefficient("Fm")  # undeclared: an input of unit 1
    assert lay.slot("cos_phi_e").coefficient.kind == "derived"
    assert lay.slot("cos_phi_k").coefficient.derived_from == ("phi_k",)
    assert m.derived == {"cos_phi_k": ("phi_k", math.cos), "sin_phi_k": ("phi_k", math.sin),
                         "cos_phi_e": ("phi_e", math.cos), "sin_phi_e": ("phi_e", math.sin)}
    assert m.param_attrs("phi_k") == {"units": "rad",
                                      "long_name": "phase of the stiffness variation"}
    assert m.param_attrs("Fm") == {}
    assert m.with_params(phi_e=0.25).coefficients().sin_phi_e == math.sin(0.25)
    with pytest.raises(geardyn.ParameterError, match="^zeta: must be >= 0"):
        m.with_params(zeta=-0.01)
    with pytest.raises(geardyn.ParameterError, match="^kappa: must be < 1"):
        m.with_params(kappa=1.0)
    with pytest.raises(geardyn.ParameterError, match="^Omega: must be >= 0"):
        m.with_omega(-1.0)
    with pytest.raises(geardyn.ParameterError, match="^cos_phi_e: derived from phi_e"):
        m.with_params(cos_phi_e=1.0)
    with pytest.raises(geardyn.ParameterError, match="^zeta: must be >= 0"):
        declared_pair(zeta=-0.5)
    squared = declared_pair(derived={"cos_phi_k": ("phi_k", math.cos),
                                     "sin_phi_k": ("phi_k", math.sin),
                                     "Omega2": ("Omega", lambda w: w * w)})
    assert m.omega_is_entry and not squared.omega_is_entry  # Omega moves Omega2
    assert squared.with_omega(3.0).coefficients().Omega2 == 9.0
    P = squared.lane_params("Omega", [2.0, 0.5])
    assert list(P[:, squared.param_index("Omega2")]) == [4.0, 0.25]


def test_a_user_models_declarations_are_checked_naming_the_field():
    cases = [
        ([Coefficient("zeta2", "1", "typo")], "coefficients: 'zeta2' is not among params"),
        ([("zeta", "1")], r"coefficients\[0\]: a geardyn.core.coefficients.Coefficient"),
        ([Coefficient("zeta"), Coefficient("zeta")], "'zeta' is declared twice"),
        ([Coefficient("zeta", kind="derived", derived_from=("kappa",), derive=abs)],
         "'zeta' has a value in params, so it is an input"),
        ([Coefficient("c", kind="derived", derived_from=("kappa",))], "'c' is derived; give"),
        ([Coefficient("c", kind="derived", derived_from=("nope",), derive=abs)],
         "derived 'c': derived from 'nope', which is not among params"),
        ([Coefficient("cos_phi_k", kind="derived", derived_from=("phi_k",), derive=abs)],
         "'cos_phi_k' is declared in derived too"),
    ]
    for coefficients, message in cases:
        with pytest.raises(ValueError, match=message):
            declared_pair(coefficients)
    with pytest.raises(ValueError, match="^zeta: unit must be a string"):
        declared_pair([Coefficient("zeta", 1)])
    with pytest.raises(ValueError, match="derived 'c': needs"):
        declared_pair((), derived={"c": "phi_k"})
    with pytest.raises(ValueError, match="coefficients: a sequence of"):
        declared_pair(Coefficient("zeta"))


def test_a_user_models_sweep_axis_carries_its_declared_unit():
    """A sweep in a declared phase: the axis has its unit and meaning, and each lane is the model
    with that phase (derived cos/sin follow it per lane)."""
    m = declared_pair()
    phases = np.array([0.0, 1.3])
    ds = geardyn.bifurcation(m, "phi_k", phases, run=geardyn.RunSettings(transient=40.0, samples=4))
    assert ds["phi_k"].attrs == {"units": "rad", "long_name": "phase of the stiffness variation"}
    for k, phase in enumerate(phases):
        one = geardyn.bifurcation(m.with_params(phi_k=float(phase)), "Omega", [1.0],
                                  run=geardyn.RunSettings(transient=40.0, samples=4))
        np.testing.assert_allclose(ds["poincare"].values[k], one["poincare"].values[0],
                                   rtol=1e-12, atol=1e-12)
    om = geardyn.bifurcation(m, "Omega", [0.9, 1.1],
                             run=geardyn.RunSettings(transient=40.0, samples=4))
    assert om["Omega"].attrs["long_name"] == "mesh frequency / natural frequency"
