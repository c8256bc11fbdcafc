"""Play in a gear train besides the meshes: a flexible bearing's radial clearance (a circular
dead zone on the journal's deflection) and a coupling's torsional backlash (a dead zone on a
shaft's twist), checked against equations written out by hand and integrated by DOP853."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import geardyn
from geardyn.trains import GROUND, Bearing, Gear, GearTrain, Inertia, Mesh, Shaft, TrainModel

Z = (19, 48)
RB = tuple(0.5 * 3e-3 * z * math.cos(math.radians(20.0)) for z in Z)
I_P, I_W, M_P = 2e-4, 6e-3, 0.6
K_B, C_B, K_M, C_M, CLEARANCE, TORQUE = 1e8, 100.0, 3e8, 100.0, 15e-6, 2.0
BACKLASH = 10e-6
AMPLITUDE = 0.3
C_COUPLING = 0.5
#: The mesh's direction (wheel centre from the pinion's) that puts its line of action, and so
#: the pinion bearing's load, on the diagonal x = y (beta = angle + 90 deg - 20 deg = 45 deg).
DIAGONAL = math.radians(-25.0)


def _pair(clearance: float = CLEARANCE, rpm: float = 5500.0, angle: float = 0.0) -> TrainModel:
    """A spur pair, the pinion on a flexible bearing with ``clearance``, the wheel on a rigid
    one; near 5500 rpm the pinion's journal leaves its bearing's load side."""
    gears = [Gear("p", I_P, base_radius=RB[0], n_teeth=Z[0], mass=M_P),
             Gear("w", I_W, base_radius=RB[1], n_teeth=Z[1])]
    train = GearTrain(gears, bearings=[Bearing("bp", "p", K_B, clearance=clearance,
                                               damping=C_B),
                                       Bearing("bw", "w", math.inf)],
                      meshes=[Mesh("mesh", "p", "w", K_M, damping=C_M, angle=angle)],
                      driven="p", free=True)
    return TrainModel(train, torques={"p": TORQUE}, load="w", backlash=BACKLASH,
                      stiffness_fluctuation=AMPLITUDE, input_speed=rpm)


def _dead(d: np.ndarray, b: float) -> np.ndarray:
    return d - np.clip(d, -b, b)


def _radial(q: np.ndarray, c: float) -> np.ndarray:
    """The radial dead zone of the journal's deflection q = (x, y) (rows): (1 - c / r) q for
    r = sqrt(x^2 + y^2) > c, else 0."""
    r = np.hypot(q[0], q[1])
    return np.where(r > c, 1.0 - c / np.maximum(r, c if c > 0.0 else 1.0), 0.0) * q


def _reference(model: TrainModel, ds, clearance: float, y0: np.ndarray):
    """The pair's equations written out (the pinion's x, y on a bearing with a radial
    ``clearance``, its damping acting at all times), integrated by DOP853 from ``y0``
    (dimensionless, the model's) at the times of ``ds``."""
    L, w0 = model.length_scale, model.time_scale
    M = np.array([I_P, M_P, M_P, I_W])
    W = model.mesh_rows()[0]  # the train's assembly (checked by the linear tests)
    F = np.array([model.body_torques["p"], 0.0, 0.0, model.body_torques["w"]])
    w = model.omega * w0

    def rhs(t, y):
        q, v = y[:4], y[4:]
        f = K_M * (1.0 + AMPLITUDE * np.sin(w * t)) * _dead(W @ q, BACKLASH) + C_M * (W @ v)
        acc = F - W * f
        acc[1:3] -= K_B * _radial(q[1:3], clearance) + C_B * v[1:3]
        return np.concatenate([v, acc / M])

    t = ds.time.values / w0
    ref = solve_ivp(rhs, (0.0, t[-1]), np.concatenate([L * y0[:4], L * w0 * y0[4:]]),
                    method="DOP853", rtol=1e-10, atol=1e-16, t_eval=t)
    assert ref.success
    mesh = K_M * (1.0 + AMPLITUDE * np.sin(w * t)) * _dead(W @ ref.y[:4], BACKLASH) \
        + C_M * (W @ ref.y[4:])
    return ref, mesh


def _kicked(model: TrainModel) -> np.ndarray:
    """The static state with the journal pushed sideways (across the line of action), so
    that it orbits instead of moving along one line."""
    y0 = model.initial_state()
    y0[5:7] += np.array([1.0, -1.0])  # dimensionless velocity [L omega_0]: 36 mm/s
    return y0


def test_radial_clearance_matches_dop853_on_hand_written_equations():
    model = _pair()
    assert [m[0] for m in model.meshes] == ["mesh", "bp_x", "bp_y"]
    assert [p.radial for p in model.play_elements()] == [1, -1]
    assert model.dof_names() == ("p.theta", "p.x", "p.y", "w.theta")
    y0 = _kicked(model)
    run = geardyn.RunSettings(transient=0, samples=40, steps_per_period=512)
    ds = geardyn.simulate(model, run=run, y0=y0)
    ref, mesh = _reference(model, ds, CLEARANCE, y0)
    x, y = ref.y[1], ref.y[2]
    r = np.hypot(x, y)
    # the journal crosses its clearance both ways, more than once, and orbits: its direction
    # turns by more than 90 degrees (a motion along one line turns by 0 or 180)
    inside = r < CLEARANCE
    assert np.count_nonzero(np.diff(inside.astype(int)) == 1) >= 2
    assert np.count_nonzero(np.diff(inside.astype(int)) == -1) >= 2
    angle = np.unwrap(np.arctan2(y, x))
    assert np.ptp(angle) > math.pi / 2
    assert not np.allclose(np.mod(angle - angle[0] + 0.1, math.pi), 0.1, atol=0.2)
    spring = K_B * _radial(ref.y[1:3], CLEARANCE)
    got = np.array([ds["F_bp_x"].values, ds["F_bp_y"].values])
    peak = np.max(np.hypot(*spring))
    np.testing.assert_allclose(got, spring, rtol=0, atol=2e-5 * peak)
    np.testing.assert_allclose(ds["F_mesh"].values, mesh, rtol=0,
                               atol=2e-5 * np.max(np.abs(mesh)))
    L = model.length_scale
    journal = L * np.array([ds["p.x"].values, ds["p.y"].values])
    np.testing.assert_allclose(journal, ref.y[1:3], rtol=0, atol=2e-5 * np.max(r))
    # both rows switch on r - c and r + c: the kernel's events at the reference's states
    g = np.empty(model.n_events)
    w0 = model.time_scale
    for i in range(0, r.size, 97):
        state = np.concatenate([ref.y[:4, i] / L, ref.y[4:, i] / (L * w0)])
        model.kernel.events(ds.time.values[i], state, g, model.params, 0.0, 1.0)
        edges = [r[i] - CLEARANCE, r[i] + CLEARANCE]
        np.testing.assert_allclose(g[2:] * L, edges + edges, rtol=0, atol=1e-12 * CLEARANCE)
    crossings = ds["edge_crossings"].sel(event=["x_bp_x-b_bp_x", "x_bp_y-b_bp_y"]).values
    assert crossings[0] == crossings[1] >= 4  # the pair crosses together


def test_a_vanishing_radial_clearance_is_the_plain_linear_bearing():
    """c = 0 is the plain linear bearing (no contact); c -> 0 tends to it: on an orbiting
    journal in contact throughout, the radial law k (1 - c / r) (x, y) differs from k (x, y)
    by k c (x, y) / r, so the motion departs from the plain bearing's in proportion to c."""
    plain = _pair(0.0)
    assert [m[0] for m in plain.meshes] == ["mesh"]
    assert plain.play_elements() == []
    run = geardyn.RunSettings(transient=0, samples=20, steps_per_period=256)
    y0 = _kicked(plain)
    base = geardyn.simulate(plain, run=run, y0=y0)["F_mesh"].values
    diffs = []
    for c in (1e-14, 1e-12, 1e-10):
        model = _pair(c)
        ds = geardyn.simulate(model, run=run, y0=y0)
        q = model.length_scale * np.array([ds["p.x"].values, ds["p.y"].values])
        assert np.all(np.hypot(*q) > 100.0 * c)  # in contact throughout
        got = np.array([ds["F_bp_x"].values, ds["F_bp_y"].values])
        np.testing.assert_allclose(got, K_B * _radial(q, c), rtol=1e-12,
                                   atol=1e-12 * K_B * np.max(np.abs(q)))
        diffs.append(np.max(np.abs(ds["F_mesh"].values - base)) / np.max(np.abs(base)))
    assert diffs[0] < 1e-7
    np.testing.assert_allclose(np.array(diffs[1:]) / diffs[:-1], 100.0, rtol=0.05)


def test_a_clearance_the_journal_never_crosses_moves_it_radially_and_not_the_forces():
    """Loaded along the line of action throughout (c well below the static deflection), the
    journal moves along that line only and sits c further out along it: every force is the
    plain bearing's."""
    plain = _pair(0.0)
    run = geardyn.RunSettings(transient=0, samples=10, steps_per_period=256)
    base = geardyn.simulate(plain, run=run)["F_mesh"].values
    L = plain.length_scale
    x0 = plain.static_state()[1:3] * L
    for c in (1e-7, 3e-7):
        model = _pair(c)
        shift = model.static_state()[1:3] * L - x0
        np.testing.assert_allclose(shift, c * x0 / np.linalg.norm(x0), rtol=1e-9, atol=0)
        forces = geardyn.simulate(model, run=run)["F_mesh"].values
        np.testing.assert_allclose(forces, base, rtol=0, atol=1e-9 * np.max(np.abs(base)))


def test_the_diagonal_touches_at_radius_c_not_at_c_on_each_axis():
    """The load on the diagonal x = y: the journal touches its clearance at radius c, where x
    and y are c / sqrt(2) each (a square clearance would leave it free there, and put it at c
    sqrt(2)); statically r = c + F / k exactly (F = T / r_b the mesh force), dynamically it
    stays in contact with x and y inside c, and its force follows the radial law."""
    model = _pair(rpm=3000.0, angle=DIAGONAL)
    L = model.length_scale
    x, y = model.static_state()[1:3] * L
    force = TORQUE / RB[0]
    assert abs(x) < CLEARANCE and abs(y) < CLEARANCE
    assert math.hypot(x, y) == pytest.approx(CLEARANCE + force / K_B, rel=1e-12)
    assert abs(x) == pytest.approx(abs(y), rel=1e-12)
    static = model.static_mesh_forces()
    assert math.hypot(static[1], static[2]) == pytest.approx(force, rel=1e-9)
    ds = geardyn.simulate(model, run=geardyn.RunSettings(transient=0, samples=20,
                                                          steps_per_period=256))
    ref, _ = _reference(model, ds, CLEARANCE, model.initial_state())
    q = ref.y[1:3]
    r = np.hypot(*q)
    assert np.all(np.abs(q) < CLEARANCE) and np.all(r > CLEARANCE)
    spring = K_B * _radial(q, CLEARANCE)
    assert np.min(np.hypot(*spring)) > 0.1 * force  # in contact, well loaded, throughout
    got = np.array([ds["F_bp_x"].values, ds["F_bp_y"].values])
    np.testing.assert_allclose(got, spring, rtol=0, atol=2e-5 * np.max(np.hypot(*spring)))
    contact = geardyn.bifurcation(model, "input_speed", [3000.0],
                                  geardyn.RunSettings(transient=100, samples=8))["contact"]
    assert contact.sel(mesh="bp_x").values.astype(str)[0] == "none"


def test_a_sweep_reports_the_bearing_losing_contact_and_equals_single_runs():
    """The sweep's lane-block kernels (the radial contact's lane forms) give the single runs'
    Poincare points bit for bit."""
    run = geardyn.RunSettings(transient=300, samples=16, steps_per_period=128)
    speeds = [3000.0, 5500.0]
    ds = geardyn.bifurcation(_pair(), "input_speed", speeds, run)
    for row in ("bp_x", "bp_y"):  # one radial contact: both rows report it
        contact = ds["contact"].sel(mesh=row).values.astype(str)
        assert contact[0] == "none" and contact[1] != "none"
    for j, rpm in enumerate(speeds):
        sim = geardyn.simulate(_pair(rpm=rpm), run=run)
        np.testing.assert_array_equal(ds["poincare"].values[j], sim["poincare"].values[-16:])


def _coupled(backlash: float) -> TrainModel:
    """A motor inertia driving a gear through a coupling with torsional ``backlash``."""
    bodies = [Inertia("motor", 1e-3), Gear("p", I_P, base_radius=RB[0], n_teeth=Z[0]),
              Gear("w", I_W, base_radius=RB[1], n_teeth=Z[1])]
    train = GearTrain(bodies, shafts=[Shaft("coupling", "motor", "p", 2e4, damping=C_COUPLING,
                                            backlash=backlash)],
                      bearings=[Bearing(f"b{b.name}", b.name, math.inf) for b in bodies],
                      meshes=[Mesh("mesh", "p", "w", K_M, damping=C_M)], driven="motor",
                      free=True)
    return TrainModel(train, torques={"motor": 0.5}, load="w", backlash=BACKLASH,
                      stiffness_fluctuation=AMPLITUDE, torque_fluctuation=2.0,
                      input_speed=1500.0)


def test_coupling_backlash_matches_dop853_on_hand_written_equations():
    b = 2e-3  # rad, half-width
    model = _coupled(b)
    assert [m[0] for m in model.meshes] == ["mesh", "coupling"]
    L, w0 = model.length_scale, model.time_scale
    ds = geardyn.simulate(model, run=geardyn.RunSettings(transient=0, samples=30,
                                                          steps_per_period=256))
    W = model.mesh_rows()[0]
    inertia = np.diag(model.mass_matrix())
    torques = model.body_torques
    w = model.omega * w0

    def rhs(t, y):
        q, v = y[:3], y[3:]
        f = K_M * (1.0 + AMPLITUDE * np.sin(w * t)) * _dead(W @ q, BACKLASH) + C_M * (W @ v)
        twist, rate = q[0] - q[1], v[0] - v[1]
        tc = 2e4 * _dead(twist, b) + C_COUPLING * rate
        drive = torques["motor"] * (1.0 + 2.0 * np.sin(w * t))
        acc = np.array([drive - tc, tc, torques["w"]]) - W * f
        return np.concatenate([v, acc / inertia])

    y0 = model.initial_state()
    t = ds.time.values / w0
    ref = solve_ivp(rhs, (0.0, t[-1]), np.concatenate([L * y0[:3], L * w0 * y0[3:]]),
                    method="DOP853", rtol=1e-10, atol=1e-16, t_eval=t)
    assert ref.success
    twist = ref.y[0] - ref.y[1]
    assert np.any(np.abs(twist) < b)  # the coupling's play is crossed
    tc = 2e4 * _dead(twist, b)
    np.testing.assert_allclose(ds["F_coupling"].values, tc, rtol=0,
                               atol=2e-5 * np.max(np.abs(tc)))


def test_play_on_a_rigid_element_names_the_field():
    with pytest.raises(geardyn.ParameterError, match="bw.clearance"):
        Bearing("bw", "w", math.inf, clearance=1e-6)
    for bad in (-1e-6, math.nan, math.inf, "-2 um"):
        with pytest.raises(geardyn.ParameterError, match="bp.clearance"):
            Bearing("bp", "p", K_B, clearance=bad)
    with pytest.raises(geardyn.ParameterError, match="j.backlash"):
        Shaft("j", "a", GROUND, math.inf, backlash=1e-3)
    with pytest.raises(geardyn.ParameterError, match="j.backlash"):
        Shaft("j", "a", "b", 1e3, backlash=-1e-3)


def test_study_file_takes_clearance_and_coupling_backlash():
    from importlib.resources import files

    from pydantic import ValidationError

    from geardyn.io.toml import load_study

    text = files("geardyn.studies").joinpath("two_stage_train.toml").read_text()
    text = text.replace('stiffness = "9e5 N m/rad"',
                        'stiffness = "9e5 N m/rad"\nbacklash = "0.1 deg"')
    text = text.replace('stiffness = "2e8 N/m"', 'stiffness = "2e8 N/m"\nclearance = "20 um"')
    model = geardyn.build_model(load_study(text))
    assert [m[0] for m in model.meshes] == ["stage1", "stage2", "b1_x", "b1_y", "mid"]
    plays = {p.name: (p.stiffness, p.half_width, p.radial) for p in model.play_elements()}
    assert plays["mid"] == (pytest.approx(9e5), pytest.approx(math.radians(0.1)), 0)
    assert plays["b1_x"] == (pytest.approx(2e8), pytest.approx(20e-6), 1)
    assert plays["b1_y"] == (pytest.approx(2e8), pytest.approx(20e-6), -1)
    with pytest.raises(ValidationError, match="train.bearings.b1.clearance"):
        load_study(text.replace('clearance = "20 um"', 'clearance = "-1 um"'))
