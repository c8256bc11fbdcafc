"""Labelled fault datasets (geardyn.fault_dataset): labels, resuming, one lane against DOP853 on
the same stiffness table, the noise's SNR and seed, local processes and Dask bitwise the same, a
diverged condition kept and marked, a planetary set's ring-sensor dataset, bad fields."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr
from scipy.integrate import solve_ivp

import geardyn
from geardyn.errors import ParameterError
from geardyn.gears import BrokenTooth, GearMesh, RootCrack, SpurGear
from geardyn.testing import assert_result

Z1, Z2, M, ALPHA, B = 19, 48, 3.2e-3, math.radians(20.0), 0.016
INERTIA, BORES = (4.3659e-4, 8.3602e-3), (0.012, 0.035)
MESH = GearMesh(SpurGear(Z1, M, ALPHA, B, name="pinion"), SpurGear(Z2, M, ALPHA, B, name="wheel"))
FAULTS = (None, RootCrack("1.5 mm"), BrokenTooth("pinion", 3))
SPEEDS, TORQUES, SEEDS = (1000.0, 1500.0), (40.0, 60.0), (0, 7)
DURATION, RATE = 0.02, 20_000.0


HALF_B = 10e-6


def build(faults):
    return geardyn.SpurPair.from_geometry(MESH, bore_radius=BORES, speed=1000, torque=50.0,
                                          faults=faults, inertia=INERTIA, backlash=HALF_B,
                                          speed_unit="rpm", stiffness_form="table")


def spec(**kw) -> geardyn.FaultDatasetSpec:
    args = dict(build=build, faults=FAULTS, speeds=SPEEDS, torques=TORQUES, seeds=SEEDS,
                snr_db=10.0, duration=DURATION, sample_rate=RATE, chunk=5)
    args.update(kw)
    return geardyn.FaultDatasetSpec(**args)


def dataset(s: geardyn.FaultDatasetSpec, **kw) -> xr.Dataset:
    """fault_dataset in this process (one process: the tests run on a shared machine)."""
    return geardyn.fault_dataset(s, **{"workers": 1, **kw})


@pytest.fixture(scope="module")
def reference():
    """One uninterrupted run in memory (12 conditions, chunks of 5)."""
    return dataset(spec())


def _same(a: xr.Dataset, b: xr.Dataset) -> None:
    for name in a.data_vars:
        assert np.array_equal(a[name].values, b[name].values, equal_nan=True), name


def test_the_store_opens_with_xarray_and_its_labels_are_the_spec(reference, tmp_path):
    path = tmp_path / "faults.zarr"
    dataset(spec(), store=path)
    ds = xr.open_zarr(path)
    assert_result(reference, "fault-dataset")
    assert ds.sizes == {"fault": 3, "speed": 2, "torque": 2, "seed": 2, "time": 400}
    assert [str(k) for k in ds["fault_kind"].values] == ["healthy", "crack", "broken_tooth"]
    assert ds["fault_size"].values[1] == pytest.approx(1.5e-3)
    assert np.isnan(ds["fault_size"].values[[0, 2]]).all()
    assert [str(g) for g in ds["fault_gear"].values] == ["none", "pinion", "pinion"]
    assert ds["fault_tooth"].values.tolist() == [-1, 0, 3]
    assert ds["speed"].values.tolist() == list(SPEEDS)
    assert ds["speed"].attrs["units"] == "rpm" and ds.attrs["speed_input"] == "speed"
    assert ds["torque"].values.tolist() == list(TORQUES)
    assert ds["seed"].values.tolist() == list(SEEDS)
    assert ds["time"].values[1] == 1.0 / RATE
    assert ds.attrs["snr_db"] == 10.0 and ds.attrs["sample_rate"] == RATE
    assert ds.attrs["duration"] == DURATION and ds.attrs["n_signals"] == 24
    assert (ds["status"].values == 0).all()
    assert (ds["stiffness_error_drive_max"].values < 1e-12).all()  # the table form
    _same(reference, ds.load())


def test_a_killed_run_resumes_to_the_same_bits(reference, tmp_path):
    from geardyn.execution.zarr_store import LaneStore, load_zarr_dataset

    path = tmp_path / "killed.zarr"
    calls = []

    def kill_after_first_chunk(done, total):
        calls.append(done)
        if done > 0:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        dataset(spec(), store=path, progress=kill_after_first_chunk)
    with pytest.raises(FileNotFoundError):
        load_zarr_dataset(path)  # no dataset yet
    resumed = []
    ds = dataset(spec(), store=path, progress=lambda d, t: resumed.append(d))
    assert resumed[0] == 5  # the first chunk was read back, not recomputed
    assert LaneStore(path).chunk_runs().tolist() == [1, 2, 2]
    _same(reference, ds)
    _same(reference, xr.open_zarr(path).load())


def test_one_lane_is_the_motion_on_the_same_table_by_dop853():
    """Without noise, condition (crack, 1500 rpm, 60 N m) against the equation of motion
    integrated here by DOP853 (rtol 1e-10) on the same stiffness table, linear between its
    angles, with the mesh force F = k(theta) (x - b) + c v taken at the sample times: within
    2e-3 of the signal's peak-to-peak (the step rule's RK4; measured 2.8e-4)."""
    ds = dataset(spec(snr_db=math.inf, seeds=(0,)))
    model = build((FAULTS[1],)).with_params(speed=1500.0, torque=60.0)
    table = model.stiffness
    kd, kc = (np.asarray(table[v].values) for v in ("mesh_stiffness", "mesh_stiffness_coast"))
    rb1 = M * Z1 * math.cos(ALPHA) / 2.0
    rb2 = M * Z2 * math.cos(ALPHA) / 2.0
    mass = INERTIA[0] * INERTIA[1] / (INERTIA[0] * rb2 ** 2 + INERTIA[1] * rb1 ** 2)
    c = 2.0 * 0.05 * math.sqrt(float(np.mean(kd)) * mass)
    omega = 1500.0 * 2.0 * math.pi / 60.0

    def k(tab, t):
        u = (omega * t / (2.0 * math.pi)) % 1.0 * tab.size
        j = int(u)
        return tab[j] * (1.0 - (u - j)) + tab[(j + 1) % tab.size] * (u - j)

    def elastic(t, x):
        if x > HALF_B:
            return k(kd, t) * (x - HALF_B)
        if x < -HALF_B:
            return k(kc, t) * (x + HALF_B)
        return 0.0

    def rhs(t, y):
        return [y[1], (60.0 / rb1 - c * y[1] - elastic(t, y[0])) / mass]

    t = np.arange(round(DURATION * RATE)) / RATE
    y0 = np.array([60.0 / rb1 / float(np.mean(kd)) + HALF_B, 0.0])
    ref = solve_ivp(rhs, (0.0, t[-1]), y0, method="DOP853", rtol=1e-10, atol=1e-16, t_eval=t)
    assert ref.status == 0
    expected = np.array([elastic(ti, x) + c * v for ti, x, v in zip(t, *ref.y, strict=True)])
    got = ds["signal"].sel(speed=1500.0, torque=60.0).values[1, 0]
    assert np.max(np.abs(got - expected)) < 2e-3 * np.ptp(expected)
    assert np.ptp(expected) > 0.1 * np.mean(expected)  # the crack's dynamic force is there


def test_noise_has_the_requested_snr_and_follows_the_seed(reference):
    clean = dataset(spec(snr_db=math.inf))
    noise = reference["signal"] - clean["signal"]  # (fault, speed, torque, seed, time)
    rms = clean["signal"].std("time").isel(seed=0)  # about the mean
    n = noise.sizes["time"]
    snr_power = (rms ** 2 / (noise ** 2).mean("time")).values
    tol = 4.0 * math.sqrt(2.0 / n)  # sampling error of a variance from n normal samples
    assert np.all(np.abs(snr_power / 10.0 - 1.0) < tol)
    assert np.allclose(reference["noise_std"], rms / 10.0 ** 0.5, rtol=1e-12)
    a, b = noise.isel(seed=0).values, noise.isel(seed=1).values
    assert not np.allclose(a, b)
    again = dataset(spec(seeds=(7,)))
    assert np.array_equal(again["signal"].values[..., 0, :],
                          reference["signal"].sel(seed=7).values)


def test_two_local_processes_give_the_bits_of_one(reference, tmp_path):
    ds = geardyn.fault_dataset(spec(), workers=2, store=tmp_path / "two.zarr")
    _same(reference, ds)


def test_a_diverged_condition_is_kept_and_marked():
    """At 2 kHz and 600 steps per forcing period, 500 rpm takes a step of 167 us (omega_n h =
    4.8, past RK4's stability limit 2.8) and diverges; 3000 rpm (33 us) does not. The diverged
    condition keeps its place, its status code and a NaN signal."""
    ds = dataset(spec(speeds=(500.0, 3000.0), torques=(50.0,), sample_rate=2000.0,
                      steps_per_period=600))
    status = ds["status"].sel(torque=50.0)
    assert ds.sizes["speed"] == 2 and ds.attrs["diverged"] == 3
    assert (status.sel(speed=500.0).values == int(geardyn.Status.DIVERGED)).all()
    assert (status.sel(speed=3000.0).values == int(geardyn.Status.OK)).all()
    assert np.isnan(ds["signal"].sel(speed=500.0).values).all()
    assert np.isfinite(ds["signal"].sel(speed=3000.0).values).all()


def test_a_dask_run_is_bitwise_the_local_run(reference):
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        remote = dataset(spec(), client=client)
    _same(reference, remote)


@pytest.mark.parametrize("kw,field", [
    (dict(speeds=[]), "speeds"), (dict(speeds=[1000.0, 1000.0]), "speeds"),
    (dict(torques=["x"]), "torques"), (dict(seeds=[-1]), "seeds"), (dict(seeds=[1.5]), "seeds"),
    (dict(snr_db=float("nan")), "snr_db"), (dict(duration=0.0), "duration"),
    (dict(sample_rate=-1.0), "sample_rate"), (dict(transient=-1.0), "transient"),
    (dict(faults=()), "faults"), (dict(faults=(None, "crack")), "faults"),
    (dict(chunk=0), "chunk"), (dict(steps_per_period=2), "steps_per_period"),
    (dict(steps_per_mode=4), "steps_per_mode"),
    (dict(steps_per_mode=50, steps_per_period=1000), "steps_per_mode"),
    (dict(build=None), "build")])
def test_bad_spec_fields_are_named(kw, field):
    with pytest.raises((ParameterError, ValueError), match=field):
        spec(**kw)


def test_each_fault_kind_declares_its_size_label():
    """A condition's ``fault_size`` label is the size its fault class declares: a crack's depth,
    a spall's length (not its depth), wear's depth, NaN for a missing tooth; every kind of
    ``FAULT_KINDS`` declares one, and an object that only looks like a fault is refused."""
    from types import SimpleNamespace

    from geardyn.analysis.fault_dataset import fault_labels
    from geardyn.gears import Spall, Wear
    from geardyn.gears.faults import FAULT_KINDS

    faults = {"crack": RootCrack("1.5 mm", tooth=2), "spall": Spall("2 mm", "1 mm", "0.1 mm"),
              "wear": Wear("20 um", gear="wheel"), "broken_tooth": BrokenTooth(tooth=3)}
    assert set(faults) == set(FAULT_KINDS)
    expected = {"crack": 1.5e-3, "spall": 2e-3, "wear": 20e-6}
    for kind, fault in faults.items():
        labels = fault_labels(fault)
        assert labels["kind"] == kind and labels["tooth"] == fault.tooth
        if kind in expected:
            assert labels["size"] == pytest.approx(expected[kind], rel=1e-12)
        else:
            assert math.isnan(labels["size"])
    fake = SimpleNamespace(kind="crack", depth=1e-3, gear="pinion", tooth=0)
    with pytest.raises(ParameterError, match="faults.*RootCrack, Spall, Wear, BrokenTooth"):
        spec(faults=(None, fake))


def test_a_fault_the_model_refuses_is_named_before_any_work():
    calls = []
    bad = spec(faults=(None, RootCrack("1 mm", gear="sun")))
    with pytest.raises(ParameterError, match=r"faults\[1\]"):
        dataset(bad, progress=lambda d, t: calls.append(d))
    assert calls == []


def test_workers_must_be_a_whole_number():
    with pytest.raises(ParameterError, match="workers"):
        geardyn.fault_dataset(spec(), workers=0)


# ---------------------------------------------------------------------------------------------
# the declaration: what a model needs for a dataset is declared by its class


def test_the_inputs_and_units_are_the_classes_declarations():
    """The spec's speeds and torques go to the inputs each class declares, in their units: a
    spur pair's ``speed`` in its own speed_unit, a planetary set's ``input_speed`` in rpm."""
    from geardyn.analysis.fault_dataset import dataset_inputs, speed_unit

    pair = dataset_inputs(build(()))
    assert (pair.speed, pair.torque, pair.signal) == ("speed", "torque", "mesh_force")
    assert speed_unit(build(())) == "rpm"
    assert speed_unit(geardyn.SpurPair.from_geometry(MESH, bore_radius=BORES, speed=100.0,
                                                     torque=50.0)) == "rad/s"
    decl = geardyn.PlanetaryGearSet.capabilities.fault_dataset
    assert (decl.speed, decl.torque, decl.speed_unit, decl.signal) == (
        "input_speed", "sun_torque", "rpm", "ring_sensor")


def _progress_never(done, total):
    raise AssertionError("work started")


def test_a_model_without_the_capability_is_refused_naming_build_and_what_is_missing():
    bad = spec(build=lambda faults: geardyn.GearPair())
    with pytest.raises(ParameterError, match="build") as err:
        dataset(bad, progress=_progress_never)
    assert "speed input" in str(err.value) and "torque input" in str(err.value)
    assert "sensor signal" in str(err.value)


def test_a_declared_class_whose_instance_lacks_the_inputs_lists_them():
    """A planetary set given mesh stiffnesses (no geometry) has no input_speed and no ring
    to place a sensor on: both are listed."""
    M = geardyn.Member

    def no_geometry(faults):
        return geardyn.PlanetaryGearSet(
            n_planets=3, sun=M(0.4, 0.39, 1e8, 0.0, radius=0.03), ring=M(2.35, 3.0, 1e8, 1e9),
            carrier=M(5.43, 6.29, 1e8, 0.0), planet=M(0.66, 0.61, 1e8),
            sun_mesh_stiffness=5e8, ring_mesh_stiffness=5e8, sun_torque=10.0)

    with pytest.raises(ParameterError, match="build") as err:
        dataset(spec(build=no_geometry, faults=(None,)), progress=_progress_never)
    assert "'input_speed'" in str(err.value) and "ring_sensor signal" in str(err.value)
    assert "sun_torque" not in str(err.value)


@pytest.mark.parametrize(("sensor", "field"), [
    ({"width": 1.0}, "sensor.width"), ({"mesh": "stage1"}, "sensor.mesh")])
def test_a_sensor_setting_the_signal_does_not_take_is_named(sensor, field):
    with pytest.raises(ParameterError, match=field):
        dataset(spec(sensor=sensor), progress=_progress_never)


def test_a_declaration_is_checked_where_the_class_is_defined():
    from geardyn.core.capabilities import Capabilities, FaultDatasetInputs

    with pytest.raises(ValueError, match="mesh_forces"):
        Capabilities(fault_dataset=FaultDatasetInputs("speed", "torque", "mesh_force"))
    with pytest.raises(ValueError, match="signal"):
        FaultDatasetInputs("speed", "torque", "microphone")
    with pytest.raises(TypeError, match="stiffness_error"):
        type("NoErrors", (geardyn.GearPair,), {"capabilities": Capabilities(
            mesh_forces=True, natural_frequencies="rad/time",
            fault_dataset=FaultDatasetInputs("Omega", "F0", "mesh_force",
                                             stiffness_error=True))})


# ---------------------------------------------------------------------------------------------
# a planetary stage: the ring sensor's signal


def planetary_build(faults):
    """The shipped 25/23/71 four-planet stage on its potential-energy stiffness (a fault's
    period: one revolution of the sun)."""
    import tomllib
    from importlib.resources import files

    from planetary_example_set import planetary_by_hand

    doc = tomllib.loads(files("geardyn.studies").joinpath("planetary_example.toml").read_text())
    return planetary_by_hand(doc, stiffness="potential_energy", faults=faults,
                             stiffness_options=dict(sun_bore_radius="12 mm",
                                                    planet_bore_radius="10 mm",
                                                    ring_rim_radius="85 mm", angles=32))


def test_a_planetary_dataset_is_the_ring_sensor_signal_of_a_simulation():
    """Healthy (a zero-size crack on the sun: the same period) and a 1.5 mm sun crack, 3000
    rpm, 20 N m: each condition's clean signal is the ring sensor signal
    (planetary_sensor_signal, width pi/2) of geardyn.simulate of the same model on the same
    grid (the sample rate a whole number K of samples per forcing period, K | the steps), to
    1e-8 of its peak-to-peak (the run-up kernel's libm phase against simulate's rotated phase
    table; each fault its own time scale); the crack changes the signal."""
    from geardyn.analysis.fault_dataset import seconds_per_time_unit
    from geardyn.analysis.sensor import planetary_sensor_signal

    faults = (RootCrack("0 mm", gear="sun"), RootCrack("1.5 mm", gear="sun"))
    m = planetary_build((faults[1],)).with_params(input_speed=3000.0, sun_torque=20.0)
    unit = seconds_per_time_unit(m)
    period = 2.0 * math.pi / m.omega
    K = round(20_000.0 * period * unit)  # samples per forcing period
    n = K * math.ceil(geardyn.default_steps_per_period(m) / K)
    rate = K / (period * unit)
    s = geardyn.FaultDatasetSpec(planetary_build, faults, speeds=[3000.0], torques=[20.0],
                                 seeds=[0], snr_db=math.inf, duration=0.01, sample_rate=rate,
                                 steps_per_period=n, sensor={"width": math.pi / 2})
    ds = dataset(s)
    assert ds.attrs["speed_input"] == "input_speed" and (ds["status"].values == 0).all()
    assert [str(k) for k in ds["fault_kind"].values] == ["crack", "crack"]
    samples = ds.sizes["time"]
    for i, fault in enumerate(faults):
        model = planetary_build((fault,)).with_params(input_speed=3000.0, sun_torque=20.0)
        sim = geardyn.simulate(model, run=geardyn.RunSettings(
            transient=0.0, samples=math.ceil(samples / K), steps_per_period=n))
        expected = planetary_sensor_signal(sim, model, width=math.pi / 2)["signal"].values[
            : samples * (n // K): n // K]
        got = ds["signal"].values[i, 0, 0, 0]
        assert np.max(np.abs(got - expected)) < 1e-8 * np.ptp(expected)
    crack = ds["signal"].values[1, 0, 0, 0] - ds["signal"].values[0, 0, 0, 0]
    assert np.max(np.abs(crack)) > 0.02 * np.ptp(ds["signal"].values[0, 0, 0, 0])  # meas. 0.04


# ---------------------------------------------------------------------------------------------
# a gear train: the mesh force of its declared observables


def train_build(faults):
    """The one-stage pinion/wheel train of tests/test_trains_faults.py on the potential-energy
    stiffness (H = 6 mesh harmonics; a fault's period: one pinion revolution)."""
    from test_trains_faults import _pair_model

    return _pair_model(tuple(faults), backlash=10e-6, mesh_damping=0.04)


def test_a_train_dataset_is_the_mesh_force_of_a_simulation():
    """A zero-size and a 1.5 mm crack on pinion tooth 2, 1500 rpm, 30 N m (the train's
    declared input_speed [rpm] and input_torque [N m]): each condition's clean signal is the
    mesh force F_m of geardyn.simulate of the same model on the same grid (K samples per
    forcing period, K | the steps), to 1e-8 of its peak-to-peak; the crack changes it."""
    from geardyn.analysis.fault_dataset import seconds_per_time_unit

    faults = (RootCrack("0 mm", gear="p", tooth=2), RootCrack("1.5 mm", gear="p", tooth=2))
    m = train_build((faults[1],)).with_params(input_speed=1500.0, input_torque=30.0)
    unit = seconds_per_time_unit(m)
    period = 2.0 * math.pi / m.omega
    K = round(20_000.0 * period * unit)
    n = K * math.ceil(geardyn.default_steps_per_period(m) / K)
    rate = K / (period * unit)
    s = geardyn.FaultDatasetSpec(train_build, faults, speeds=[1500.0], torques=[30.0],
                                 seeds=[0], snr_db=math.inf, duration=0.005, sample_rate=rate,
                                 steps_per_period=n)
    ds = dataset(s)
    assert (ds.attrs["speed_input"], ds.attrs["torque_input"]) == ("input_speed",
                                                                   "input_torque")
    assert ds["speed"].attrs["units"] == "rpm" and ds.attrs["signal"] == "mesh_force"
    assert ds["signal"].attrs["meaning"] == "dynamic mesh force F_m"
    assert (ds["status"].values == 0).all()
    assert [str(g) for g in ds["fault_gear"].values] == ["p", "p"]
    samples = ds.sizes["time"]
    for i, fault in enumerate(faults):
        model = train_build((fault,)).with_params(input_speed=1500.0, input_torque=30.0)
        sim = geardyn.simulate(model, run=geardyn.RunSettings(
            transient=0.0, samples=math.ceil(samples / K), steps_per_period=n))
        expected = sim["F_m"].values[: samples * (n // K): n // K]
        got = ds["signal"].values[i, 0, 0, 0]
        assert np.max(np.abs(got - expected)) < 1e-8 * np.ptp(expected)
    crack = ds["signal"].values[1, 0, 0, 0] - ds["signal"].values[0, 0, 0, 0]
    assert np.max(np.abs(crack)) > 0.01 * np.ptp(ds["signal"].values[0, 0, 0, 0])


def test_a_train_without_a_driven_torque_lacks_the_torque_input():
    from geardyn.trains import TrainModel
    from test_trains_faults import _pair_train

    def unloaded(faults):
        return TrainModel(_pair_train(tuple(faults)), harmonics=6)

    with pytest.raises(ParameterError, match="build") as err:
        dataset(spec(build=unloaded, faults=(None,)), progress=_progress_never)
    assert "'input_torque'" in str(err.value) and "input_speed" not in str(err.value)
