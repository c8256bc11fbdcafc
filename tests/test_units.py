"""Unit strings of the frequency kind: Hz and rpm count cycles, rad/s is as given, a bare 1/s is
refused as ambiguous. Expected values are computed here by hand (1 Hz = 2 pi rad/s, 1 rpm =
2 pi / 60 rad/s), and every frequency field of the planetary set (the only model with
dimensional frequencies) is checked through its constructor or ``with_params``."""

from __future__ import annotations

import math

import pytest

import geardyn
import geardyn.gears as g
from geardyn.errors import ParameterError
from geardyn.units import to_si

TWO_PI = 2.0 * math.pi
#: (unit string, rad/s computed by hand)
SPEEDS = [("1000 Hz", TWO_PI * 1000.0), ("2.5 kHz", TWO_PI * 2500.0),
          ("3000 rpm", 3000.0 * TWO_PI / 60.0), ("1234.5 rad/s", 1234.5),
          ("90 deg/s", math.pi / 2), ("7 revolution/s", 7 * TWO_PI)]
BARE = ["1000 1/s", "1000 s^-1", "1000 / s", "60 1/min"]

M = geardyn.Member
MEMBERS = dict(
    sun=M(mass=0.4, inertia_over_r2=0.39, bearing_stiffness=1e8, radius=0.02),
    ring=M(mass=2.35, inertia_over_r2=3.0, bearing_stiffness=1e8, torsional_stiffness=1e9),
    carrier=M(mass=5.43, inertia_over_r2=6.29, bearing_stiffness=1e8, torsional_stiffness=1e9,
              radius=0.05),
    planet=M(mass=0.66, inertia_over_r2=0.61, bearing_stiffness=1e8))


def plain(**kw) -> geardyn.PlanetaryGearSet:
    return geardyn.PlanetaryGearSet(n_planets=3, sun_mesh_stiffness=3e8, ring_mesh_stiffness=4e8,
                                    **MEMBERS, **kw)


def built(held: str = "ring") -> geardyn.PlanetaryGearSet:
    def gear(z: int, name: str, internal: bool = False) -> g.SpurGear:
        return g.SpurGear(z, 2e-3, "20 deg", "20 mm", internal=internal, name=name)
    geo = g.PlanetaryGeometry(gear(25, "sun"), gear(23, "planet"), gear(71, "ring", True),
                              n_planets=4)
    members = {k: M(m.mass, m.inertia_over_r2, m.bearing_stiffness, m.torsional_stiffness)
               for k, m in MEMBERS.items()}
    return geardyn.PlanetaryGearSet.from_geometry(geo, **members, held=held)


@pytest.mark.parametrize(("text", "want"), SPEEDS)
def test_frequency_strings_count_cycles(text, want):
    assert to_si(text, "frequency") == pytest.approx(want, rel=1e-13)
    assert to_si(want, "frequency") == want  # a plain number is rad/s


@pytest.mark.parametrize("text", BARE + ["1 Hz*rad", "1 Bq"])
def test_bare_inverse_time_is_refused(text):
    with pytest.raises(ValueError, match="ambiguous"):
        to_si(text, "frequency")


@pytest.mark.parametrize(("text", "want"), SPEEDS)
@pytest.mark.parametrize("field", ["mesh_frequency", "time_scale"])
def test_mesh_frequency_and_time_scale(field, text, want):
    gs = plain(**{field: text})
    value = gs.omega * gs.time_scale if field == "mesh_frequency" else gs.time_scale
    assert value == pytest.approx(want, rel=1e-13)
    assert gs.with_params(**{field: text}).inputs[field] == text
    if field == "mesh_frequency":
        assert gs.with_params(mesh_frequency=text).omega * gs.time_scale \
            == pytest.approx(want, rel=1e-13)


@pytest.mark.parametrize(("text", "want"), SPEEDS)
def test_carrier_speed(text, want):
    assert plain(carrier_speed=text).carrier_speed == pytest.approx(want, rel=1e-13)
    assert plain(carrier_speed=0.0).with_params(carrier_speed=text).carrier_speed \
        == pytest.approx(want, rel=1e-13)


@pytest.mark.parametrize(("text", "want"), SPEEDS)
@pytest.mark.parametrize("held", ["ring", "sun"])
def test_input_speed(held, text, want):
    """input_speed [rpm as a number]: a unit string is converted; the mesh frequency is Z_s
    times the sun's speed relative to the carrier (ring held: Z_s Z_r / (Z_s + Z_r) times the
    sun's speed; sun held: Z_s times the carrier's)."""
    gs = built(held).with_params(input_speed=text)
    assert gs.input_speed == pytest.approx(want * 60.0 / TWO_PI, rel=1e-12)
    per = 25 * 71 / (25 + 71) if held == "ring" else 25.0
    assert gs.omega * gs.time_scale == pytest.approx(per * want, rel=1e-12)


@pytest.mark.parametrize("text", BARE)
@pytest.mark.parametrize("field", ["mesh_frequency", "time_scale", "carrier_speed",
                                   "input_speed"])
def test_bare_inverse_time_names_the_field(field, text):
    with pytest.raises(ParameterError, match="ambiguous") as e:
        if field == "input_speed":
            built().with_params(input_speed=text)
        else:
            plain(**{field: text})
    assert e.value.field == field


def test_study_reads_hz_as_cycles():
    """A study's [params] strings go through the same conversion."""
    from geardyn.io.toml import load_study

    text = """
[study]
name = "hz"
model = "planetary"
[params]
n_planets = 3
sun_mesh_stiffness = 3e8
ring_mesh_stiffness = 4e8
mesh_frequency = "1000 Hz"
carrier_speed = "50 Hz"
time_scale = "100 Hz"
[params.sun]
mass = 0.4
inertia_over_r2 = 0.39
bearing_stiffness = 1e8
[params.ring]
mass = 2.35
inertia_over_r2 = 3.0
bearing_stiffness = 1e8
torsional_stiffness = 1e9
[params.carrier]
mass = 5.43
inertia_over_r2 = 6.29
bearing_stiffness = 1e8
torsional_stiffness = 1e9
radius = 0.05
[params.planet]
mass = 0.66
inertia_over_r2 = 0.61
bearing_stiffness = 1e8
"""
    gs = geardyn.build_model(load_study(text))
    assert gs.time_scale == pytest.approx(TWO_PI * 100.0, rel=1e-13)
    assert gs.omega * gs.time_scale == pytest.approx(TWO_PI * 1000.0, rel=1e-13)
    assert gs.carrier_speed == pytest.approx(TWO_PI * 50.0, rel=1e-13)


def test_si_value_reads_a_finite_bounded_quantity_and_names_the_field():
    from geardyn.units import si_value

    assert si_value("gap", "50 um", "length") == pytest.approx(5e-5, rel=1e-15)
    assert si_value("gap", 0.0, "length", 0.0) == 0.0
    for value, bound, strict, message in ((float("nan"), None, False, "^gap: must be finite"),
                                          (-1e-6, 0.0, False, "^gap: must be >= 0"),
                                          (0.0, 0.0, True, "^gap: must be > 0"),
                                          ("3 kg", None, False, "^gap: ")):
        with pytest.raises(ParameterError, match=message) as err:
            si_value("gap", value, "length", bound, strict)
        assert err.value.field == "gap"
