"""Validated parameters: the paper's values, unit strings, every kind of bad input, changes by the
paper's names, per-planet and derived overrides, and the three interpretations."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from pydantic import ValidationError

from geardyn import CATTDevice, Mesh, PlanetaryParams, PlanetOverride
from geardyn.cli.errors import format_error

MESH = dict(
    mean_stiffness=0.825e9, stiffness_amplitude=0.2e9, backlash=5e-5, error=1e-5,
    damping_ratio=0.05,
)


# --------------------------------------------------------------------------- paper values
def test_paper_values_are_tables_1_and_2_in_si():
    p = PlanetaryParams.paper()
    assert p.n_planets == 4
    assert (p.sun.teeth, p.inside_planet.teeth, p.outside_planet.teeth) == (40, 30, 40)
    for g in (p.sun, p.inside_planet, p.outside_planet):
        assert g.module == 3e-3
        assert g.face_width == 0.015
        assert g.pressure_angle == pytest.approx(math.radians(20.0), rel=1e-14)
    assert p.sun.base_radius == 0.05638
    assert p.inside_planet.base_radius == 0.04229
    assert p.outside_planet.base_radius == 0.05638
    assert p.inside_planet.inertia == 7.13e-4
    assert p.outside_planet.inertia == 0.002
    assert p.carrier.inertia == 7.58e-3
    assert (p.carrier.r_c1, p.carrier.r_c2) == (0.105, 0.21)
    assert p.sun_mesh.mean_stiffness == 0.825e9
    assert p.planet_mesh.mean_stiffness == 1.0e9
    for m in (p.sun_mesh, p.planet_mesh):
        assert m.stiffness_amplitude == 0.2e9
        assert m.backlash == 5e-5
        assert m.error == 1e-5
        assert m.damping_ratio == 0.05
    assert (p.loads.T_D, p.loads.A1, p.loads.A2) == (1500.0, 600.0, 900.0)
    assert (p.loads.B1, p.loads.B2, p.loads.Lambda) == (0.0, 0.0, 0.0)
    assert p.b_c == 1e-5


# --------------------------------------------------------------------------- units
@pytest.mark.parametrize(
    ("field", "text", "si"),
    [
        ("backlash", "50 um", 5e-5),
        ("backlash", "0.05 mm", 5e-5),
        ("mean_stiffness", "0.825e9 N/m", 0.825e9),
        ("mean_stiffness", "825 N/um", 0.825e9),
        ("error", "10 micrometer", 1e-5),
    ],
)
def test_mesh_unit_strings(field, text, si):
    m = Mesh(**{**MESH, field: text})
    assert getattr(m, field) == si


def test_torque_and_angle_unit_strings():
    p = PlanetaryParams.paper(T_D="1500 N m", A1="0.6 kN*m", psi1="20 deg")
    assert p.loads.T_D == 1500.0
    assert p.loads.A1 == 600.0
    assert p.loads.psi1 == pytest.approx(math.radians(20.0), rel=1e-14)


@pytest.mark.parametrize(
    ("field", "text"),
    [("backlash", "50 kg"), ("mean_stiffness", "1e9 N"), ("error", "3 furlongs per gram")],
)
def test_wrong_units_rejected_naming_the_field(field, text):
    with pytest.raises(ValidationError) as info:
        Mesh(**{**MESH, field: text})
    line = format_error(info.value)
    assert line.startswith(f"{field}:")
    assert repr(text) in line


# --------------------------------------------------------------------------- bad input
def _paper_data() -> dict:
    return PlanetaryParams.paper().model_dump()


def _with(path: tuple, value) -> dict:
    data = _paper_data()
    target = data
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    return data


BAD = [
    (("sun_mesh", "mean_stiffness"), -1.0),
    (("sun_mesh", "mean_stiffness"), 0.0),
    (("planet_mesh", "mean_stiffness"), float("inf")),
    (("inside_planet", "inertia"), -7.13e-4),
    (("outside_planet", "inertia"), 0.0),
    (("sun", "mass"), 0.0),
    (("inside_planet", "mass"), -1.0),
    (("carrier", "inertia"), float("nan")),
    (("sun_mesh", "backlash"), -1e-6),
    (("planet_mesh", "damping_ratio"), -0.05),
    (("sun_mesh", "damping_ratio"), float("nan")),
    (("loads", "T_D"), float("inf")),
    (("n_planets",), 0),
    (("sun", "teeth"), 0),
    (("carrier", "colour"), "red"),
    (("sun_mesh", "stiffnes"), 1e9),
]


@pytest.mark.parametrize(("path", "value"), BAD, ids=[".".join(p) for p, _ in BAD])
def test_bad_input_names_field_and_value(path, value):
    with pytest.raises(ValidationError) as info:
        PlanetaryParams.model_validate(_with(path, value))
    line = format_error(info.value)
    assert line.startswith(".".join(path) + ":"), line
    assert f"(got {value!r})" in line, line
    assert "\n" not in line


def test_unknown_top_level_key():
    data = _paper_data()
    data["gears"] = 3
    with pytest.raises(ValidationError) as info:
        PlanetaryParams.model_validate(data)
    assert format_error(info.value).startswith("gears: unknown key")


def test_unknown_derived_override_named():
    with pytest.raises(ValidationError) as info:
        PlanetaryParams.paper(derived={"omega_m": 3.0e4})
    line = format_error(info.value)
    assert "derived" in line and "'omega_m'" in line


def test_derived_override_must_be_positive():
    with pytest.raises(ValidationError) as info:
        PlanetaryParams.paper(derived={"omega_n": -1.0})
    line = format_error(info.value)
    assert line.startswith("derived.omega_n:") and "(got -1.0)" in line


def test_stiffness_amplitude_cannot_make_stiffness_negative():
    with pytest.raises(ValidationError) as info:
        PlanetaryParams.paper(Ka=0.9e9)
    line = format_error(info.value)
    assert line.startswith("sun_mesh:") and "stiffness_amplitude" in line


def test_pressure_angle_in_degrees_by_mistake():
    with pytest.raises(ValidationError) as info:
        PlanetaryParams.model_validate(_with(("sun", "pressure_angle"), 20.0))
    assert format_error(info.value).startswith("sun.pressure_angle:")


# --------------------------------------------------------------------------- replace
def test_replace_with_paper_names():
    p = PlanetaryParams.paper()
    q = p.replace(xi1=0.1, backlash="30 um", B1=100.0, Lambda=2.0, N=3)
    assert q.sun_mesh.damping_ratio == 0.1
    assert q.planet_mesh.damping_ratio == 0.05
    assert q.sun_mesh.backlash == q.planet_mesh.backlash == 3e-5
    assert q.loads.B1 == 100.0 and q.loads.Lambda == 2.0
    assert q.n_planets == 3
    assert p.sun_mesh.damping_ratio == 0.05  # the original is unchanged (frozen)
    assert PlanetaryParams.paper(xi=0.2).planet_mesh.damping_ratio == 0.2


def test_replace_unknown_name_raises_key_error():
    with pytest.raises(KeyError) as info:
        PlanetaryParams.paper().replace(xi3=0.1)
    assert "xi3" in format_error(info.value)


def test_frozen():
    p = PlanetaryParams.paper()
    with pytest.raises(ValidationError):
        p.n_planets = 3  # type: ignore[misc]


# --------------------------------------------------------------------------- planets
def test_per_planet_override_mistunes_one_set():
    planets = [PlanetOverride() for _ in range(4)]
    planets[0] = PlanetOverride(sun_mesh={"mean_stiffness": "0.9e9 N/m"})
    p = PlanetaryParams.paper(planets=planets)
    assert not p.identical_planets
    assert p.planet_set(0)[0].mean_stiffness == 0.9e9
    assert p.planet_set(1)[0].mean_stiffness == 0.825e9
    m = CATTDevice(p)
    assert not m.reduced and m.n_states == 16
    k = m.coefficients["k_sq_q"]
    assert k[0] / k[1] == pytest.approx(0.9 / 0.825, rel=1e-12)


def test_identical_overrides_keep_reduced_model():
    p = PlanetaryParams.paper(planets=[PlanetOverride() for _ in range(4)])
    assert p.identical_planets
    assert CATTDevice(p).reduced


@pytest.mark.parametrize("count", [1, 3, 5])
def test_planets_list_length_must_equal_n(count):
    with pytest.raises(ValidationError) as info:
        PlanetaryParams.paper(planets=[PlanetOverride() for _ in range(count)])
    line = format_error(info.value)
    assert "planets" in line and str(count) in line and "n_planets is 4" in line


def test_bad_per_planet_value_named():
    planets = [{"planet_mesh": {"damping_ratio": -1.0}}] + [{}] * 3
    with pytest.raises(ValidationError) as info:
        PlanetaryParams.paper(planets=planets)
    line = format_error(info.value)
    assert line.startswith("planets[0].planet_mesh.damping_ratio:") and "(got -1.0)" in line


# --------------------------------------------------------------------------- derived overrides
def test_derived_override_changes_omega_n():
    m = CATTDevice(PlanetaryParams.paper(derived={"omega_n": 3.0e4}))
    assert m.omega_n == 3.0e4
    assert CATTDevice(PlanetaryParams.paper()).omega_n != pytest.approx(3.0e4)


def test_derived_override_of_per_planet_quantity():
    m = CATTDevice(PlanetaryParams.paper(derived={"m_q": 1.0}))
    np.testing.assert_array_equal(m.derived.m_q, np.ones(4))


# --------------------------------------------------------------------------- interpretations
def _table1_masses():
    """Solid steel discs, 15 mm wide, at the pitch radii 60/45/60 mm (independent of the code)."""

    def disc(r):
        return 7850.0 * math.pi * r**2 * 0.015

    return disc(0.060), disc(0.045), disc(0.060)  # sun, inside planet, outside planet


def test_interpretations_give_expected_carrier_mass():
    _, m_q, m_p = _table1_masses()
    J_c, r_c1, r_c2, n = 7.58e-3, 0.105, 0.21, 4
    expected = {
        "consistent": (J_c + n * (m_p * r_c2**2 + m_q * r_c1**2)) / r_c1**2,
        "carrier-only": J_c / r_c1**2,
        "as-printed": (J_c + n * (m_p * r_c2 + m_q * r_c1)) / r_c1**2,
    }
    assert expected["consistent"] == pytest.approx(24.99, abs=0.01)
    assert expected["carrier-only"] == pytest.approx(0.6875, abs=1e-4)
    assert expected["as-printed"] == pytest.approx(130.7, abs=0.05)
    p = PlanetaryParams.paper()
    for interp, M_c in expected.items():
        assert CATTDevice(p, interpretation=interp).derived.M_c == pytest.approx(M_c, rel=1e-9)


def test_interpretations_omega_n():
    p = PlanetaryParams.paper()
    M_s = 0.002 / 0.05638**2
    for interp in ("consistent", "carrier-only", "as-printed"):
        m = CATTDevice(p, interpretation=interp)
        M_c = m.derived.M_c
        inv = 1.0 / M_s + 1.0 / M_c
        want = math.sqrt(0.825e9 * inv) if interp != "as-printed" else math.sqrt(0.825e9 / inv)
        assert m.omega_n == pytest.approx(want, rel=1e-12)


def test_unknown_interpretation_rejected():
    with pytest.raises(ValueError, match="interpretation"):
        CATTDevice(PlanetaryParams.paper(), interpretation="printed")  # type: ignore[arg-type]


# --------------------------------------------------------------------------- derived, by hand
def _paper_by_hand(interpretation: str) -> dict[str, float]:
    """Every quantity ``geardyn params show`` lists for the paper's device, from Tables 1 and 2
    and the model notes (Eqs. 6, 9, 10, 11; solid steel discs, 7850 kg/m^3, 15 mm wide, at the
    pitch radii m z / 2; J_s = J_p; r_bc = r_c1 = 60 + 45 mm, r_c2 = 105 + 45 + 60 mm; carrier
    arm of a sun-planet force r_bs cos 20 deg), computed here without the library."""
    n, xi1, xi2, b_c = 4, 0.05, 0.05, 1e-5
    km_sq, km_pq, t_d, a1, a2 = 0.825e9, 1.0e9, 1500.0, 600.0, 900.0
    r_bs, r_bq, r_bp = 0.05638, 0.04229, 0.05638
    j_q, j_p, j_c = 7.13e-4, 0.002, 7.58e-3
    j_s = j_p
    r_c1, r_c2 = 0.105, 0.210
    r_bc, arm = r_c1, r_bs * math.cos(math.radians(20.0))
    m_s, m_q, m_p = (7850.0 * math.pi * (3e-3 * z / 2) ** 2 * 0.015 for z in (40, 30, 40))
    M_s, M_q, M_p = j_s / r_bs**2, j_q / r_bq**2, j_p / r_bp**2
    j_c_eff = {"consistent": j_c + n * (m_p * r_c2**2 + m_q * r_c1**2),
               "carrier-only": j_c,
               "as-printed": j_c + n * (m_p * r_c2 + m_q * r_c1)}[interpretation]
    M_c = j_c_eff / r_bc**2
    inv = 1 / M_s + 1 / M_c
    printed = interpretation == "as-printed"
    w_n = math.sqrt(km_sq / inv) if printed else math.sqrt(km_sq * inv)
    gamma = 1 / w_n if printed else 1.0  # Eq. (10)'s carrier damping typo, as printed
    c_sq = 2 * xi1 * math.sqrt(km_sq / (1 / M_s + 1 / M_q))
    c_pq = 2 * xi2 * math.sqrt(km_pq / (1 / M_p + 1 / M_q))
    k = {"k_sq_c": r_c1 * arm * km_sq / (M_c * r_bc**2 * w_n**2),
         "k_sq_q": km_sq / (M_q * w_n**2), "k_pq_q": km_pq / (M_q * w_n**2),
         "k_pq_p": km_pq / (M_p * w_n**2)}
    out = dict(m_s=m_s, m_q=m_q, m_p=m_p, J_s=j_s, M_s=M_s, M_q=M_q, M_p=M_p, r_bc=r_bc,
               J_c_eff=j_c_eff, M_c=M_c, arm=arm, omega_n=w_n, C_sq=c_sq, C_pq=c_pq, **k,
               c_sq_c=gamma * r_c1 * arm * c_sq / (M_c * r_bc**2 * w_n),
               c_sq_q=c_sq / (M_q * w_n), c_pq_q=c_pq / (M_q * w_n), c_pq_p=c_pq / (M_p * w_n),
               b_sq=5e-5 / b_c, E_sq=1e-5 / b_c,
               f_p0=a1 / (M_p * r_bp * w_n**2 * b_c),
               f_c0=r_c1 * (t_d - a2) / (M_c * r_bc**2 * w_n**2 * b_c))
    # Eq. (10) linearised, every planet set alike: N - 1 sets move against each other (the
    # carrier sees no net force), one in phase (the carrier term counts N times)
    modes = []
    for carrier in (0.0, n * k["k_sq_c"]):
        K = np.array([[k["k_sq_q"] + carrier, -k["k_pq_q"]],
                      [-k["k_sq_q"], k["k_pq_q"] + k["k_pq_p"]]])
        modes.append(np.sqrt(np.sort(np.linalg.eigvals(K).real)))
    out["modes"] = np.sort(np.concatenate([np.repeat(modes[0], n - 1), modes[1]]))
    # statics under the mean loads: the mesh deflections beyond the backlash, dimensionless
    K = np.array([[k["k_sq_q"] + n * k["k_sq_c"], -k["k_pq_q"]],
                  [-k["k_sq_q"], k["k_pq_q"] + k["k_pq_p"]]])
    u_sq, u_pq = np.linalg.solve(K, [out["f_c0"], out["f_p0"]])
    out["F_sq"], out["F_pq"] = km_sq * b_c * u_sq, km_pq * b_c * u_pq
    return out


def _shown(text: str) -> dict[str, float]:
    """First number of every named row of the tables ``geardyn params show`` prints."""
    rows = {}
    for line in text.splitlines():
        cells = [c.strip() for c in line.split("│")]
        if len(cells) > 3 and cells[1] and cells[2]:
            try:
                rows[cells[1]] = float(cells[2].split()[0])
            except ValueError:
                continue
    return rows


@pytest.mark.parametrize("study,interpretation", [
    (None, "consistent"), (None, "as-printed"), ("paper_fig3", "carrier-only")])
def test_params_show_default_lists_derived_quantities(capsys, study, interpretation):
    """Every derived quantity ``geardyn params show`` prints (6 significant digits) equals the
    hand computation from the paper's tables, for each interpretation."""
    from geardyn.cli.main import main

    with pytest.raises(SystemExit) as info:
        main(["params", "show", *([study] if study else []), "--interpretation", interpretation])
    out = capsys.readouterr().out
    assert info.value.code == 0, out
    want = _paper_by_hand(interpretation)
    got = _shown(out)
    names = [k for k in want if k not in ("modes", "F_sq", "F_pq")]
    assert set(names) <= set(got), sorted(set(names) - set(got))
    for name in names:
        assert got[name] == pytest.approx(want[name], rel=1e-5), name
    modes = np.array([float(v) for v in re.findall(r"│\s+\d+ │\s+([\d.e+-]+) │", out)])
    np.testing.assert_allclose(modes, want["modes"], rtol=1e-5)
    forces = re.search(r"F_sq = ([\d.e+-]+) N, F_pq = ([\d.e+-]+) N", out)
    assert forces is not None, out
    np.testing.assert_allclose([float(forces[1]), float(forces[2])],
                               [want["F_sq"], want["F_pq"]], rtol=1e-5)
