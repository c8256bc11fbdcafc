"""Tooth faults on a helical gear of a train (geardyn.trains.faults on the sliced
potential-energy stiffness).

Checks: a one-mesh helical train with a cracked pinion tooth has, over the pinion's revolution,
the stiffness of geardyn.gears.helical_stiffness with the same crack over Z mesh cycles (its
discrete Fourier series summed here, turned to the inclined line of action by 1 / cos^2
beta_b), drive and coast flank, and the compiled stiffness is it; its mesh force matches SciPy's
DOP853 on the one-mesh equation along the inclined line of action written out here; a zero-size
fault gives the healthy train's series bitwise; a spall or Archard wear on a helical gear is
refused naming the fault's field, in Python and in a study file.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn.gears as g
from geardyn.errors import ParameterError
from geardyn.gears import HelicalGear, HelicalMesh, helical_stiffness
from geardyn.io.toml import load_study
from geardyn.models.spur_pair import evaluate_series
from geardyn.trains import Bearing, Gear, GearTrain, Mesh, TrainModel
from test_trains_faults import _train_stiffness, assert_one_mesh_matches_dop853, kernel_stiffness

#: The 19/48 pair (m_n 3.2 mm, 20 deg) at a 15 deg helix, 16 mm face (overlap ratio 0.41).
PINION = HelicalGear(19, "3.2 mm", "20 deg", "15 deg", "16 mm", name="pinion")
WHEEL = HelicalGear(48, "3.2 mm", "20 deg", "15 deg", "16 mm", name="wheel")
BORE = 12e-3
INERTIA = (2.4e-4, 8.5e-3)
H = 6
CRACK = dict(depth="1.5 mm", angle="45 deg")
TORQUE = 40.0


def _train(faults=()) -> GearTrain:
    return GearTrain([Gear("p", INERTIA[0], mass=1.0, geometry=PINION),
                      Gear("w", INERTIA[1], mass=4.0, geometry=WHEEL)],
                     bearings=[Bearing("bp", "p", math.inf), Bearing("bw", "w", math.inf)],
                     meshes=[Mesh("m", "p", "w", "potential_energy", bore_radius=BORE)],
                     driven="p", free=True, faults=faults)


def _model(faults=(), **kw) -> TrainModel:
    return TrainModel(_train(faults), torques={"p": TORQUE}, load="w", harmonics=H, **kw)


def _revolution_series(tooth: int) -> dict[str, np.ndarray]:
    """(k0, a1, b1, ...) [N/m along the inclined line of action] of each flank over the
    pinion's revolution with the crack on pinion ``tooth``: the discrete Fourier series of
    helical_stiffness over Z mesh cycles, H Z harmonics, over cos^2(beta_b)."""
    z = PINION.teeth
    table = helical_stiffness(HelicalMesh(PINION, WHEEL), bore_radius=BORE,
                              faults=(g.RootCrack(**CRACK, gear="pinion", tooth=tooth),),
                              cycles=z)
    normal = 1.0 / math.cos(PINION.base_helix_angle) ** 2
    out = {}
    for flank, var in (("drive", "mesh_stiffness"), ("coast", "mesh_stiffness_coast")):
        k = table[var].values
        assert k.size == 360 * z
        c = np.fft.rfft(k)[:H * z + 1] / k.size
        series = np.empty(2 * H * z + 1)
        series[0] = c[0].real
        series[1::2], series[2::2] = 2.0 * c[1:].real, -2.0 * c[1:].imag
        out[flank] = series * normal
    return out


def test_cracked_helical_train_has_the_sliced_revolution_stiffness():
    """The train's drive and coast series over the pinion's revolution are those of
    helical_stiffness with the crack over 19 mesh cycles (phase 0: the one mesh's geometric
    phase), to 1e-10 of the mean; the compiled stiffness is the series; the crack lowers the
    mean and deepens the stiffness while tooth 2 is in contact."""
    model = _model((g.RootCrack(**CRACK, gear="p", tooth=2),))
    healthy = _model()
    z = PINION.teeth
    assert model.mesh_order == z and model.mesh_phase[0] == 0.0
    want = _revolution_series(2)
    theta = np.linspace(0.0, 2.0 * math.pi, 1999)
    for coast, flank in ((False, "drive"), (True, "coast")):
        ref = evaluate_series(want[flank], theta)
        got = _train_stiffness(model, 0, theta, coast)
        np.testing.assert_allclose(got, ref, rtol=0.0, atol=1e-10 * want[flank][0])
    assert model.mesh_stiffnesses()[0] == pytest.approx(want["drive"][0], rel=1e-13)
    assert model.mesh_stiffnesses()[0] < healthy.mesh_stiffnesses()[0]
    compiled = kernel_stiffness(model, theta[::10] / model._kernel_orders[0])[:, 0]
    np.testing.assert_allclose(compiled, _train_stiffness(model, 0, theta[::10]), rtol=1e-12)
    # tooth 2 passes the pitch point at 2 mesh cycles: the drop is largest within a cycle or
    # two of it (the path of contact and the overlap), nil half a revolution away
    c = theta * z / (2.0 * math.pi)
    drop = _train_stiffness(healthy, 0, 2.0 * math.pi * c) - _train_stiffness(model, 0, theta)
    assert abs(c[np.argmax(drop)] - 2.0) < 1.5
    far = np.abs(c - 2.0 - z / 2.0) < 3.0
    assert np.max(np.abs(drop[far])) < 0.05 * np.max(drop)


def test_cracked_helical_train_matches_dop853_on_the_one_mesh_equation():
    """delta the deflection along the line of action inclined by beta_b (delta = cos(beta_b)
    (r1 theta1 + r2 theta2), transverse base radii): m_n delta'' = T / (r1 cos beta_b) - F, F
    = k_n(theta) g(delta) + c delta', m_n = m_t / cos^2 beta_b (m_t the transverse equivalent
    mass), k_n = helical_stiffness's series over the cracked pinion's revolution / cos^2
    beta_b (drive flank where delta > b, coast flank where delta < -b), c = 2 zeta sqrt(k0_n
    m_n): DOP853 at rtol 1e-10 against the train's mesh force over two pinion revolutions near
    the mesh resonance (the teeth separate); the static force is T / (r1 cos beta_b)."""
    zeta, b = 0.04, 10e-6
    series = _revolution_series(2)
    r1, r2 = PINION.transverse.base_radius, WHEEL.transverse.base_radius
    cb = math.cos(PINION.base_helix_angle)
    m_n = INERTIA[0] * INERTIA[1] / (INERTIA[0] * r2 ** 2 + INERTIA[1] * r1 ** 2) / cb ** 2
    k0 = float(series["drive"][0])
    rpm = 0.9 * math.sqrt(k0 / m_n) / PINION.teeth * 60.0 / (2.0 * math.pi)
    model = _model((g.RootCrack(**CRACK, gear="p", tooth=2),), mesh_damping=zeta, backlash=b,
                   input_speed=rpm)
    assert model.static_mesh_forces()[0] == pytest.approx(TORQUE / (r1 * cb), rel=1e-9)
    omega = model.omega * model.time_scale
    assert omega == pytest.approx(rpm * 2.0 * math.pi / 60.0, rel=1e-12)
    assert_one_mesh_matches_dop853(
        model, lambda theta: evaluate_series(series["drive"], theta),
        lambda theta: evaluate_series(series["coast"], theta), m_n,
        2.0 * zeta * math.sqrt(k0 * m_n), b, TORQUE / (r1 * cb))


@pytest.mark.parametrize("fault", [g.RootCrack(depth=0.0, gear="p", tooth=4),
                                   g.Wear(depth=0.0, gear="w", tooth=7)])
def test_zero_size_fault_on_a_helical_gear_is_the_healthy_train(fault):
    """A zero-size fault: the series (drive, coast) bitwise the healthy one at harmonics l Z
    of the faulty gear's revolution (phase 0), the means the healthy ones."""
    healthy, zero = _model(), _model((fault,))
    z = (PINION if fault.gear == "p" else WHEEL).teeth
    assert zero.mesh_order == z
    for got, want in ((zero.fourier, healthy.fourier), (zero.fourier_coast,
                                                         healthy.fourier_coast)):
        embedded = np.zeros((1, 2 * H * z))
        embedded[0, 2 * z - 2::2 * z] = want[0, 0::2]
        embedded[0, 2 * z - 1::2 * z] = want[0, 1::2]
        assert np.array_equal(got, embedded)
    assert zero.mesh_stiffnesses()[0] == healthy.mesh_stiffnesses()[0]
    assert zero.coast_stiffnesses()[0] == healthy.coast_stiffnesses()[0]


@pytest.mark.parametrize(("fault", "field"), [
    (g.Spall(length="1 mm", width="2 mm", depth="0.1 mm", gear="p"), "spall.gear"),
    (g.Wear(depth="10 um", profile="archard", gear="w"), "wear.profile"),
])
def test_faults_helical_stiffness_refuses_name_the_field(fault, field):
    """What helical_stiffness refuses (a spall: no place across the face; Archard wear: the
    spur pair's load share) is refused on a helical gear of a train, naming the fault's
    field; in a study file its [[train.faults]] table's."""
    with pytest.raises(ParameterError) as err:
        _train((fault,))
    assert err.value.field == field
    assert "helical" in err.value.reason


def test_study_helical_fault_errors_name_the_table(tmp_path):
    """A spall on a helical gear in a study: the error names train.faults[0].gear."""
    text = """
[study]
name = "helical_spall"
model = "train"
[params]
torques = { p = "40 N m" }
load = "w"
[train]
driven = "p"
free = true
[train.gears.p]
inertia = 2.4e-4
[train.gears.p.geometry]
teeth = 19
module = "3.2 mm"
pressure_angle = "20 deg"
helix_angle = "15 deg"
face_width = "16 mm"
[train.gears.w]
inertia = 8.5e-3
[train.gears.w.geometry]
teeth = 48
module = "3.2 mm"
pressure_angle = "20 deg"
helix_angle = "15 deg"
face_width = "16 mm"
[train.bearings.bp]
body = "p"
stiffness = "inf"
[train.bearings.bw]
body = "w"
stiffness = "inf"
[train.meshes.m]
a = "p"
b = "w"
stiffness = "potential_energy"
bore_radius = "12 mm"
[[train.faults]]
kind = "spall"
gear = "p"
length = "1 mm"
width = "2 mm"
depth = "0.1 mm"
"""
    path = tmp_path / "helical_spall.toml"
    path.write_text(text)
    with pytest.raises(Exception) as err:
        load_study(path)
    msg = str(err.value).replace("[", ".").replace("]", "").replace(" ", "")
    assert "train.faults.0.gear" in msg, str(err.value)
