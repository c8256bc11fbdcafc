"""Raw-coefficient overrides (``with_params(k_pq_q=..., f_c0=...)``): every derived quantity
follows the coefficients, or the override is refused with a reason (issue 10)."""

from __future__ import annotations

import numpy as np
import pytest

import geardyn
from geardyn.core.plan import default_steps_per_period, lane_steps_per_period
from geardyn.errors import ParameterError
from geardyn.solvers.kernels import kernels_for

#: The coefficients a change of Km_pq moves (omega_n depends on Km_sq only): stiffness, damping
#: and the relative stiffness variation Ka/Km (the kpq_* harmonics).
KM_PQ_COEFFICIENTS = ("k_pq_q", "k_pq_p", "c_pq_q", "c_pq_p")


@pytest.fixture(scope="module")
def device():
    return geardyn.CATTDevice(geardyn.PlanetaryParams.paper(), omega=1.1)


def rhs_and_forces(m, y):
    """The model's own kernel at phase 0 (sin 0, cos 1): mean stiffness, no error there."""
    k = kernels_for(m.kernel)
    dy, out = np.empty(m.n_states), np.empty(m.n_observables)
    p = np.ascontiguousarray(m.params)
    k.rhs(0.0, y, dy, p, 0.0, 1.0)
    k.observe(0.0, y, out, p, 0.0, 1.0)
    return dy, out


def independent_frequencies(m) -> np.ndarray:
    """Natural frequencies of the general 2N model, written here from Eq. (10) with the
    reduced vector's coefficients (carrier coupling of one set = k_sq_c / N)."""
    c = m.coefficient_values()
    n = m.params_in.n_planets
    A = np.zeros((2 * n, 2 * n))
    for i in range(n):
        s, q = 2 * i, 2 * i + 1
        A[s, 0::2] += c["k_sq_c"] / n
        A[s, s] += c["k_sq_q"]
        A[s, q] -= c["k_pq_q"]
        A[q, s] -= c["k_sq_q"]
        A[q, q] += c["k_pq_q"] + c["k_pq_p"]
    return np.sort(np.sqrt(np.linalg.eigvals(A).real))


@pytest.mark.parametrize("form", ["reduced", "general"])
def test_overriding_the_km_pq_coefficients_equals_the_physical_change(device, form):
    base = device if form == "reduced" else device.general()
    physical = base.with_params(Km_pq=4.0e9)
    names = [n for n in base.param_names
             if n.rstrip("0123456789") in KM_PQ_COEFFICIENTS or n.startswith("kpq_")]
    raw = base.with_params(**{n: physical.params[base.param_index(n)] for n in names})
    np.testing.assert_array_equal(raw.params, physical.params)
    assert raw.raw_overrides and not physical.raw_overrides
    np.testing.assert_allclose(raw.natural_frequencies(), physical.natural_frequencies(),
                               rtol=1e-12)
    np.testing.assert_allclose(raw.static_mesh_forces(), physical.static_mesh_forces(),
                               rtol=1e-12)
    np.testing.assert_allclose(raw.initial_state(), physical.initial_state(), rtol=1e-12)
    assert default_steps_per_period(raw) == default_steps_per_period(physical)
    assert default_steps_per_period(raw) > default_steps_per_period(base)
    # and they really moved from the base device's
    assert not np.allclose(raw.natural_frequencies(), base.natural_frequencies())
    assert not np.allclose(raw.initial_state(), base.initial_state())


def test_one_raw_stiffness_against_an_independent_eigenproblem_and_the_kernel(device):
    m = device.with_params(k_pq_q=3.0 * device.coefficients["k_pq_q"][0], f_c0=0.05)
    expect = independent_frequencies(m)
    np.testing.assert_allclose(m.natural_frequencies(), expect, rtol=1e-10)
    np.testing.assert_allclose(m.fastest_natural_frequency(), expect[-1], rtol=1e-12)
    assert lane_steps_per_period(m, m.params[None])[0] >= 100 * expect[-1] / 1.1
    # the quasi-static state is a fixed point of the model's own right-hand side, and the
    # static mesh forces are the forces the kernel observes there
    y = m.initial_state()
    dy, forces = rhs_and_forces(m, y)
    assert np.max(np.abs(dy)) < 1e-12 * np.max(np.abs(y))
    np.testing.assert_allclose(m.static_mesh_forces(), forces, rtol=1e-12)
    old = device.initial_state()  # the state the override replaced is not one
    assert np.max(np.abs(rhs_and_forces(m, old)[0])) > 1e-3
    assert m.coefficients["k_pq_q"][0] == pytest.approx(3.0 * device.coefficients["k_pq_q"][0])
    assert m.coefficients["f_c0"] == 0.05


def test_raw_overrides_survive_changes_that_leave_them_alone(device):
    a = device.with_params(k_pq_q=2.5).with_params(backlash=3.0e-5, Omega=0.8)
    b = device.with_params(backlash=3.0e-5, Omega=0.8).with_params(k_pq_q=2.5)
    np.testing.assert_array_equal(a.params, b.params)
    assert a.raw_overrides == {"k_pq_q": 2.5}
    P = device.with_params(k_pq_q=2.5).lane_params("xi", [0.02, 0.1])
    np.testing.assert_array_equal(P[:, device.param_index("k_pq_q")], [2.5, 2.5])
    g = device.with_params(k_sq_c=0.1, k_pq_q=2.5).general()
    np.testing.assert_allclose(g.natural_frequencies(),
                               device.with_params(k_sq_c=0.1, k_pq_q=2.5).natural_frequencies(),
                               rtol=1e-10)
    assert g.params[g.param_index("k_sq_c2")] == pytest.approx(0.1 / 4)
    one = device.general().with_params(k_sq_c2=0.5)
    assert one.coefficients["k_sq_c"].tolist()[1] == 0.5
    assert one.coefficients["k_sq_c"][0] == device.coefficients["k_sq_c"][0]
    with pytest.raises(ParameterError, match="^spare3: "):
        device.general().with_params(spare3=1.0)


@pytest.mark.parametrize("first,then,field", [
    (dict(k_pq_q=2.5), dict(Km_sq=1.0e9), "k_pq_q"),     # omega_n moves every coefficient
    (dict(c_sq_q=0.2), dict(xi1=0.1), "c_sq_q"),         # the damping ratio sets it
    (dict(f_c0=0.05), dict(T_D=1000.0), "f_c0"),
])
def test_a_physical_change_that_would_undo_an_override_is_refused(device, first, then, field):
    with pytest.raises(ParameterError, match=f"^{field}: set as a raw coefficient"):
        device.with_params(**first).with_params(**then)


@pytest.mark.parametrize("name", ["n_harmonics", "n_blocks", "spare"])
def test_structural_coefficients_are_refused(device, name):
    with pytest.raises(ParameterError, match=f"^{name}: "):
        device.with_params(**{name: 2.0})
    with pytest.raises(ParameterError, match=f"^{name}: "):
        device.lane_params(name, [2.0, 3.0])


def test_raw_overrides_have_no_body_angle_form(device):
    with pytest.raises(ParameterError, match="k_pq_q: a raw coefficient has no counterpart"):
        device.with_params(k_pq_q=2.5).dimensional()
    with pytest.raises(ParameterError, match="must be finite"):
        device.with_params(k_pq_q=float("nan"))


def test_gear_pair_overrides_are_validated_and_followed():
    g = geardyn.GearPair(Fm=0.1).with_params(Fm=0.3)
    assert g.initial_state()[0] == pytest.approx(1.3)
    assert g.static_mesh_forces()[0] == 0.3
    with pytest.raises(ValueError, match="kappa"):
        g.with_params(kappa=1.5)
    with pytest.raises(KeyError, match="no parameter"):
        g.with_params(stiffness=2.0)
