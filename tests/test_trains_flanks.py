"""The two flanks of a gear train's meshes (geardyn.trains.TrainModel, ``coast``): the coast
flank mirrored from the geometry, checked against SciPy's DOP853 on equations written out here
for a two-stage parallel train whose meshes reach the coast side, and ``coast="symmetric"``
giving the one-stiffness model bitwise."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import geardyn
from geardyn.errors import ParameterError
from geardyn.gears import SpurGear
from geardyn.models import planetary_kernels as pk
from geardyn.trains import Bearing, Gear, GearTrain, Mesh, Shaft, TrainModel

MODULE = 3e-3
Z = (19, 31, 62, 41)
INERTIA = (0.01, 0.35, 0.02, 0.6)
K_MID, KA, KB = 9e5, 6e8, 8e8
T_IN, C_MESH, BACKLASH = 60.0, 300.0, 20e-6
#: Drive flank's relative stiffness k0(x) - 1 = sum a_h cos(h x) + b_h sin(h x); its cosine
#: terms make the mirror image about half a mesh cycle differ from it.
A, B = np.array([0.15, 0.05]), np.array([0.2, -0.04])
PHASE = {"stage1": 0.3, "stage2": 1.1}


def _spur(z: int) -> SpurGear:
    return SpurGear(z, MODULE, math.radians(20.0), 0.02)


def _train(geometry: bool = True) -> GearTrain:
    """Two unshifted spur stages at their standard centre distances (coast phase 1/2: tooth
    thickness half the pitch), on a flexible intermediate shaft, free."""
    if geometry:
        g = [Gear(f"g{i + 1}", INERTIA[i], geometry=_spur(Z[i])) for i in range(4)]
    else:
        g = [Gear(f"g{i + 1}", INERTIA[i], base_radius=_spur(Z[i]).base_radius,
                  n_teeth=Z[i]) for i in range(4)]
    return GearTrain(g, shafts=[Shaft("mid", "g2", "g3", K_MID)],
                     bearings=[Bearing(f"b{i + 1}", f"g{i + 1}", math.inf) for i in range(4)],
                     meshes=[Mesh("stage1", "g1", "g2", KA, damping=C_MESH),
                             Mesh("stage2", "g3", "g4", KB, damping=C_MESH)],
                     driven="g1", free=True)


def _model(train: GearTrain, **kw) -> TrainModel:
    rpm = 60.0 * 1190.0 / Z[0]
    return TrainModel(train, torques={"g1": T_IN}, load="g4", waveform=(A, B),
                      mesh_phase=PHASE, backlash=BACKLASH, input_speed=rpm, **kw)


def _k0(x: np.ndarray) -> np.ndarray:
    h = np.arange(1, A.size + 1)[:, None]
    x = np.asarray(x, dtype=float)
    return 1.0 + (A[:, None] * np.cos(h * x[None]) + B[:, None] * np.sin(h * x[None])).sum(0)


def test_symmetric_coast_is_the_one_stiffness_model_bitwise():
    geo = _model(_train(), coast="symmetric")
    plain = _model(_train(geometry=False))
    assert np.array_equal(geo.params, plain.params)
    assert plain.params[geardyn.models.planetary_kernels.TWO_FLANK] == 0.0
    assert _model(_train(geometry=False), coast="mirror").params.tobytes() == \
        plain.params.tobytes()  # no geometry: no coast flank to mirror


def test_a_sine_mirrored_about_half_a_cycle_keeps_one_flank():
    """sin(pi - theta) = sin(theta): phi = 1/2 (to round-off) leaves the one-flank model."""
    kw = dict(torques={"g1": T_IN}, load="g4", stiffness_fluctuation=0.25)
    mirror = TrainModel(_train(), **kw)
    assert np.array_equal(mirror.params, TrainModel(_train(), coast="symmetric", **kw).params)
    assert mirror.params[geardyn.models.planetary_kernels.TWO_FLANK] == 0.0


def test_mirrored_coast_flank_is_the_drive_flank_reflected_about_half_a_cycle():
    """Unshifted teeth at the standard centre distance: s = p / 2, phi = 1/2, so kc(theta) =
    k0(pi - theta - psi) with the drive flank k0(theta + psi)."""
    model = _model(_train())
    assert model.coast_flank == "mirror"
    assert model.coast_phases() == pytest.approx({"stage1": 0.5, "stage2": 0.5}, abs=1e-12)
    theta = np.linspace(0.0, 2 * math.pi, 37)
    h = np.arange(1, A.size + 1)[:, None]
    for m, name in enumerate(model.mesh_names):
        psi = PHASE[name]
        fc = model.fourier_coast[m]
        kc = 1.0 + (fc[0::2, None] * np.cos(h * theta) + fc[1::2, None] * np.sin(h * theta)
                    ).sum(0)
        np.testing.assert_allclose(kc, _k0(math.pi - theta - psi), rtol=0, atol=1e-14)
    assert model.params[pk.TWO_FLANK] == 1.0


def test_bad_coast_is_refused():
    with pytest.raises(ParameterError, match="coast"):
        _model(_train(), coast="mirrored")


def test_coast_contact_matches_dop853_on_hand_written_equations():
    """Stage 2 at twice stage 1's mesh frequency near the train's second mode: the teeth
    separate and strike the coast flanks, where the force uses k0(pi - theta - psi)."""
    model = _model(_train())
    L, w0 = model.length_scale, model.time_scale
    rb = np.array([_spur(z).base_radius for z in Z])
    M = np.diag(INERTIA)
    K = np.zeros((4, 4))
    K[1, 1] = K[2, 2] = K_MID
    K[1, 2] = K[2, 1] = -K_MID
    W = np.array([[rb[0], rb[1], 0.0, 0.0], [0.0, 0.0, rb[2], rb[3]]])
    k = np.array([KA, KB])
    order = np.array([1.0, Z[2] / Z[1]])
    psi = np.array([PHASE["stage1"], PHASE["stage2"]])
    F = np.array([T_IN, 0.0, 0.0, -T_IN * (Z[1] / Z[0]) * (Z[3] / Z[2])])
    w = model.omega * w0
    Minv = np.linalg.inv(M)

    def force(t, q, v):
        d = W @ q
        g = d - np.clip(d, -BACKLASH, BACKLASH)
        col = (2,) + (1,) * (g.ndim - 1)  # mesh axis first, time after (an array t)
        theta = np.multiply.outer(order * w, t) + psi.reshape(col)
        drive = _k0(theta.ravel()).reshape(theta.shape)
        coast = _k0((math.pi - theta).ravel()).reshape(theta.shape)
        return k.reshape(col) * np.where(g > 0.0, drive, coast) * g + C_MESH * (W @ v)

    def rhs(t, y):
        return np.concatenate([y[4:], Minv @ (F - K @ y[:4] - W.T @ force(t, y[:4], y[4:]))])

    y0 = model.initial_state()
    ds = geardyn.simulate(model, run=geardyn.RunSettings(transient=0, samples=30,
                                                         steps_per_period=256))
    t = ds.time.values / w0
    y0_si = np.concatenate([L * y0[:4], L * w0 * y0[4:]])
    ref = solve_ivp(rhs, (0.0, t[-1]), y0_si, method="DOP853", rtol=1e-10, atol=1e-16,
                    t_eval=t)
    assert ref.success
    d_ref = W @ ref.y[:4]
    assert np.any(d_ref < -BACKLASH)  # the coast flanks are in contact
    f_ref = force(t, ref.y[:4], ref.y[4:])
    f = np.array([ds["F_stage1"].values, ds["F_stage2"].values])
    np.testing.assert_allclose(f, f_ref, rtol=0, atol=5e-6 * np.max(np.abs(f_ref)))


# ---------------------------------------------------------------- phasing from the geometry
def _wrapped(a, b) -> np.ndarray:
    """a - b folded into [-1/2, 1/2) mesh cycles."""
    return (np.asarray(a) - np.asarray(b) + 0.5) % 1.0 - 0.5


def _idler(**kw) -> TrainModel:
    """g1 drives idler g2 (31 teeth), which drives g3 a quarter turn further round g2."""
    z = (19, 31, 23)
    g = [Gear(f"g{i + 1}", INERTIA[i], geometry=_spur(z[i])) for i in range(3)]
    train = GearTrain(g, bearings=[Bearing(f"b{i + 1}", f"g{i + 1}", math.inf)
                                   for i in range(3)],
                      meshes=[Mesh("m1", "g1", "g2", KA, angle=0.0),
                              Mesh("m2", "g2", "g3", KB, angle=math.pi / 2)],
                      driven="g1", free=True)
    return TrainModel(train, torques={"g1": T_IN}, load="g3", stiffness_fluctuation=0.2, **kw)


def test_idler_mesh_phase_is_the_fractional_tooth_count_between_its_pitch_points():
    """The idler turns clockwise: a tooth leaving m1's pitch point (at 180 deg from its centre)
    reaches m2's (at 90 deg) after a quarter turn, 31 / 4 = 7.75 pitches: m2 lags m1 by 0.75
    of a mesh cycle (both meshes load the idler's counter-clockwise flanks, equal thickness)."""
    model = _idler(mesh_phase="geometry")
    gamma = model.geometry_phases()
    assert gamma["m1"] == 0.0
    assert _wrapped(gamma["m2"], 0.75) == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(model.mesh_phase, [0.0, -2 * math.pi * gamma["m2"]])
    assert np.array_equal(_idler(mesh_phase=0.3).mesh_phase, [0.3, 0.3])  # the user's wins


def test_geometry_phasing_without_geometry_is_refused():
    with pytest.raises(ParameterError, match="geometry of both gears of mesh stage1"):
        TrainModel(_train(geometry=False), torques={"g1": T_IN}, load="g4",
                   mesh_phase="geometry")


def _stage(shifted: bool):
    """25/23/71, m 2 mm: unshifted at the standard centre distance (3 planets), or the sun and
    ring shifted (+0.2, +0.3) at a widened one (4 planets; coast phases away from 1/2)."""
    from geardyn.gears import PlanetaryGeometry

    def gear(z: int, x: float = 0.0, internal: bool = False) -> SpurGear:
        return SpurGear(z, 2e-3, math.radians(20.0), 0.02, profile_shift=x, internal=internal)
    if shifted:
        return PlanetaryGeometry(gear(25, 0.2), gear(23), gear(71, 0.3, True), n_planets=4,
                                 centre_distance=0.0484)
    return PlanetaryGeometry(gear(25), gear(23), gear(71, internal=True), n_planets=3)


@pytest.mark.parametrize("shifted", [False, True])
def test_planetary_stage_phases_are_parker_and_lins(shifted):
    """Sun-planet phases gamma_sn = Z_s psi_n / 2 pi as Parker & Lin's; a ring-planet row's
    drive flank (positive deflection) is the planet's flank the ring does not load in Parker &
    Lin's convention, so its phase is theirs plus the planet's coast phase in the ring mesh."""
    from geardyn.gears.potential_energy import coast_phase

    geo = _stage(shifted)
    sun, planet, ring, n = geo.sun, geo.planet, geo.ring, geo.n_planets
    rc = geo.sun_mesh.centre_distance
    bodies = [Gear("sun", 1e-3, mass=0.5, geometry=sun),
              Gear("ring", 1.0, mass=3.0, geometry=ring),
              geardyn.trains.Inertia("carrier", 0.1, mass=5.0)]
    bearings = [Bearing(f"{k}_bearing", k, 1e8) for k in ("sun", "ring", "carrier")]
    meshes = []
    for i, psi in enumerate(geo.planet_angles):
        bodies.append(Gear(f"p{i + 1}", 1e-3, mass=0.3, geometry=planet))
        bearings.append(Bearing(f"pin{i + 1}", f"p{i + 1}", 1e8, host="carrier", radius=rc,
                                angle=psi))
        meshes.append(Mesh(f"s{i + 1}", "sun", f"p{i + 1}", 5e8, angle=psi,
                           centre_distance=rc))
    meshes += [Mesh(f"r{i + 1}", f"p{i + 1}", "ring", 5e8, internal=True, angle=psi + math.pi,
                    centre_distance=rc) for i, psi in enumerate(geo.planet_angles)]
    train = GearTrain(bodies, [Shaft("output", "carrier", geardyn.trains.GROUND, 1e6)],
                      bearings, meshes, fixed=("ring",), driven="sun")
    model = TrainModel(train, torques={"sun": 5.0}, mesh_phase="geometry")
    gamma = model.geometry_phases()
    pl = geo.phases_turning(1)
    phi_r = coast_phase(geo.ring_mesh)
    assert _wrapped([gamma[f"s{i + 1}"] for i in range(n)], pl.sun) == \
        pytest.approx(np.zeros(n), abs=1e-9)
    assert _wrapped([gamma[f"r{i + 1}"] for i in range(n)], pl.ring + phi_r) == \
        pytest.approx(np.zeros(n), abs=1e-9)
    assert np.any(np.abs(_wrapped(pl.sun[1:], 0.0)) > 0.1)  # the phases are not all 0


def test_the_default_phases_come_from_the_geometry_where_there_is_one():
    """Not given, the mesh phases are the geometry's (every meshing gear with geometry) and the
    datasets say so; a train of base radii keeps every mesh in phase, said so too."""
    model = _idler()
    asked = _idler(mesh_phase="geometry")
    np.testing.assert_array_equal(model.mesh_phase, asked.mesh_phase)
    assert np.any(model.mesh_phase != 0.0)
    assert model.dataset_attrs()["mesh_phases"] == "geometry"
    assert _idler(mesh_phase=0.0).dataset_attrs()["mesh_phases"] == "given"
    from test_trains_model import _parallel

    plain = _parallel()
    assert np.all(plain.mesh_phase == 0.0)
    assert plain.dataset_attrs()["mesh_phases"] == "all meshes in phase (no geometry)"


def test_lanes_of_other_mesh_orders_and_errors_give_the_single_runs_bitwise():
    """The lane-block kernels' own-phase cache (each distinct mesh order's sin and cos computed
    twice a step per lane, the relative stiffnesses of both flanks with them) holds what the
    per-lane functions compute anew: lanes whose stage 2 turns at another order (whole,
    fractional, 1) share a block, with a transmission error and the teeth striking the coast
    flanks, and each lane's Poincare points are simulate's at its order, bit for bit."""
    model = _model(_train(), mesh_error={"stage2": 2e-6})
    assert model.params[pk.TWO_FLANK] == 1.0
    orders = (model.orders[1], 23.0 / 61.0, 1.0, 3.0, 0.61)
    run = geardyn.RunSettings(transient=60.0, samples=6, steps_per_period=96)
    ds = geardyn.bifurcation(model, "stage2_order", orders, run=run)
    assert int((ds["contact"] != "none").sum()) > 0
    for j, r in enumerate(orders):
        sim = geardyn.simulate(model.with_params(stage2_order=r), run=run)
        np.testing.assert_array_equal(ds.poincare.values[j], sim.poincare.values[-6:])
