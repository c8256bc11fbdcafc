"""A gear train's potential-energy mesh stiffness and tooth faults (geardyn.trains.faults,
TrainModel's stiffness series).

Checks: a one-stage train on the potential-energy stiffness is SpurPair of the same gears (the
same series to round-off, drive and coast flank, healthy and with a cracked pinion tooth; the
cracked train's mesh force against SciPy's DOP853 on SpurPair's equation written out here); a
zero-size fault gives the healthy train's series bitwise (embedded at the revolution's
harmonics) and its response to round-off; the fault felt once per revolution, at the faulty
tooth's contact on each of an idler's two meshes (their tooth passages worked out here from the
idler's rotation); a cracked input pinion in the two_stage_train study ([[train.faults]]) puts
sidebands at the pinion's rotation frequency round the stage-1 mesh frequency into the mesh
force, which the healthy train lacks; bad faults named by their field.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import geardyn
import geardyn.gears as g
from geardyn.errors import ParameterError
from geardyn.gears import GearMesh, SpurGear
from geardyn.io.toml import load_study
from geardyn.models.spur_pair import evaluate_series
from geardyn.study import build_model
from geardyn.trains import Bearing, Gear, GearTrain, Mesh, TrainModel

#: The commonly used 19/48 pair (m 3.2 mm, 20 deg, 16 mm face), bores 12 mm.
PINION = SpurGear(19, 3.2e-3, math.radians(20.0), 0.016)
WHEEL = SpurGear(48, 3.2e-3, math.radians(20.0), 0.016)
BORE = 12e-3
INERTIA = (2.4e-4, 8.5e-3)
H = 6  # mesh harmonics of the series (fewer than the default: short runs)
CRACK = dict(depth="1.5 mm", angle="45 deg")
STUDY = Path(geardyn.__file__).parent / "studies" / "two_stage_train.toml"


def _pair_train(faults=(), bearing: float = math.inf) -> GearTrain:
    return GearTrain([Gear("p", INERTIA[0], mass=1.0, geometry=PINION),
                      Gear("w", INERTIA[1], mass=4.0, geometry=WHEEL)],
                     bearings=[Bearing("bp", "p", bearing), Bearing("bw", "w", math.inf)],
                     meshes=[Mesh("m", "p", "w", "potential_energy", bore_radius=BORE)],
                     driven="p", free=True, faults=faults)


def _pair_model(faults=(), **kw) -> TrainModel:
    return TrainModel(_pair_train(faults), torques={"p": 40.0}, load="w", harmonics=H, **kw)


def _spur_pair(faults=(), **kw) -> geardyn.SpurPair:
    cycles = PINION.teeth if faults else 1
    return geardyn.SpurPair.from_geometry(
        GearMesh(PINION, WHEEL), bore_radius=BORE, angles=360, faults=faults,
        period="pinion" if faults else "mesh", harmonics=H * cycles, inertia=INERTIA, **kw)


def _train_stiffness(model: TrainModel, m: int, theta: np.ndarray, coast: bool = False
                     ) -> np.ndarray:
    """k [N/m] of mesh m from the model's series at its phase ``theta`` [rad]."""
    coef = (model.fourier_coast if coast else model.fourier)[m]
    mean = (model.coast_stiffnesses() if coast else model.mesh_stiffnesses())[m]
    series = np.concatenate([[1.0], coef])
    return mean * evaluate_series(series, theta)


def set_series_misses(model: TrainModel, gs: geardyn.PlanetaryGearSet,
                      points: int = 2001) -> tuple[float, float]:
    """The largest difference of a train's planetary stage ``model`` from the
    :class:`~geardyn.PlanetaryGearSet` ``gs`` of the same stage, series against series at
    ``points`` phases over a forcing period, drive and coast (the ring meshes' flanks named the
    other way round), relative to each mesh's mean: (sun meshes, ring meshes)."""
    n = gs.n_planets
    theta = np.linspace(0.0, 2.0 * math.pi, points)
    out = [0.0, 0.0]
    for coast in (False, True):
        for m in range(2 * n):
            theirs = coast if m < n else not coast
            coef = gs.fourier_coast if theirs else gs.fourier
            mean = (gs.coast_stiffnesses() if theirs else gs.mesh_stiffnesses())[m]
            want = mean * evaluate_series(np.concatenate([[1.0], coef[m]]), theta)
            got = _train_stiffness(model, m, theta * model._kernel_orders[m], coast)
            out[m >= n] = max(out[m >= n], float(np.max(np.abs(got - want))) / mean)
    return out[0], out[1]


def kernel_stiffness(model: TrainModel, thetas: np.ndarray, sign: float = 1.0) -> np.ndarray:
    """k_m [N/m] of every mesh (columns) at the forcing phases ``thetas`` (rows) from the
    compiled observable: at a state of dimensionless deflection ``sign`` in every mesh, at
    rest, no backlash, the mesh force is sign k_m L."""
    W = model.mesh_rows()
    X = np.linalg.lstsq(W, np.full(W.shape[0], sign), rcond=None)[0]
    assert np.allclose(W @ X, sign)
    y = np.r_[X, np.zeros_like(X)]
    out = np.empty((np.size(thetas), W.shape[0]))
    for i, theta in enumerate(np.ravel(thetas)):
        model.kernel.observe(theta / model.omega, y, out[i], model.params, math.sin(theta),
                             math.cos(theta))
    return out / (sign * model.length_scale)


# ---------------------------------------------------------------- the pair
@pytest.mark.parametrize("faults", [(), (g.RootCrack(**CRACK, gear="p", tooth=2),)])
def test_one_stage_train_is_the_spur_pair(faults):
    """The same potential-energy series as SpurPair of the same gears (the pinion's revolution
    the period with the crack, a mesh cycle without), drive and coast flank, to round-off; the
    compiled stiffness is the series."""
    model = _pair_model(faults)
    pair = _spur_pair(tuple(g.RootCrack(**CRACK, gear="pinion", tooth=2) for _ in faults),
                      speed=100.0, torque=40.0)
    assert model.mesh_order == (PINION.teeth if faults else 1)
    theta = np.linspace(0.0, 2.0 * math.pi, 997)
    for coast, flank in ((False, "drive"), (True, "coast")):
        want = evaluate_series({"drive": pair.drive_series,
                                "coast": pair.coast_series}[flank], theta)
        got = _train_stiffness(model, 0, theta, coast)
        np.testing.assert_allclose(got, want, rtol=0.0, atol=1e-12 * np.max(want))
    compiled = kernel_stiffness(model, theta[::10] / model._kernel_orders[0])[:, 0]
    np.testing.assert_allclose(compiled, _train_stiffness(model, 0, theta[::10]), rtol=1e-12)
    assert model.dataset_attrs()["mesh_stiffness_methods"] == "potential_energy"


def test_cracked_one_stage_train_matches_dop853_on_the_spur_pair_equation():
    """m x'' + c x' + k(theta) g(x) = T / r_b1, k SpurPair's series of the cracked pinion's
    revolution (drive flank where x > b, coast flank where x < -b), c = 2 zeta sqrt(k0 m),
    theta the pinion's angle: integrated here by DOP853 at rtol 1e-10 against the train's mesh
    force over two pinion revolutions, speed near the mesh resonance (the teeth separate)."""
    crack = g.RootCrack(**CRACK, gear="p", tooth=2)
    zeta, b, torque = 0.04, 10e-6, 40.0
    pair = _spur_pair((g.RootCrack(**CRACK, gear="pinion", tooth=2),), speed=100.0,
                      torque=torque)
    r1, r2 = PINION.base_radius, WHEEL.base_radius
    m = INERTIA[0] * INERTIA[1] / (INERTIA[0] * r2 ** 2 + INERTIA[1] * r1 ** 2)
    k0 = float(pair.drive_series[0])
    f_n = math.sqrt(k0 / m)
    rpm = 0.9 * f_n / PINION.teeth * 60.0 / (2.0 * math.pi)
    model = TrainModel(_pair_train((crack,)), torques={"p": torque}, load="w", harmonics=H,
                       mesh_damping=zeta, backlash=b, input_speed=rpm)
    omega = model.omega * model.time_scale  # the pinion's angular speed [rad/s]
    assert omega == pytest.approx(rpm * 2.0 * math.pi / 60.0, rel=1e-12)
    assert_one_mesh_matches_dop853(
        model, lambda theta: pair.stiffness_at(theta, "drive"),
        lambda theta: pair.stiffness_at(theta, "coast"), m, 2.0 * zeta * math.sqrt(k0 * m),
        b, torque / r1)


def assert_one_mesh_matches_dop853(model: TrainModel, drive, coast, m: float, c: float,
                                   b: float, force: float) -> None:
    """The one-mesh train ``model``'s mesh force F_m against DOP853 (rtol 1e-10) on m x'' =
    ``force`` - k(theta) g(x) - c x' (x the mesh deflection [m], g(x) = x - clip(x, -b, b),
    k = ``drive``(theta) [N/m] where x > b, ``coast``(theta) where x < -b, theta = omega t
    the pinion's angle, omega = the model's speed [rad/s]) over two periods of the model
    (transient 0, 19 x 400 steps a period), from the model's initial state: the teeth leave
    the drive flank, and F_m is the reference's to 2e-5 of its largest."""
    L, w0 = model.length_scale, model.time_scale
    omega = model.omega * w0

    def mesh_force(t, x, v):
        gap = x - np.clip(x, -b, b)
        theta = omega * np.asarray(t, dtype=float)
        return np.where(gap > 0.0, drive(theta), coast(theta)) * gap + c * v

    def rhs(t, y):
        return [y[1], (force - mesh_force(t, y[0], y[1])) / m]

    ds = geardyn.simulate(model, run=geardyn.RunSettings(transient=0, samples=2,
                                                         steps_per_period=19 * 400))
    t = ds.time.values / w0
    W = model.mesh_rows()[0]
    y0 = model.initial_state()
    n = W.size
    x0, v0 = L * (W @ y0[:n]), L * w0 * (W @ y0[n:])
    ref = solve_ivp(rhs, (0.0, t[-1]), [x0, v0], method="DOP853", rtol=1e-10, atol=1e-16,
                    t_eval=t)
    assert ref.success
    assert np.any(ref.y[0] < b)  # the teeth leave the drive flank
    f_ref = mesh_force(t, ref.y[0], ref.y[1])
    np.testing.assert_allclose(ds["F_m"].values, f_ref, rtol=0.0,
                               atol=2e-5 * np.max(np.abs(f_ref)))


def _embedded(series: np.ndarray, z: int) -> np.ndarray:
    """A one-mesh-cycle series (1, 2 H) as harmonics l z of the revolution (1, 2 H z)."""
    out = np.zeros((1, 2 * H * z))
    out[0, 2 * z - 2::2 * z] = series[0, 0::2]
    out[0, 2 * z - 1::2 * z] = series[0, 1::2]
    return out


def test_zero_size_fault_is_the_healthy_train():
    """A zero-depth crack: the series bitwise the healthy one at harmonics l Z of the
    revolution (the healthy mean, the stage's other series untouched), the compiled stiffness
    the healthy one to round-off, and a run over one revolution the healthy run over Z mesh
    periods on the same time grid."""
    healthy = _pair_model(mesh_phase=0.7, backlash=5e-6, mesh_damping=0.05)
    zero = TrainModel(_pair_train((g.RootCrack(depth=0.0, gear="p", tooth=4),)),
                      torques={"p": 40.0}, load="w", harmonics=H, mesh_phase=0.7,
                      backlash=5e-6, mesh_damping=0.05)
    z = PINION.teeth
    for got, want in ((zero.fourier, healthy.fourier), (zero.fourier_coast,
                                                         healthy.fourier_coast)):
        # the healthy harmonic h of the mesh cycle is harmonic h z of the revolution, its
        # phase shift h psi the revolution's h z (psi / z)
        embedded = _embedded(want, z)
        np.testing.assert_allclose(got, embedded, rtol=1e-13, atol=1e-15)
    assert zero.mesh_stiffnesses()[0] == healthy.mesh_stiffnesses()[0]
    assert zero.coast_stiffnesses()[0] == healthy.coast_stiffnesses()[0]
    theta = np.linspace(0.0, 2.0 * math.pi * z, 77)
    for sign in (1.0, -1.0):
        np.testing.assert_allclose(kernel_stiffness(zero, theta / z, sign),
                                   kernel_stiffness(healthy, theta, sign), rtol=1e-11)
    n = 64
    a = geardyn.simulate(healthy, run=geardyn.RunSettings(transient=0.0, samples=z,
                                                          steps_per_period=n))
    b = geardyn.simulate(zero, run=geardyn.RunSettings(transient=0.0, samples=1,
                                                       steps_per_period=z * n))
    assert a.sizes["time"] == b.sizes["time"]
    np.testing.assert_allclose(b.time.values, a.time.values, rtol=1e-12)
    scale = float(np.max(np.abs(a["F_m"].values)))
    np.testing.assert_allclose(b["F_m"].values, a["F_m"].values, rtol=0.0, atol=1e-9 * scale)


def test_zero_size_fault_series_is_bitwise_the_embedded_healthy_series():
    """Phase 0: no shift, so the series of the zero-size fault is the healthy series itself at
    harmonics l Z, bit for bit."""
    healthy = _pair_model()
    zero = _pair_model((g.Spall(length="0 mm", width="2 mm", depth="0.1 mm", gear="p"),))
    z = PINION.teeth
    for got, want in ((zero.fourier, healthy.fourier), (zero.fourier_coast,
                                                         healthy.fourier_coast)):
        embedded = _embedded(want, z)
        assert np.array_equal(got, embedded)


# ---------------------------------------------------------------- an idler: the right time
def _idler(faults=()) -> TrainModel:
    """g1 (19) drives the idler g2 (31), which drives g3 (23) a quarter turn further round."""
    gears = [SpurGear(z, 3e-3, math.radians(20.0), 0.02) for z in (19, 31, 23)]
    bodies = [Gear(f"g{i + 1}", 0.01 * (i + 1), geometry=gears[i]) for i in range(3)]
    train = GearTrain(bodies, bearings=[Bearing(f"b{i + 1}", f"g{i + 1}", math.inf)
                                        for i in range(3)],
                      meshes=[Mesh("m1", "g1", "g2", "potential_energy", bore_radius=8e-3),
                              Mesh("m2", "g2", "g3", "potential_energy", bore_radius=8e-3,
                                   angle=math.pi / 2)],
                      driven="g1", free=True, faults=faults)
    return TrainModel(train, torques={"g1": 20.0}, load="g3", harmonics=H,
                      mesh_phase="geometry")


def test_idler_fault_is_felt_on_each_mesh_at_its_tooth_passage():
    """A crack on idler tooth 5: each mesh's stiffness over the idler's revolution drops most
    while the cracked tooth is in contact, from the start to the end of the path of contact
    about its pitch-point passage. The idler turns clockwise: a tooth passing m1's pitch point
    (180 deg from its centre) reaches m2's (90 deg) a quarter turn later, 31 / 4 mesh cycles
    (m1 the first mesh: tooth j passes it j cycles after tooth 0, at gamma_1 = 0)."""
    tooth, z = 5, 31
    faulty, healthy = _idler((g.RootCrack(**CRACK, gear="g2", tooth=tooth),)), _idler()
    assert faulty.mesh_order == z and healthy.mesh_order == 1
    c = np.arange(0, z * 64) / 64.0  # mesh cycles over the idler's revolution
    drop = (kernel_stiffness(healthy, 2.0 * math.pi * c)
            - kernel_stiffness(faulty, 2.0 * math.pi * c / z))
    assert healthy.geometry_phases()["m1"] == 0.0
    passage = {"m1": float(tooth), "m2": tooth + z / 4.0}
    for m, name in enumerate(("m1", "m2")):
        pair = GearMesh(*(SpurGear(t, 3e-3, math.radians(20.0), 0.02) for t in
                          ((19, 31) if name == "m1" else (31, 23))))
        start, end = -pair.approach_length / pair.base_pitch, pair.recess_length / pair.base_pitch
        at = c[np.argmax(drop[:, m])]
        offset = (at - passage[name] + z / 2) % z - z / 2
        assert start <= offset <= end, (name, at, passage[name], start, end)
        # the stiffness is untouched half a revolution away
        away = np.abs((c - passage[name] + z / 2) % z - z / 2) > 4.0
        assert np.max(np.abs(drop[away, m])) < 0.05 * np.max(drop[:, m])

# ---------------------------------------------------------------- the two-stage study
def _two_stage(depth: str, tmp_path: Path, gear: str = "g1") -> TrainModel:
    text = STUDY.read_text()
    text = text.replace('stiffness = "iso"', 'stiffness = "potential_energy"\n'
                        'bore_radius = "10 mm"').replace("stiffness_fluctuation = 0.25\n", "")
    text += (f'\n[[train.faults]]\nkind = "crack"\ngear = "{gear}"\ntooth = 3\n'
             f'depth = "{depth}"\nangle = "45 deg"\n')
    path = tmp_path / f"two_stage_{gear}_{depth.split()[0]}.toml"
    path.write_text(text)
    return build_model(load_study(path))


def test_cracked_input_pinion_puts_sidebands_round_the_stage1_mesh_frequency(tmp_path):
    """The study's two-stage train on the potential-energy stiffness, a 2 mm crack on g1: the
    stage-1 mesh force over 8 revolutions of g1 (Hann window) has lines at 19 +- 1 times g1's
    rotation frequency above 3e-3 of the mesh line, where the zero-size crack's (the healthy
    train's response) stays below 1e-4 of it; the forcing is quasi-periodic (stage 2 meshes at
    23/61 of stage 1) and the datasets say so."""
    revs = 8
    lines = {}
    for depth in ("0 mm", "2 mm"):
        model = _two_stage(depth, tmp_path)
        assert model.faults.gear == "g1" and model.mesh_order == 19
        assert model.quasi_periodic
        revolution = 2.0 * math.pi / model.omega
        ds = geardyn.simulate(model, run=geardyn.RunSettings(
            transient=10 * revolution, samples=revs, steps_per_period=19 * 128))
        assert ds.attrs["forcing"] == "quasi-periodic"
        assert ds.attrs["faulty_gear"] == "g1" and ds.attrs["mesh_cycles_per_period"] == 19
        f = ds["F_stage1"].values[:-1]
        window = np.hanning(f.size)
        lines[depth] = np.abs(np.fft.rfft((f - f.mean()) * window)) * 2.0 / window.sum()
    mesh_line = lines["0 mm"][19 * revs]
    assert lines["2 mm"][19 * revs] == pytest.approx(mesh_line, rel=0.02)
    for k in (18, 20):
        assert lines["2 mm"][k * revs] > 3e-3 * mesh_line, k
        assert lines["0 mm"][k * revs] < 1e-4 * mesh_line, k


def test_the_forcing_says_whether_the_revolution_is_a_common_period(tmp_path):
    """A crack on the output wheel g4 (71 teeth, stage 2 at 23/61 of stage 1): the period is
    g4's revolution, 71 x 61 / 23 stage-1 mesh cycles, not a whole number, so stage 1's phase
    does not close on it: quasi-periodic, and the datasets say so. The one-stage pair with a
    crack on its wheel: one wheel revolution, 48 mesh cycles, periodic."""
    model = _two_stage("1 mm", tmp_path, gear="g4")
    assert model.mesh_order == pytest.approx(71 * 61 / 23, rel=1e-12)
    np.testing.assert_allclose(model._kernel_orders, [71 * 61 / 23, 1.0], rtol=1e-12)
    np.testing.assert_allclose(model.orders, [1.0, 23 / 61], rtol=1e-12)
    attrs = model.dataset_attrs()
    assert model.quasi_periodic and attrs["forcing"] == "quasi-periodic"
    assert attrs["section"] == "once per revolution of g4"
    assert attrs["faulty_meshes"] == "stage2" and attrs["mesh_cycles_per_period"] == 71
    pair = _pair_model((g.RootCrack(**CRACK, gear="w", tooth=5),))
    assert pair.mesh_order == 48 and not pair.quasi_periodic
    assert pair.dataset_attrs()["forcing"] == "periodic"


# ---------------------------------------------------------------- errors
@pytest.mark.parametrize(("fault", "field"), [
    (dict(gear="g9"), "crack.gear"),
    (dict(gear="p", tooth=19), "crack.tooth"),
])
def test_bad_faults_name_the_field(fault, field):
    with pytest.raises(ParameterError) as err:
        _pair_train((g.RootCrack(**{**CRACK, **fault}),))
    assert err.value.field == field


def test_faults_need_the_potential_energy_stiffness_and_one_gear():
    bodies = [Gear("p", 1e-3, geometry=PINION), Gear("w", 1e-2, geometry=WHEEL)]
    with pytest.raises(ParameterError) as err:
        GearTrain(bodies, bearings=[Bearing("bp", "p", math.inf),
                                    Bearing("bw", "w", math.inf)],
                  meshes=[Mesh("m", "p", "w", "iso")], driven="p", free=True,
                  faults=g.RootCrack(**CRACK, gear="p"))
    assert err.value.field == "m.stiffness"
    with pytest.raises(ParameterError) as err:
        _pair_train((g.RootCrack(**CRACK, gear="p"), g.BrokenTooth(gear="w")))
    assert err.value.field == "faults"
    with pytest.raises(ParameterError) as err:  # the PE mesh's waveform is the teeth's
        TrainModel(_pair_train(), torques={"p": 1.0}, load="w", stiffness_fluctuation=0.2)
    assert err.value.field == "stiffness_fluctuation"
    with pytest.raises(ParameterError) as err:  # a static error once per revolution
        TrainModel(_pair_train((g.RootCrack(**CRACK, gear="p"),)), torques={"p": 1.0},
                   load="w", mesh_error=1e-6)
    assert err.value.field == "mesh_error.m"


def test_study_fault_errors_name_the_table(tmp_path):
    text = STUDY.read_text().replace('stiffness = "iso"', 'stiffness = "potential_energy"\n'
                                     'bore_radius = "10 mm"')
    for extra, loc in (('gear = "g9"\ntooth = 0\ndepth = "1 mm"', "train.faults.0.gear"),
                       ('gear = "g1"\ntooth = 40\ndepth = "1 mm"', "train.faults.0.tooth"),
                       ('gear = "g1"\ndepth = "-1 mm"', "train.faults.0.depth")):
        path = tmp_path / "bad.toml"
        path.write_text(text + f'\n[[train.faults]]\nkind = "crack"\n{extra}\n')
        with pytest.raises(Exception) as err:
            load_study(path)
        assert loc in str(err.value).replace("[", ".").replace("]", "").replace(" ", ""), \
            str(err.value)


def test_iso_train_keeps_the_mesh_cycle_period():
    """A train on ISO stiffness (no tables): its waveform the one given, the period a mesh
    cycle."""
    bodies = [Gear("p", 1e-3, geometry=PINION), Gear("w", 1e-2, geometry=WHEEL)]
    train = GearTrain(bodies, bearings=[Bearing(f"b{n}", n, math.inf) for n in "pw"],
                      meshes=[Mesh("m", "p", "w", "iso")], driven="p", free=True)
    model = TrainModel(train, torques={"p": 1.0}, load="w", stiffness_fluctuation=0.1)
    assert model.mesh_order == 1 and model.faults is None
    assert model.fourier.shape == (1, 2)
    assert model.dataset_attrs()["mesh_stiffness_methods"] == "iso"


def test_analyses_run_on_a_cracked_train():
    """A sweep in the input speed, its axes, the modes and the static forces of the pair with a
    cracked pinion tooth; the forcing period is the pinion's revolution (periodic: one stage)."""
    model = _pair_model((g.RootCrack(**CRACK, gear="p", tooth=1),), backlash=5e-6,
                        mesh_damping=0.05)
    assert not model.quasi_periodic and model.mesh_order == 19
    fast = model.with_params(input_speed=2000.0)
    assert fast.input_speed == pytest.approx(2000.0, rel=1e-12)
    assert fast.mesh_frequency == pytest.approx(2000.0 * 19 * 2 * math.pi / 60, rel=1e-12)
    assert fast.omega * fast.time_scale == pytest.approx(2000.0 * 2 * math.pi / 60, rel=1e-12)
    revolution = 2.0 * math.pi / fast.omega
    br = geardyn.bifurcation(model, "input_speed", [2000.0, 3000.0],
                             run=geardyn.RunSettings(transient=revolution, samples=2,
                                                     steps_per_period=19 * 128))
    assert np.all(br["status"].values == 0) and np.all(np.isfinite(br["poincare"].values))
    assert br.attrs["faulty_gear"] == "p" and br.attrs["forcing"] == "periodic"
    assert br["input_speed"].attrs["units"] == "rpm"
    axes = fast.speed_axes(np.array([fast.omega]))
    assert axes["input_speed"][0][0] == pytest.approx(2000.0, rel=1e-12)
    assert axes["mesh_frequency"][0][0] == pytest.approx(fast.mesh_frequency / (2 * math.pi))
    assert np.all(np.isfinite(model.modes()["frequency"].values))
    assert model.static_mesh_forces()[0] == pytest.approx(40.0 / PINION.base_radius, rel=1e-9)


# ---------------------------------------------------------------- a planetary stage's sun
def test_cracked_sun_of_a_train_stage_is_the_planetary_sets():
    """A planetary stage built from elements (25/23/71, four planets, ring held, sun driven,
    sun-planet meshes on the potential-energy stiffness, mesh_phase="geometry") with a crack on
    sun tooth 7: every sun-planet mesh's stiffness over the sun's revolution relative to the
    carrier equals that of PlanetaryGearSet.from_geometry with the same crack, whose tooth
    passages come from the planet angles (geardyn.models.planetary_faults): the train's, from
    its unreduced passage steps across the sun between the meshes, put the crack on each mesh
    at the same time. Drive and coast flank, to 1e-10 of the mean."""
    from test_planetary_pe import MEMBERS, stage

    geo = stage()
    z, n, h = geo.sun.teeth, geo.n_planets, 3
    crack = dict(**CRACK, gear="sun", tooth=7)
    rc = geo.sun_mesh.centre_distance
    bodies = [Gear("sun", 1e-3, mass=0.5, geometry=geo.sun),
              Gear("ring", 1.0, mass=3.0, geometry=geo.ring),
              geardyn.trains.Inertia("carrier", 0.1, mass=5.0)]
    bearings = [Bearing(f"{k}_bearing", k, 1e8) for k in ("sun", "ring", "carrier")]
    meshes = []
    for i, psi in enumerate(geo.planet_angles):
        bodies.append(Gear(f"p{i + 1}", 1e-3, mass=0.3, geometry=geo.planet))
        bearings.append(Bearing(f"pin{i + 1}", f"p{i + 1}", 1e8, host="carrier", radius=rc,
                                angle=psi))
        meshes.append(Mesh(f"s{i + 1}", "sun", f"p{i + 1}", "potential_energy", angle=psi,
                           bore_radius=10e-3))
    meshes += [Mesh(f"r{i + 1}", f"p{i + 1}", "ring", 5e8, internal=True, angle=psi + math.pi)
               for i, psi in enumerate(geo.planet_angles)]
    train = GearTrain(bodies, [geardyn.trains.Shaft("output", "carrier", "ground", 1e6)],
                      bearings, meshes, fixed=("ring",), driven="sun",
                      faults=g.RootCrack(**crack))
    model = TrainModel(train, torques={"sun": 5.0}, mesh_phase="geometry", harmonics=h)
    assert model.faults.meshes == tuple(f"s{i + 1}" for i in range(n))
    assert model.mesh_order == z and model._kernel_orders[0] == 1.0
    gs = geardyn.PlanetaryGearSet.from_geometry(
        geo, harmonics=h, stiffness="potential_energy",
        stiffness_options={"sun_bore_radius": "10 mm", "planet_bore_radius": "10 mm",
                           "ring_rim_radius": "85 mm"},
        faults=[g.RootCrack(**crack)], **MEMBERS)
    assert gs.mesh_order == z
    theta = np.linspace(0.0, 2.0 * math.pi, 1001)
    for coast in (False, True):
        coef = gs.fourier_coast if coast else gs.fourier
        mean = gs.coast_stiffnesses() if coast else gs.mesh_stiffnesses()
        for m in range(n):
            want = mean[m] * evaluate_series(np.concatenate([[1.0], coef[m]]), theta)
            got = _train_stiffness(model, m, theta, coast)
            np.testing.assert_allclose(got, want, rtol=0.0, atol=1e-10 * mean[m])


def test_symmetric_coast_puts_the_drive_table_on_both_flanks():
    """coast="symmetric" on the potential-energy stiffness: the coast flank is the drive
    flank's series and mean (one flank), "mirror" the coast table's (two flanks); a waveform
    pair for every mesh is refused where a mesh takes its waveform from its teeth."""
    sym, mirror = _pair_model(coast="symmetric"), _pair_model()
    assert sym.fourier_coast is sym.fourier and not sym._mirrored
    assert np.array_equal(sym.coast_stiffnesses(), sym.mesh_stiffnesses())
    assert np.array_equal(sym.fourier, mirror.fourier) and mirror._mirrored
    assert not np.array_equal(mirror.fourier_coast, mirror.fourier)
    assert "stiffness_fluctuation" not in mirror.physical_names  # the teeth give it
    with pytest.raises(ParameterError) as err:
        TrainModel(_pair_train(), torques={"p": 1.0}, load="w", waveform=([0.1], [0.0]))
    assert err.value.field == "waveform"
