"""The inputs a sweep takes, declared once (``PhysicalInput.swept`` and its unit,
geardyn.core.inputs), checked against what the models do: every declared swept input of the
planetary set, of a gear train, of the SI spur pair and of the CATT device (its paper names) is
swept by ``lane_params`` (each lane
the model ``with_params`` builds at that value, the lanes differing), a plain number is read in
the unit its axis is labelled with (the same model as the unit string "<number> <unit>", pint's
conversion), and every other declared input is refused naming it. A drifted declaration (the
wrong unit kind) is caught."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import geardyn
from geardyn.core.inputs import PhysicalInput, by_name, rederived
from geardyn.errors import ParameterError
from geardyn.io.toml import builtin_study
from geardyn.models import planetary_coefficients
from geardyn.study import build_model
from geardyn.trains import inputs as train_inputs
from test_trains_model import _parallel

#: Two admissible values of an input of each kind (in the axis unit of its sweep).
KIND_VALUES = {"length": (1e-6, 2.5e-6), "angle": (0.1, 0.3), "stiffness": (4e8, 6e8),
               "torque": (5.0, 8.0), "frequency": (2e4, 3e4), "dimensionless": (0.02, 0.1),
               "number": (0.01, 0.02)}
#: Where an input's range or meaning needs other values than its kind's.
NAME_VALUES = {"sun_pressure_angle": (0.35, 0.42), "ring_pressure_angle": (0.35, 0.42),
               "contact_ratio": (1.4, 1.7), "torque_order": (1.0, 2.0),
               "carrier_speed": (10.0, 20.0), "carrier_speed_ratio": (1e-3, 2e-3),
               "input_speed": (1000.0, 2000.0), "input_torque": (50.0, 80.0),
               "Lambda": (0.5, 0.8)}
#: The axis unit of a dimensionless input (no unit string: written in percent instead).
DIMENSIONLESS = "1"


def _planetary(cls=geardyn.PlanetaryGearSet) -> geardyn.PlanetaryGearSet:
    """A set on which every swept input acts: no member held fixed (ring and carrier on
    torsional supports, every member with a radius), a rectangular stiffness wave (its contact
    ratio acts), a transmission error and a torque fluctuation (their phases act)."""
    m = {k: geardyn.Member(mass, i_r2, 1e8, torsional_stiffness=kt, radius=r)
         for k, (mass, i_r2, kt, r) in {"sun": (0.4, 0.39, 0.0, 0.02),
                                         "ring": (2.35, 3.0, 1e9, 0.08),
                                         "carrier": (5.43, 6.29, 2e8, 0.05),
                                         "planet": (0.66, 0.61, 0.0, 0.02)}.items()}
    return cls(3, "24.6 deg", "24.6 deg", **m, sun_mesh_stiffness=5e8, ring_mesh_stiffness=5e8,
               sun_stiffness_fluctuation=0.2, ring_stiffness_fluctuation=0.2,
               waveform="rectangular", sun_backlash="3 um", ring_backlash="3 um",
               sun_mesh_error="1 um", ring_mesh_error="1 um", mesh_damping=0.03,
               sun_torque=4.0, torque_fluctuation=0.1, mesh_frequency=2.5e4)


def _train():
    return _parallel(waveform="rectangular", mesh_error=1e-6, torque_fluctuation=0.1)


def _planetary_from_geometry():
    return build_model(builtin_study("planetary_example"))


def _spur_pair(speed_unit: str = "rpm") -> geardyn.SpurPair:
    """The cracked pair of the built-in study (speed in rpm), or with its speed in another
    unit; a transmission error so that its phase acts."""
    model = build_model(builtin_study("spur_pair_cracked"))
    if speed_unit == model.speed_unit:
        return model.with_params(error=1e-6)
    return geardyn.SpurPair(model.mesh, model.stiffness, speed=f"{model.speed} rad/s",
                            torque=20.0, error=1e-6, speed_unit=speed_unit)


def _catt() -> geardyn.CATTDevice:
    """The paper's device with its load fluctuations on (so that their phases act)."""
    from geardyn.models.params import PlanetaryParams

    return geardyn.CATTDevice(PlanetaryParams.paper(B1="100 N m", B2="150 N m", Lambda=0.5))


def _values(model, name: str) -> tuple[float, float]:
    if name in NAME_VALUES:
        return NAME_VALUES[name]
    return KIND_VALUES[by_name(model.input_declarations)[name].kind]


def sweep_disagreements(model, names) -> list[str]:
    """Where sweeping ``names`` of ``model`` disagrees with its declarations, one line each:
    a name refused, or neither in ``physical_names`` nor a parameter; a lane that is not the
    model ``with_params`` builds at the value; lanes that do not differ; a plain number not
    read in the unit of the name's axis (``param_attrs``), or, for a dimensionless kind, not a
    unit string in percent."""
    out = []
    for name in names:
        lo, hi = _values(model, name)
        if name not in model.physical_names and name not in model.param_names:
            out.append(f"{name}: neither in physical_names nor a parameter")
        try:
            P = model.lane_params(name, [lo, hi])
            rows = [model.with_params(**{name: v}).params for v in (lo, hi)]
            unit = model.param_attrs(name).get("units")
            if unit is None:
                out.append(f"{name}: no unit on its axis")
                continue
            text = f"{hi * 100!r} percent" if unit == DIMENSIONLESS else f"{hi!r} {unit}"
            declared = {i.name: i for i in model.input_declarations}.get(name)
            as_text = (unit != DIMENSIONLESS or declared is None
                       or declared.kind == "dimensionless")
            written = model.with_params(**{name: text}).params if as_text else rows[1]
        except (ParameterError, ValueError, KeyError) as exc:
            out.append(f"{name}: {type(exc).__name__}: {exc}")
            continue
        for j in range(2):
            if not np.allclose(P[j], rows[j], rtol=1e-12, atol=1e-300):
                out.append(f"{name}: lane {j} is not with_params({name}={(lo, hi)[j]!r})")
        if np.array_equal(P[0], P[1]):
            out.append(f"{name}: the lanes are the same")
        if not np.allclose(written, rows[1], rtol=1e-12, atol=1e-300):
            out.append(f"{name}: {text!r} is not {hi!r} (the axis unit {unit!r})")
    return out


def _declared_swept(model) -> list[str]:
    return [i.name for i in model.input_declarations if i.swept]


def test_every_declared_swept_input_of_the_planetary_set_sweeps_in_its_unit():
    model = _planetary()
    names = _declared_swept(model)
    assert len(names) == 28
    assert sweep_disagreements(model, names) == []
    assert list(model.physical_names) == names  # one value for every planet, all of them


def test_a_set_from_geometry_sweeps_its_input_speed_in_rpm():
    """``input_speed`` (not a constructor input: the mesh frequency through the tooth counts)
    is read in rpm, as its axis says; "2000 rpm" is 2000."""
    model = _planetary_from_geometry()
    assert sweep_disagreements(model, ["input_speed"]) == []
    rpm = model.with_params(input_speed=2000.0)
    assert rpm.mesh_frequency == pytest.approx(
        2000.0 * 2 * math.pi / 60 * model.mesh_frequency_per_input_speed(), rel=1e-12)


def test_every_declared_swept_input_of_a_train_sweeps_in_its_unit():
    """The train's declared swept inputs (input_speed in rpm, its declared unit) and its input
    torque [N m]."""
    model = _train()
    names = _declared_swept(model)
    assert "input_speed" in names and by_name(model.input_declarations)["input_speed"].unit \
        == "rpm"
    assert sweep_disagreements(model, [*names, "input_torque"]) == []
    assert set(model.physical_names) == {*names, "input_torque"}


def test_a_per_mesh_or_per_planet_value_is_not_offered_as_a_sweep():
    """A value given per mesh (a mapping) or per planet (a list) is not one value: the name is
    left out of ``physical_names`` (its declaration stays swept)."""
    train = _parallel(backlash={"stage1": 1e-6})
    assert "backlash" not in train.physical_names and "mesh_damping" in train.physical_names
    lp = _planetary().with_params(sun_backlash=[1e-6, 2e-6, 3e-6])
    assert "sun_backlash" not in lp.physical_names and "ring_backlash" in lp.physical_names


@pytest.mark.parametrize("speed_unit", ["rpm", "rad/s", "Hz"])
def test_every_declared_swept_input_of_the_spur_pair_sweeps_in_its_unit(speed_unit):
    """speed (in the pair's speed_unit, its axis unit) and the inputs that are coefficients of
    their names (torque, zeta, backlash, error, error_phase: the coefficient's unit on the axis,
    the declared kind reading unit strings); physical_names is speed alone, the input the
    coefficients are re-derived from."""
    model = _spur_pair(speed_unit)
    names = _declared_swept(model)
    assert names == ["speed", "torque", "zeta", "backlash", "error", "error_phase"]
    assert model.param_attrs("speed")["units"] == speed_unit
    assert sweep_disagreements(model, names) == []
    assert model.physical_names == ("speed",) == rederived(model.input_declarations)
    for name in names[1:]:
        declared = by_name(model.input_declarations)[name]
        assert declared.coefficient.name == name
        assert model.param_attrs(name)["units"] == declared.axis_unit


def test_the_spur_pairs_speed_sweep_sets_omega_by_the_tooth_counts():
    """A lane of speed is the pinion speed in rpm times 2 pi / 60 (mesh frequency: its teeth
    times that), Omega that over the period's mesh cycles."""
    model = _spur_pair("rpm")
    P = model.lane_params("speed", [1000.0, 3000.0])
    rad_s = np.array([1000.0, 3000.0]) * 2.0 * math.pi / 60.0
    omega = P[:, model.param_index("Omega")]
    np.testing.assert_allclose(omega, rad_s * model.mesh.pinion.teeth / model.cycles,
                               rtol=1e-15)


def test_every_declared_swept_input_of_the_catt_device_sweeps_in_its_unit():
    """The paper's names but the count N and the choice waveform, each in the SI unit of its
    kind (b_sq and b_pq too, which are also the reduced form's dimensionless coefficients: the
    paper name is what a sweep and with_params take); physical_names is the swept names."""
    model = _catt()
    names = _declared_swept(model)
    assert len(names) == 23 and {"N", "waveform"}.isdisjoint(names)
    assert sweep_disagreements(model, names) == []
    assert list(model.physical_names) == names
    assert model.param_attrs("b_sq")["units"] == "m" and model.param_attrs("xi1")["units"] == "1"


def test_a_sweep_of_the_catt_devices_planet_count_is_deprecated():
    """N is a count (not swept, not in physical_names): its sweep of the reduced form warns
    and gives each lane the device built with that many planet sets."""
    model = _catt()
    assert "N" not in model.physical_names and not by_name(model.input_declarations)["N"].swept
    with pytest.warns(DeprecationWarning, match="sweeping N"):
        P = model.lane_params("N", [3.0, 5.0])
    for row, n in zip(P, (3, 5), strict=True):
        np.testing.assert_array_equal(row, model.with_params(N=n).params)
    assert not np.array_equal(P[0], P[1])


def _others(model) -> list[str]:
    """The declared inputs the model was built with that a sweep does not take."""
    given = getattr(model, "inputs", None)
    return [i.name for i in model.input_declarations
            if not i.swept and (given is None or i.name in given)]


#: Declared inputs each model must refuse to sweep (among others).
REFUSED = {"planetary": {"time_scale", "length_scale", "harmonics", "waveform"},
           "train": {"time_scale", "length_scale", "harmonics", "waveform"},
           "spur_pair": {"inertia", "harmonics", "stiffness_form", "period", "speed_unit"},
           "catt": {"waveform"}}


@pytest.mark.parametrize(("kind", "build"), [("planetary", _planetary), ("train", _train),
                                             ("spur_pair", _spur_pair), ("catt", _catt)])
def test_every_other_declared_input_is_refused_by_a_sweep_naming_it(kind, build):
    """Counts, choices, flags, names, tables, lists and the scales: a sweep is a
    ParameterError naming the input, with one value or several; no unit on its axis."""
    model = build()
    others = [n for n in _others(model) if not (kind == "catt" and n == "N")]
    assert REFUSED[kind] <= set(others)
    for name in others:
        for values in ([1.0], [1.0, 2.0]):
            with pytest.raises(ParameterError, match="not swept") as e:
                model.lane_params(name, values)
            assert e.value.field == name
        assert name not in model.physical_names
        assert model.param_attrs(name) == {}


def test_the_cli_lists_the_swept_names_with_their_units():
    """An unknown --param names the sweep's vocabulary with the declared units."""
    from geardyn.cli.bifurcation import _check_param_name

    model = _train()
    with pytest.raises(ParameterError) as e:
        _check_param_name(model, "gear_ratio")
    assert e.value.field == "--param"
    assert "input_speed [rpm]" in str(e.value) and "backlash [m]" in str(e.value)
    with pytest.raises(ParameterError) as e:
        _check_param_name(model, "harmonics")
    assert e.value.field == "harmonics"


class _DriftedSet(geardyn.PlanetaryGearSet):
    """sun_backlash declared an angle (the model reads a length)."""

    input_declarations = tuple(
        dataclasses.replace(i, kind="angle") if i.name == "sun_backlash" else i
        for i in planetary_coefficients.INPUTS)


def test_a_drifted_declaration_is_caught():
    model = _planetary(_DriftedSet)
    found = sweep_disagreements(model, ["sun_backlash", "ring_backlash"])
    assert len(found) == 1 and found[0].startswith("sun_backlash: ParameterError")


@pytest.mark.parametrize(("kw", "message"), [
    ({"kind": "count", "swept": True}, "a swept input is a number"),
    ({"kind": "length", "form": "list", "swept": True}, "a swept input is a number"),
    ({"kind": "choice", "choices": ("a",), "default": "a", "unit": "rpm"},
     "declares its unit"),
])
def test_a_malformed_sweep_declaration_is_refused(kw, message):
    with pytest.raises(ValueError, match=message):
        PhysicalInput("x", meaning="an input", **kw)


def test_axis_units_of_the_declarations():
    """The axis unit of each kind is pint's reading of its SI unit (a unit string in it is the
    SI number), and the train's input_speed is declared in rpm."""
    from geardyn.core.inputs import AXIS_UNITS
    from geardyn.units import SI_UNITS, to_si

    assert set(AXIS_UNITS) == {*SI_UNITS, "number"}
    for kind, unit in AXIS_UNITS.items():
        if kind in SI_UNITS and unit != DIMENSIONLESS:
            assert to_si(f"2.5 {unit}", kind) == 2.5, kind
    speed = by_name(train_inputs.INPUTS)["input_speed"]
    assert speed.axis_unit == "rpm"


@pytest.mark.parametrize("study", ["planetary_example", "two_stage_train"])
def test_the_explorers_controls_are_declared_swept_inputs_with_their_meanings(study):
    """The explorer's main controls of a planetary or train study are swept inputs of the
    model, and their help is the declaration's meaning (or the coefficient's, for a name that
    is also a coefficient)."""
    from geardyn.explore.state import MAIN_PARAMS, ExplorerState, Window

    state = ExplorerState(builtin_study(study), study, window=Window(1000.0, 2000.0, 2))
    declared = by_name(state.model.input_declarations)
    offered = MAIN_PARAMS[state.kind]
    assert set(state.main_params()) <= set(offered)
    for name in offered:
        assert declared[name].swept, name
        layout = state.model.coefficient_layout
        expected = (layout.slot(name).coefficient.describe() if name in layout.names
                    else declared[name].meaning)
        assert state.param_help(name) == expected
