"""Coefficients declared once (:mod:`geardyn.core.coefficients`): the schema's indices, names,
builder, read-back and validation; every model's ``param_names`` are its declared parameters;
``with_params`` keeps one set of rules for every model; structure and workspace are never
parameters; the gear-pair study table comes from the declarations; capabilities are read from the
declaration, not probed."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import geardyn
from geardyn.analysis.dataset import model_attrs
from geardyn.analysis.frc import deflection_units, physical_axes
from geardyn.core.capabilities import Capabilities
from geardyn.core.coefficients import Coefficient, CoefficientBlock, CoefficientLayout
from geardyn.errors import ParameterError, StudyError, UnknownParameterError
from geardyn.io.toml import GearPairParams, load_study
from geardyn.models import catt, derived, gear_pair, planetary
from geardyn.models import catt_kernels as ck
from geardyn.models import planetary_kernels as pk
from geardyn.models.gear_pair_coefficients import GEAR_PAIR, INPUTS

sys.path.insert(0, str(Path(__file__).parent))
from conformance_cases import user_model  # noqa: E402
from test_planetary_kernels import busy_set  # noqa: E402

BLOCK = CoefficientBlock((
    Coefficient("w", "rad/s", "forcing frequency", minimum=0.0),
    Coefficient("k", "N/m", "stiffness", "derived", ("E", "h")),
    Coefficient("n", "1", "count", "structure", constant="N_COUNT"),
    Coefficient("scratch", "1", "cache", "workspace", default=2.0),
))


# ------------------------------------------------------------------------------ the schema
def test_block_offsets_names_and_constants():
    assert [BLOCK.offset(n) for n in ("w", "k", "n", "scratch")] == [0, 1, 2, 3]
    assert BLOCK.constants() == {"W": 0, "K": 1, "N_COUNT": 2, "SCRATCH": 3}
    assert set(BLOCK.vocabulary()) == {"w", "k"}
    assert BLOCK["k"].describe() == "stiffness [N/m] (derived from E, h)"
    with pytest.raises(KeyError, match="declared: w, k, n, scratch"):
        BLOCK.offset("x")


def test_layout_build_and_read_back_round_trip():
    lay = CoefficientLayout.of(BLOCK, (BLOCK, "1"), model="toy")
    assert lay.size == 8 and lay.names == ("w", "k", "w1", "k1")
    assert lay.all_names == ("w", "k", "n", "scratch", "w1", "k1", "n1", "scratch1")
    values = {"w": 1.5, "k": 2.0, "n": 2.0, "w1": 0.25, "k1": 3.0, "n1": 2.0}
    p = lay.build(values)
    np.testing.assert_array_equal(p, [1.5, 2.0, 2.0, 2.0, 0.25, 3.0, 2.0, 2.0])  # workspace 2
    assert lay.read(p) == {"w": 1.5, "k": 2.0, "w1": 0.25, "k1": 3.0}
    full = lay.read(p, parameters_only=False)
    np.testing.assert_array_equal(lay.build(full), p)
    assert lay.index("k1") == 5 and lay.raw_index("n1") == 6
    np.testing.assert_array_equal(lay.parameter_indices(), [0, 1, 4, 5])


def test_layout_errors_name_the_field():
    lay = CoefficientLayout.of(BLOCK, model="toy")
    with pytest.raises(ParameterError, match="^w: must be >= 0"):
        lay.validate({"w": -1.0})
    with pytest.raises(ParameterError, match="^k: must be finite"):
        lay.validate({"k": math.nan})
    with pytest.raises(ParameterError, match="^n: toy: no value given"):
        lay.build({"w": 1.0, "k": 1.0})
    with pytest.raises(UnknownParameterError, match="^q: toy has no parameter.*known: w, k"):
        lay.build({"q": 1.0})
    with pytest.raises(KeyError, match="^scratch: cache: kernel workspace of toy"):
        lay.index("scratch")
    with pytest.raises(KeyError, match="^n: count: structure of toy"):
        lay.validate({"n": 3.0})


# ------------------------------------------------------------------------------ derivations
def phase_block() -> CoefficientBlock:
    """A phase and its cos and sin, derived with their functions."""
    return CoefficientBlock((
        Coefficient("phi", "rad", "phase"),
        Coefficient("cos_phi", "1", "cos of the phase", "derived", ("phi",), derive=math.cos),
        Coefficient("sin_phi", "1", "sin of the phase", "derived", ("phi",), derive=math.sin),
    ))


def test_a_derived_coefficient_carries_its_function_and_the_layout_fills_it():
    phase = phase_block()
    lay = CoefficientLayout.of(phase, (phase, "2"), model="toy")
    assert lay.derivations() == {"cos_phi": ("phi", math.cos), "sin_phi": ("phi", math.sin),
                                 "cos_phi2": ("phi2", math.cos), "sin_phi2": ("phi2", math.sin)}
    P = np.zeros((3, 6))
    P[:, 0], P[:, 3] = [0.0, 0.5, 0.5], [1.0, -2.0, 3.0]
    assert lay.fill_derived(P) is P
    for row, (a, b) in zip(P, [(0.0, 1.0), (0.5, -2.0), (0.5, 3.0)], strict=True):
        assert list(row) == [a, math.cos(a), math.sin(a), b, math.cos(b), math.sin(b)]
    assert lay.vocabulary()["phi2"].unit == "rad" and set(lay.vocabulary()) == set(lay.names)
    for bad in (dict(kind="input", derive=math.cos),
                dict(kind="derived", derived_from=("a", "b"), derive=math.cos),
                dict(kind="derived", derived_from=("a",), derive=1.0)):
        with pytest.raises(ValueError, match="^x: derive is the function of one input"):
            Coefficient("x", **bad)
    with pytest.raises(ValueError, match="^x: unit must be a string"):
        Coefficient("x", 1.0)
    with pytest.raises(ValueError, match="^cos_phi: a derived coefficient with its function"):
        CoefficientLayout().place(["c1", "c2"], phase["cos_phi"])


def test_with_params_and_lane_params_refill_the_declared_derivations():
    """Model's own with_params and lane_params (no model override) refill a derived
    coefficient from its declaration, and refuse it naming its input."""
    block = CoefficientBlock((Coefficient("Omega"), *phase_block().entries))
    toy = geardyn.UserModel(user_model().kernel.rhs, n_states=2, params=[1.0, 0.0, 1.0, 0.0],
                            name="toy")
    toy.coefficient_layout = CoefficientLayout.of(block, model="toy")
    assert toy.derived == {"cos_phi": ("phi", math.cos), "sin_phi": ("phi", math.sin)}
    out = toy.with_params(phi=0.4)
    assert list(out.params) == [1.0, 0.4, math.cos(0.4), math.sin(0.4)]
    P = toy.lane_params("phi", [0.1, -0.2])
    np.testing.assert_array_equal(P[:, 2:], [[math.cos(0.1), math.sin(0.1)],
                                             [math.cos(-0.2), math.sin(-0.2)]])
    with pytest.raises(ParameterError, match="^cos_phi: derived from phi"):
        toy.with_params(cos_phi=0.5)
    with pytest.raises(ParameterError, match="^phi: must be a number"):
        toy.with_params(phi=True)


def test_the_gear_pair_declares_each_derived_coefficient_once():
    """GearPair.derived is read from the functions in GEAR_PAIR; its with_params and lane_params
    are Model's, and fill the cos/sin of the phases as the compiled code's libm does."""
    declared = {c.name: (c.derived_from[0], c.derive) for c in GEAR_PAIR.entries
                if c.kind == "derived"}
    assert dict(geardyn.GearPair.derived) == declared == {
        "cos_kappa_phase": ("kappa_phase", math.cos), "sin_kappa_phase": ("kappa_phase", math.sin),
        "cos_error_phase": ("error_phase", math.cos), "sin_error_phase": ("error_phase", math.sin)}
    assert "with_params" not in vars(geardyn.GearPair)
    assert "lane_params" not in vars(geardyn.GearPair)
    m = geardyn.GearPair().with_params(kappa_phase=0.3, error_phase=-1.1)
    got = m.coefficient_values()
    assert (got["cos_kappa_phase"], got["sin_kappa_phase"]) == (math.cos(0.3), math.sin(0.3))
    assert (got["cos_error_phase"], got["sin_error_phase"]) == (math.cos(-1.1), math.sin(-1.1))
    with pytest.raises(ParameterError, match="^backlash: must be >= 0"):
        m.with_params(backlash=-0.5)


def test_declarations_are_checked():
    with pytest.raises(ValueError, match="names what it derives from"):
        Coefficient("k", kind="derived")
    with pytest.raises(ValueError, match="kind must be one of"):
        Coefficient("k", kind="cache")
    with pytest.raises(ValueError, match="same in every lane"):
        Coefficient("n", kind="structure", per_lane=True)
    assert not Coefficient("n", kind="structure").per_lane and Coefficient("w").per_lane


# ------------------------------------------------------------------------------ kernel indices
@pytest.mark.parametrize("block,module,prefix", [
    (derived.CATT_HEADER, ck, ""), (derived.CATT_BLOCK, ck, ""),
    (catt.THETA_HEADER, ck, ""), (catt.THETA_BLOCK, ck, ""),
    (planetary.HEADER, pk, ""), (planetary.MESH, pk, ""), (GEAR_PAIR, gear_pair, ""),
])
def test_declared_offsets_are_the_kernels_index_constants(block, module, prefix):
    for name, offset in block.constants().items():
        assert getattr(module, prefix + name) == offset, name
    sizes = {derived.CATT_HEADER: ck.HEADER, derived.CATT_BLOCK: ck.BLOCK_FIXED,
             catt.THETA_HEADER: ck.T_HEADER, catt.THETA_BLOCK: ck.T_BLOCK_FIXED,
             planetary.HEADER: pk.HEADER, planetary.MESH: pk.MESH_FIXED, GEAR_PAIR: 12}
    assert block.size == sizes[block]


# ------------------------------------------------------------------------------ every model
def _models() -> dict[str, geardyn.Model]:
    paper = geardyn.PlanetaryParams.paper()
    device = geardyn.CATTDevice(paper, omega=1.1)
    return {"catt-reduced": device, "catt-general": device.general(),
            "dimensional": device.dimensional(), "planetary": busy_set(),
            "gear-pair": geardyn.GearPair(), "user": user_model()}


MODELS = _models()


@pytest.mark.parametrize("key", list(MODELS))
def test_param_names_are_the_declared_parameters(key):
    m = MODELS[key]
    lay = m.coefficient_layout
    assert m.param_names == lay.names and lay.size == m.params.size
    values = m.coefficient_values()
    assert list(values) == list(m.param_names)
    for name in m.param_names:
        assert values[name] == m.params[m.param_index(name)]
    np.testing.assert_array_equal(lay.build(lay.read(m.params, parameters_only=False)),
                                  m.params)  # read back, built again: the same vector


def test_gear_pair_declares_its_vector():
    assert geardyn.GearPair.param_names == GEAR_PAIR.names


#: Per model: (a derived coefficient or None, whether raw overrides are taken, a structural
#: entry or None, a workspace entry or None, a settable coefficient).
TABLE = {
    "catt-reduced": ("k_pq_q", True, "n_blocks", None, "k_pq_q"),
    "catt-general": ("k_pq_q2", True, "spare3", None, "f_c0"),
    "dimensional": ("C_sq1", False, "n_sets", None, "T_D"),
    "planetary": ("s1_KF", True, "n_dof", "cache0_sin", "torque_phase"),
    "gear-pair": ("cos_kappa_phase", False, None, None, "zeta"),
    "user": (None, False, None, None, "zeta"),
}


@pytest.mark.parametrize("key", list(MODELS))
def test_with_params_has_one_set_of_rules(key):
    m = MODELS[key]
    derived_name, raw_ok, structural, workspace, settable = TABLE[key]
    with pytest.raises(KeyError, match="no parameter"):  # unknown
        m.with_params(no_such_coefficient=1.0)
    for name, word in ((structural, "structure"), (workspace, "workspace")):
        if name is not None:
            assert name not in m.param_names
            with pytest.raises(KeyError, match=f"^{name}: .*{word} of"):
                m.with_params(**{name: 1.0})
            with pytest.raises(KeyError, match=f"^{name}: .*{word} of"):
                m.lane_params(name, [1.0, 2.0])
    if derived_name is not None:
        assert m.coefficient_layout.slot(derived_name).coefficient.kind == "derived"
        value = 1.25 * m.params[m.param_index(derived_name)]
        if raw_ok:
            out = m.with_params(**{derived_name: value})
            assert out.params[out.param_index(derived_name)] == value
        else:
            inputs = ", ".join(m.coefficient_layout.slot(derived_name).coefficient.derived_from)
            with pytest.raises(ParameterError, match=f"^{derived_name}: derived from {inputs}"):
                m.with_params(**{derived_name: value})
            with pytest.raises(ParameterError, match=f"^{derived_name}: derived from"):
                m.lane_params(derived_name, [value])
    out = m.with_params(**{settable: 0.0625})
    assert out.params[out.param_index(settable)] == 0.0625
    assert m.params[m.param_index(settable)] != 0.0625  # the model itself is left alone
    P = m.lane_params(settable, [0.0625, 0.125])
    np.testing.assert_array_equal(P[:, m.param_index(settable)], [0.0625, 0.125])


def test_planetary_workspace_and_structure_are_not_parameters():
    """The stiffness cache, the kernel's flags and copies, the sparse indices and counts are in
    the kernel's vector but not among the parameters (the old ``param_names`` held them, and
    ``with_params(cache0_sin=...)`` was accepted)."""
    gs = MODELS["planetary"]
    lay = gs.coefficient_layout
    kinds = {s.name: s.coefficient.kind for s in lay.slots}
    for name in ("cache0_sin", "cache_last", "cache_ct_checked", "damped", "torque_on"):
        assert kinds[name] == "workspace" and name not in gs.param_names
    for name in ("n_dof", "n_meshes", "n_harmonics", "nk", "Kt_row0", "s1_nz_index0", "n_gyro"):
        assert kinds[name] == "structure" and name not in gs.param_names
    with pytest.raises(KeyError):
        gs.with_params(cache0_sin=0.5)
    with pytest.raises(KeyError):
        gs.lane_params("cache_last", [1.0])
    assert len(gs.param_names) < gs.params.size == lay.size


def test_a_raw_fluctuating_force_switches_the_torque_flag_on():
    gs = busy_set(torque_fluctuation=0.0)
    assert gs.params[pk.TORQUE_ON] == 0.0
    name = next(n for n in gs.param_names if n.startswith("F1_"))
    assert gs.with_params(**{name: 0.1}).params[pk.TORQUE_ON] == 1.0


# ------------------------------------------------------------------------------ study schema
def test_the_gear_pair_study_table_comes_from_the_declarations():
    fields = GearPairParams.model_fields
    assert tuple(fields) == INPUTS
    for c in (c for c in GEAR_PAIR.entries if c.kind == "input"):
        assert fields[c.name].description == c.meaning
        assert fields[c.name].default == c.default
    study = load_study('[study]\nmodel = "gear_pair"\n[params]\nzeta = 0.1\n')
    assert study.params.zeta == 0.1 and study.params.kappa == 0.0
    with pytest.raises((StudyError, ValueError), match="zeta2"):
        load_study('[study]\nmodel = "gear_pair"\n[params]\nzeta2 = 0.1\n')
    with pytest.raises((StudyError, ValueError), match="kappa"):
        load_study('[study]\nmodel = "gear_pair"\n[params]\nkappa = 1.5\n')
    with pytest.raises((StudyError, ValueError), match="Omega"):
        load_study('[study]\nmodel = "gear_pair"\n[params]\nOmega = -1.0\n')


# ------------------------------------------------------------------------------ capabilities
class _Probed(geardyn.UserModel):
    """A user model with attributes the old probes looked for, declaring no capability."""

    omega_n = 123.0
    interpretation = "mine"


def test_capabilities_are_declared_not_probed():
    probed = _Probed(user_model().kernel.rhs, n_states=2, params=[1.0, 0.1],
                     param_names=("Omega", "zeta"))
    assert probed.capabilities == Capabilities()
    # the old hasattr probes recorded omega_n = 123; only the engine's own kernel path is added
    assert model_attrs(probed) == {"kernel_path": "per-lane"}
    assert physical_axes(probed, np.array([1.0])) is None
    assert deflection_units(probed) == {"units": "1"}
    device = MODELS["catt-reduced"]
    assert model_attrs(device) == {"interpretation": "consistent", "omega_n": device.omega_n,
                                   "kernel_path": "lane-form"}
    assert device.capabilities.frequency_scale and device.capabilities.paper_device
    axes = physical_axes(MODELS["dimensional"], np.array([2 * math.pi * 26.0]))
    assert axes is not None and axes["mesh_frequency"][0][0] == pytest.approx(26.0)
    assert deflection_units(device)["length_scale"] == device.params_in.b_c


def test_natural_frequencies_are_declared_with_their_unit():
    """Each model with natural_frequencies() declares their unit; a class that defines the
    method without declaring it is refused where it is defined, and an undeclared model gets no
    natural frequency in the step rule (NaN), however it is written."""
    units = {"gear-pair": "rad/time", "catt-reduced": "rad/time"}
    for key, unit in units.items():
        assert MODELS[key].capabilities.natural_frequencies == unit
    assert geardyn.PlanetaryGearSet.capabilities.natural_frequencies == "Hz"
    assert geardyn.SpurPair.capabilities.natural_frequencies == "rad/time"
    with pytest.raises(TypeError, match="_Undeclared defines natural_frequencies"):
        class _Undeclared(geardyn.UserModel):
            def natural_frequencies(self):
                return np.array([1.0])
    probed = _Probed(user_model().kernel.rhs, n_states=2, params=[1.0, 0.1],
                     param_names=("Omega", "zeta"))
    assert np.isnan(probed.fastest_natural_frequency()).all()
    with pytest.raises(ValueError, match="natural_frequencies='rpm'"):
        Capabilities(natural_frequencies="rpm")


class _StiffnessLike(geardyn.UserModel):
    """A user model declaring its natural frequencies in rad per time unit, with a time_scale
    and stiffness-table look-alikes (what the old probes looked for), no stiffness tables."""

    capabilities = Capabilities(natural_frequencies="rad/time")
    time_scale = 50.0
    mesh_tables = ("a table",)
    n_harmonics = 3

    def natural_frequencies(self):
        return np.array([2.0, 5.0])

    def period_stiffness(self, flank="drive"):
        raise AssertionError("probed")


def test_runup_and_the_stiffness_panel_read_the_declarations():
    """The run-up's natural frequencies are the declared method's in its declared unit (a
    time_scale attribute does not rescale rad per time unit; Hz over the planetary set's
    time_scale is 2 pi f / omega_0); the stiffness panel needs declared stiffness tables."""
    from geardyn.analysis.runup import natural_frequencies
    from geardyn.explore.compute import stiffness_view

    model = _StiffnessLike(user_model().kernel.rhs, n_states=2, params=[1.0, 0.1],
                           param_names=("Omega", "zeta"))
    np.testing.assert_array_equal(natural_frequencies(model), [2.0, 5.0])
    assert stiffness_view(model) is None
    assert geardyn.SpurPair.capabilities.stiffness_tables == "pair"
    assert geardyn.PlanetaryGearSet.capabilities.stiffness_tables == "meshes"
    with pytest.raises(ValueError, match="stiffness_tables='table'"):
        Capabilities(stiffness_tables="table")
    from test_swept_inputs import _planetary

    lp = _planetary()
    hz = np.sort(np.asarray(lp.natural_frequencies(), dtype=float))
    expected = 2.0 * math.pi * hz[hz > 1e-9 * hz.max()] / lp.time_scale
    np.testing.assert_allclose(natural_frequencies(lp), np.unique(expected), rtol=1e-15)


# ------------------------------------------------------------------------------ vocabularies
def test_explorer_and_cli_read_the_declared_vocabulary(tmp_path):
    from typer.testing import CliRunner

    from geardyn.cli.main import app
    from geardyn.explore.state import MAIN_PARAMS, ExplorerState

    study = load_study('[study]\nmodel = "gear_pair"\n[params]\nzeta = 0.1\n[sweep]\n'
                       'param = "Omega"\nstart = 1.6\nstop = 2.4\nnum = 6\nsamples = 8\n')
    state = ExplorerState(study, "gp.toml", save_dir=tmp_path)
    for name in MAIN_PARAMS["gear_pair"]:
        assert name in GEAR_PAIR.vocabulary()
        assert state.param_help(name) == GEAR_PAIR[name].describe()
    assert state.param_help("zeta") == "damping ratio"
    path = tmp_path / "gp.toml"
    path.write_text('[study]\nmodel = "gear_pair"\n[params]\nzeta = 0.1\n')
    result = CliRunner().invoke(app, ["params", "show", str(path)])
    assert result.exit_code == 0, result.output
    assert "transmission-error amplitude" in result.output


def test_a_coefficient_declared_alike_in_every_lane_is_not_swept():
    fixed = CoefficientBlock((Coefficient("Omega"), Coefficient("mu", per_lane=False)))
    m = user_model()
    toy = geardyn.UserModel(m.kernel.rhs, n_states=2, params=[1.0, 0.5], name="toy")
    toy.coefficient_layout = CoefficientLayout.of(fixed, model="toy")
    assert toy.param_names == ("Omega", "mu")
    np.testing.assert_array_equal(toy.lane_params("Omega", [1.0, 2.0])[:, 0], [1.0, 2.0])
    with pytest.raises(ParameterError, match="^mu: the same in every lane of toy"):
        toy.lane_params("mu", [0.5, 0.6])
    assert toy.with_params(mu=0.7).params[1] == 0.7


def test_a_raw_sweep_sets_the_kernel_flags_per_lane():
    """Sweeping a raw modal-damping entry from an undamped set switches the kernel's ``damped``
    flag on in the damped lanes (it stayed 0 in every lane: the damping was silently dropped)."""
    gs = busy_set(modal_damping=0.0)
    name = next(n for n in gs.param_names if n.startswith("Ct_"))
    assert gs.params[pk.DAMPED] == 0.0
    P = gs.lane_params(name, [0.0, 0.1])
    np.testing.assert_array_equal(P[:, pk.DAMPED], [0.0, 1.0])
    F1 = next(n for n in gs.param_names if n.startswith("F1_"))
    P = busy_set(torque_fluctuation=0.0).lane_params(F1, [0.0, 0.2])
    np.testing.assert_array_equal(P[:, pk.TORQUE_ON], [0.0, 1.0])
