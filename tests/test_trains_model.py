"""The nonlinear model of a gear train (geardyn.trains.TrainModel), checked against independent
computations: the Lin & Parker set of geardyn.PlanetaryGearSet for one planetary stage, SciPy's
DOP853 on equations written out here from M, K and the mesh rows for a two-stage parallel train
(quasi-periodic forcing, with and without contact loss), the integrator's 4th order, and the
linear natural frequency for where a speed sweep loses contact."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import geardyn
from geardyn.errors import ParameterError
from geardyn.trains import GROUND, Bearing, Gear, GearTrain, Inertia, Mesh, Shaft, TrainModel

# ---------------------------------------------------------------- one planetary stage
LP = {"sun": (0.4, 0.39), "ring": (2.35, 3.0), "carrier": (5.43, 6.29), "planet": (0.66, 0.61)}
K_BEARING, K_PLANET, K_MESH, K_CARRIER_U = 1e8, 1e8, 5e8, 2e8
ZS, ZP = 23, 19
ZR = ZS + 2 * ZP
M_P = 2e-3
A_S = A_R = math.radians(24.6)
N_PLANETS = 3
PHASES = [0.0, 0.7, 1.9]
SUN_TORQUE = 4.0
ZETA = 0.03


def _rb(module: float, teeth: int, alpha: float) -> float:
    return 0.5 * module * teeth * math.cos(alpha)


RB = {"sun": _rb(M_P, ZS, A_S), "ring": _rb(M_P, ZR, A_R), "planet": _rb(M_P, ZP, A_S)}
RC = 0.5 * M_P * (ZS + ZP)


def _lp_set() -> geardyn.PlanetaryGearSet:
    member = {k: geardyn.Member(mass=m, inertia_over_r2=i, bearing_stiffness=K_BEARING)
              for k, (m, i) in LP.items()}
    member["sun"] = geardyn.Member(*LP["sun"], K_BEARING, radius=RB["sun"])
    member["carrier"] = geardyn.Member(*LP["carrier"], K_BEARING,
                                       torsional_stiffness=K_CARRIER_U)
    member["planet"] = geardyn.Member(*LP["planet"], K_PLANET)
    return geardyn.PlanetaryGearSet(
        N_PLANETS, A_S, A_R, **member, sun_mesh_stiffness=K_MESH, ring_mesh_stiffness=K_MESH,
        fixed=("ring",), sun_stiffness_fluctuation=0.2, ring_stiffness_fluctuation=0.2,
        sun_mesh_phase=PHASES, ring_mesh_phase=PHASES, sun_backlash="3 um",
        ring_backlash="3 um", sun_mesh_error="1 um", mesh_damping=ZETA,
        sun_torque=SUN_TORQUE, mesh_frequency=1.1 * math.sqrt(K_MESH / LP["planet"][1]))


def _stage_model(lp: geardyn.PlanetaryGearSet) -> TrainModel:
    """The same stage from elements (rotations in rad: I = (I/r^2) r^2, the carrier's
    torsional support k_u r_c^2) and its nonlinear model with the same inputs."""
    bodies: list[Inertia] = [
        Gear("sun", LP["sun"][1] * RB["sun"] ** 2, mass=LP["sun"][0], base_radius=RB["sun"],
             n_teeth=ZS),
        Gear("ring", LP["ring"][1] * RB["ring"] ** 2, mass=LP["ring"][0],
             base_radius=RB["ring"], n_teeth=ZR),
        Inertia("carrier", LP["carrier"][1] * RC ** 2, mass=LP["carrier"][0])]
    bearings = [Bearing(f"{k}_bearing", k, K_BEARING) for k in ("sun", "ring", "carrier")]
    meshes = []
    for i in range(N_PLANETS):
        psi = 2 * math.pi * i / N_PLANETS
        p = f"planet{i + 1}"
        bodies.append(Gear(p, LP["planet"][1] * RB["planet"] ** 2, mass=LP["planet"][0],
                           base_radius=RB["planet"], n_teeth=ZP))
        bearings.append(Bearing(f"pin{i + 1}", p, K_PLANET, host="carrier", radius=RC,
                                angle=psi))
        meshes += [Mesh(f"s{i + 1}", "sun", p, K_MESH, angle=psi, pressure_angle=A_S)]
    for i in range(N_PLANETS):
        psi = 2 * math.pi * i / N_PLANETS
        meshes += [Mesh(f"r{i + 1}", f"planet{i + 1}", "ring", K_MESH, internal=True,
                        angle=psi + math.pi, pressure_angle=A_R)]
    train = GearTrain(bodies, [Shaft("output", "carrier", GROUND, K_CARRIER_U * RC ** 2)],
                      bearings, meshes, fixed=("ring",), driven="sun")
    phase = {f"{g}{i + 1}": PHASES[i] for g in "sr" for i in range(N_PLANETS)}
    # Lin & Parker's ring-planet damping takes the ring's inertia into m_e, held or not
    j_r, j_p = LP["ring"][1], LP["planet"][1]
    zeta = {f"s{i + 1}": ZETA for i in range(N_PLANETS)}
    zeta.update({f"r{i + 1}": ZETA * math.sqrt(j_r / (j_r + j_p)) for i in range(N_PLANETS)})
    return TrainModel(
        train,
        torques={"sun": SUN_TORQUE}, backlash=3e-6, stiffness_fluctuation=0.2,
        mesh_phase=phase, mesh_error={f"s{i + 1}": 1e-6 for i in range(N_PLANETS)},
        mesh_damping=zeta, mesh_frequency=lp.omega * lp.time_scale, time_scale=lp.time_scale,
        length_scale=lp.length_scale)


def test_planetary_stage_as_train_gives_the_planetary_gear_sets_trajectory():
    """Same equations in other coordinates (rad and fixed-frame x, y against Lin & Parker's
    u = r theta and the planets' radial/tangential ones): the mesh forces agree to round-off
    (a ring-planet row is the negative of Lin & Parker's: its force too)."""
    lp = _lp_set()
    tm = _stage_model(lp)
    assert np.all(tm.orders == 1.0) and not tm.quasi_periodic
    assert tm.omega == lp.omega
    np.testing.assert_allclose(np.sort(tm.natural_frequencies()),
                               np.sort(lp.natural_frequencies()), rtol=1e-9)
    sign = np.sign(tm.static_mesh_forces() / lp.static_mesh_forces())
    np.testing.assert_allclose(tm.static_mesh_forces(), sign * lp.static_mesh_forces(),
                               rtol=1e-9)
    assert list(sign) == [1.0] * N_PLANETS + [-1.0] * N_PLANETS
    run = geardyn.RunSettings(transient=0, samples=12, steps_per_period=256)
    a, b = geardyn.simulate(tm, run=run), geardyn.simulate(lp, run=run)
    fa = np.array([a[f"F_{m}"].values for m in tm.mesh_names])
    fb = np.array([b[f"F_{m}"].values for m in lp.mesh_names]) * sign[:, None]
    scale = np.max(np.abs(fb))
    assert int(b.edge_crossings.sum()) > 0  # contact is lost: the dead zone acts
    crossings = b.edge_crossings.values.reshape(-1, 2)  # a flipped row swaps its edges
    crossings[sign < 0] = crossings[sign < 0, ::-1]
    np.testing.assert_array_equal(a.edge_crossings.values, crossings.ravel())
    np.testing.assert_allclose(fa, fb, rtol=0, atol=1e-9 * scale)


# ---------------------------------------------------------------- two parallel stages
MODULE = 3e-3
Z = (19, 61, 23, 71)
INERTIA = (0.01, 0.35, 0.02, 0.6)
K_MID, KA, KB = 9e5, 6e8, 8e8
#: Stage 2 meshing at twice stage 1's frequency: a whole order, periodic forcing.
Z_WHOLE = (19, 31, 62, 41)
T_IN = 60.0
C_MESH = 300.0


def _radii(z: tuple[int, ...]) -> tuple[float, ...]:
    return tuple(_rb(MODULE, zi, math.radians(20.0)) for zi in z)


RBP = _radii(Z)


def _parallel(z: tuple[int, ...] = Z, **kw) -> TrainModel:
    """Two spur stages (tooth counts ``z``) on a flexible intermediate shaft, free (one
    rigid-body mode), the output torque balancing the input's (``load``)."""
    rb = _radii(z)
    g = [Gear(f"g{i + 1}", INERTIA[i], base_radius=rb[i], n_teeth=z[i]) for i in range(4)]
    train = GearTrain(g, shafts=[Shaft("mid", "g2", "g3", K_MID)],
                      bearings=[Bearing(f"b{i + 1}", f"g{i + 1}", math.inf) for i in range(4)],
                      meshes=[Mesh("stage1", "g1", "g2", KA, damping=C_MESH),
                              Mesh("stage2", "g3", "g4", KB, damping=C_MESH)],
                      driven="g1", free=True)
    args = dict(torques={"g1": T_IN}, load="g4", stiffness_fluctuation=0.25)
    return TrainModel(train, **{**args, **kw})


def _hand_rhs(model: TrainModel, backlash: float, z: tuple[int, ...]):
    """dq/dt in SI, written out from M, K and the mesh rows (not from the model's vectors):
    q = theta_1..4 [rad]; mesh m's phase r_m w t (w: stage 1's mesh frequency, r_2 = Z_3 (Z_1 /
    Z_2) / Z_1), stiffness k_m (1 + 0.25 sin phase), force through the dead zone."""
    rb = _radii(z)
    M = np.diag(INERTIA)
    K = np.zeros((4, 4))
    K[1, 1] = K[2, 2] = K_MID
    K[1, 2] = K[2, 1] = -K_MID
    W = np.array([[rb[0], rb[1], 0.0, 0.0], [0.0, 0.0, rb[2], rb[3]]])
    k = np.array([KA, KB])
    order = np.array([1.0, z[2] * z[0] / z[1] / z[0]])
    t_load = -T_IN * (z[1] / z[0]) * (z[3] / z[2])
    F = np.array([T_IN, 0.0, 0.0, t_load])
    w = model.omega * model.time_scale
    Minv = np.linalg.inv(M)

    def rhs(t, y):
        q, v = y[:4], y[4:]
        d, dv = W @ q, W @ v
        g = d - np.clip(d, -backlash, backlash)
        f = k * (1.0 + 0.25 * np.sin(order * w * t)) * g + C_MESH * dv
        return np.concatenate([v, Minv @ (F - K @ q - W.T @ f)])

    def forces(t, y):
        d, dv = W @ y[:4], W @ y[4:]
        g = d - np.clip(d, -backlash, backlash)
        return (k[:, None] * (1.0 + 0.25 * np.sin(order[:, None] * w * t)) * g
                + C_MESH * dv)

    return rhs, forces


@pytest.mark.parametrize(("backlash", "z"), [(0.0, Z), (20e-6, Z), (20e-6, Z_WHOLE)])
def test_two_stage_train_matches_dop853_on_hand_written_equations(backlash, z):
    """Stage 2 at 23/61 of stage 1's mesh frequency (quasi-periodic; its phase from the time)
    or at twice it (periodic; its phase locked to stage 1's)."""
    rpm = 60.0 * 1190.0 / Z[0]  # stage 1's mesh near the train's second mode
    model = _parallel(z, input_speed=rpm, backlash=backlash)
    assert model.quasi_periodic == (z == Z)
    assert model.orders[1] == (pytest.approx(Z[2] / Z[1], rel=1e-12) if z == Z else 2.0)
    L, w0 = model.length_scale, model.time_scale
    y0 = model.initial_state()
    run = geardyn.RunSettings(transient=0, samples=30, steps_per_period=256)
    ds = geardyn.simulate(model, run=run)
    tau = ds.time.values
    rhs, forces = _hand_rhs(model, backlash, z)
    t = tau / w0
    y0_si = np.concatenate([L * y0[:4], L * w0 * y0[4:]])
    ref = solve_ivp(rhs, (0.0, t[-1]), y0_si, method="DOP853", rtol=1e-10, atol=1e-16,
                    t_eval=t)
    assert ref.success
    f_ref = forces(t, ref.y)
    f = np.array([ds["F_stage1"].values, ds["F_stage2"].values])
    scale = np.max(np.abs(f_ref))
    d_ref = np.array([[RBP[0], RBP[1], 0.0, 0.0]]) @ ref.y[:4]
    if backlash > 0.0 and z == Z:  # the teeth separate: the dead zone acts
        assert np.any(np.abs(d_ref) < backlash) and int(ds.edge_crossings.sum()) > 0
    np.testing.assert_allclose(f, f_ref, rtol=0, atol=5e-6 * scale)
    q = np.array([ds[s].values for s in model.state_names[:4]]) * L
    rel = (q - q[0]) - (ref.y[:4] - ref.y[0])  # relative rotations (rigid-body mode aside)
    assert np.max(np.abs(rel)) <= 5e-6 * np.max(np.abs(ref.y[1:4] - ref.y[0]))


def test_step_size_convergence_is_fourth_order():
    """Mesh forces after 10 periods at n, 2n, 4n steps per period against 16n: the error
    falls by ~16 per halving (RK4, edges located), with contact loss."""
    model = _parallel(input_speed=60.0 * 1190.0 / Z[0], backlash=20e-6)
    out = {}
    for n in (128, 256, 512, 2048):
        ds = geardyn.simulate(model, run=geardyn.RunSettings(transient=0, samples=10,
                                                             steps_per_period=n))
        out[n] = ds["F_stage1"].values[-1]
    err = [abs(out[n] - out[2048]) for n in (128, 256, 512)]
    assert err[0] > err[1] > err[2] > 0.0
    orders = [math.log2(err[0] / err[1]), math.log2(err[1] / err[2])]
    assert min(orders) > 3.3, orders


def test_sweep_lanes_give_the_single_runs_bitwise():
    """The lane-block kernels' own-phase path (a mesh order not 1) computes what the per-lane
    functions do: a sweep's Poincare points are simulate's at each speed, bit for bit."""
    model = _parallel(input_speed=2500.0, backlash=20e-6)
    run = geardyn.RunSettings(transient=100.0, samples=8, steps_per_period=128)
    speeds = (2500.0, 3300.0)
    ds = geardyn.bifurcation(model, "input_speed", speeds, run=run)
    for j, v in enumerate(speeds):
        sim = geardyn.simulate(model.with_params(input_speed=v), run=run)
        np.testing.assert_array_equal(ds.poincare.values[j], sim.poincare.values[-8:])


def test_speed_sweep_builds_no_model_per_point(monkeypatch):
    """A bifurcation in input speed (Omega alone differs between the lanes) takes the model's
    own initial state and static mesh forces, building no model per point; a sweep of the
    backlash (more than Omega) builds one per point, as before."""
    model = _parallel(input_speed=2500.0, backlash=20e-6)
    built = []
    build = TrainModel._build

    def counted(self, omega):
        built.append(omega)
        build(self, omega)

    monkeypatch.setattr(TrainModel, "_build", counted)
    run = geardyn.RunSettings(transient=10.0, samples=2, steps_per_period=64)
    ds = geardyn.bifurcation(model, "input_speed", [2000.0, 2500.0, 3000.0], run=run)
    assert built == []
    np.testing.assert_array_equal(ds["force_peak"].values[0] > 0.0, [True, True])
    geardyn.bifurcation(model, "backlash", [10e-6, 20e-6], run=run)
    assert len(built) >= 2


def test_speed_sweep_loses_contact_at_the_linear_resonance():
    """Backlash and a stiffness fluctuation: sweeping the input speed, the stage-1 mesh's
    peak force peaks, and contact is lost, near the speed at which its mesh frequency meets
    the natural frequency with most of its strain energy in that mesh: 60 f_n / order."""
    model = _parallel(backlash=10e-6, mesh_damping=0.02, stiffness_fluctuation=0.1,
                      input_speed=1000.0)
    modes = model.modes()
    share = modes.energy_share.sel(element="stage1").values
    mode = int(np.nanargmax(share))
    f_n = float(modes.frequency[mode])
    rpm_res = 60.0 * f_n / model.mesh_frequency_per_input_speed()
    speeds = np.linspace(0.6, 1.4, 33) * rpm_res
    ds = geardyn.bifurcation(model, "input_speed", speeds,
                             run=geardyn.RunSettings(transient=200, samples=16))
    assert ds.attrs["forcing"] == "quasi-periodic"
    peak = ds.force_peak.sel(mesh="stage1").values
    top = speeds[int(np.argmax(peak))]
    assert 0.8 * rpm_res <= top <= 1.05 * rpm_res
    static = abs(model.static_mesh_forces()[0])
    assert peak[0] < 2.0 * static and peak[-1] < 2.0 * static
    assert np.max(peak) > 2.0 * static  # contact lost: the dynamic factor exceeds 2


# ---------------------------------------------------------------- inputs and refusals
def test_quasi_periodic_forcing_refuses_periodic_orbits_and_their_continuation():
    model = _parallel(input_speed=2000.0)
    assert model.dataset_attrs()["forcing"] == "quasi-periodic"
    with pytest.raises(ValueError, match="no common period"):
        geardyn.periodic_orbit(model)
    with pytest.raises(ValueError, match="no common period"):
        geardyn.continuation(model, "Omega", model.omega, 1.1 * model.omega)


def test_unbalanced_torques_and_unknown_names_are_refused():
    with pytest.raises(ParameterError, match="do not balance"):
        _parallel(load=None)
    with pytest.raises(ParameterError, match="torques.nope"):
        _parallel(torques={"nope": 1.0})
    with pytest.raises(ParameterError, match="backlash.stage9"):
        _parallel(backlash={"stage9": 1e-6})
    with pytest.raises(ParameterError, match="reference_mesh"):
        _parallel(reference_mesh="stage9")


def test_load_balances_the_input_torque_by_the_speed_ratio():
    model = _parallel()
    ratio = (Z[1] / Z[0]) * (Z[3] / Z[2])
    assert model.body_torques["g4"] == pytest.approx(-T_IN * ratio, rel=1e-9)
    f = model.static_mesh_forces()
    assert abs(f[0]) == pytest.approx(T_IN / RBP[0], rel=1e-9)
    assert abs(f[1]) == pytest.approx(T_IN * Z[1] / Z[0] / RBP[2], rel=1e-9)


def test_input_speed_sets_omega_alone_in_a_sweep():
    model = _parallel(input_speed=1500.0)
    P = model.lane_params("input_speed", [1500.0, 3000.0])
    assert P[0, model.omega_index] == pytest.approx(model.omega, rel=1e-12)
    assert P[1, model.omega_index] == pytest.approx(2 * model.omega, rel=1e-12)
    np.testing.assert_array_equal(np.delete(P[0], model.omega_index),
                                  np.delete(P[1], model.omega_index))
    assert model.input_speed == pytest.approx(1500.0, rel=1e-12)
    assert model.with_params(input_speed=3000.0).omega == pytest.approx(2 * model.omega)


# ---------------------------------------------------------------- the study file
def test_train_study_builds_the_model_the_api_builds():
    """The packaged study's [train] and [params] give the TrainModel built in Python from the
    same inputs (coefficients bitwise)."""
    from geardyn.io.toml import builtin_study

    study = builtin_study("two_stage_train")
    model = geardyn.build_model(study)
    direct = TrainModel(study.gear_train, input_speed=3000.0, torques={"g1": 60.0}, load="g4",
                        backlash=20e-6, mesh_damping=0.03, stiffness_fluctuation=0.25)
    np.testing.assert_array_equal(model.params, direct.params)
    assert model.dof_names() == direct.dof_names() and len(model.dof_names()) == 8
    assert model.input_speed == pytest.approx(3000.0, rel=1e-12)


def test_train_study_takes_the_coast_flank_and_geometry_phasing():
    """``coast`` and ``mesh_phase = "geometry"`` in [params] reach the model."""
    from geardyn.io.toml import builtin_study

    study = builtin_study("two_stage_train")
    params = type(study.params).model_validate({**study.params.model_dump(),
                                                "coast": "symmetric", "mesh_phase": "geometry"})
    study = study.model_copy(update={"params": params})
    model = geardyn.build_model(study)
    assert model.coast_flank == "symmetric" and model.inputs["mesh_phase"] == "geometry"


def test_train_study_bad_params_name_the_field():
    from geardyn.io.toml import load_study

    text = (Path(geardyn.__file__).parent / "studies" / "two_stage_train.toml").read_text()
    bad = load_study(text.replace('load = "g4"', 'load = "g9"'))
    with pytest.raises(ParameterError, match="params.load"):
        geardyn.build_model(bad)


def test_cli_bifurcation_in_rpm_writes_what_the_api_computes(tmp_path):
    from geardyn.io.netcdf import load_dataset
    from geardyn.io.toml import builtin_study
    from test_cli import TINY, invoke

    nc = tmp_path / "train.nc"
    r = invoke("bifurcation", "two_stage_train", "--range", "2000:4000:3", *TINY, "--out", nc)
    assert r.returncode == 0, r.stderr
    saved = load_dataset(nc)
    assert saved.attrs["forcing"] == "quasi-periodic"
    assert saved.attrs["reference_mesh"] == "stage1"
    np.testing.assert_allclose(saved["input_speed"].values, [2000.0, 3000.0, 4000.0])
    direct = geardyn.bifurcation(geardyn.build_model(builtin_study("two_stage_train")),
                                 "input_speed", [2000.0, 3000.0, 4000.0],
                                 run=geardyn.RunSettings(transient=60.0, samples=6,
                                                         steps_per_period=64))
    np.testing.assert_array_equal(saved["poincare"].values, direct["poincare"].values)


def test_cli_params_show_and_simulate_take_the_speed_from_params(tmp_path):
    from test_cli import invoke

    r = invoke("params", "show", "two_stage_train")
    assert r.returncode == 0, r.stderr
    assert "stage2 0.377049 (quasi-periodic forcing)" in r.stdout
    r = invoke("simulate", "two_stage_train", "--periods", "4", "--transient", "10",
               "--out", tmp_path / "s.nc")
    assert r.returncode == 0, r.stderr
    assert "Omega = 0.989278" in r.stdout  # [params].input_speed 3000 rpm
