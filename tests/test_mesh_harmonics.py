"""Each mesh's own harmonic count and step (the planetary kernels' ``harmonics`` and
``harmonic_step`` entries of a mesh block): the kernels sum a mesh's stiffness series only up to
its last harmonic with a coefficient that is not zero, and past the first only over the
multiples of the step that all its nonzero harmonics are (a healthy mesh of a faulty set: the
faulty gear's teeth Z_f), and the results are bitwise those of summing every term of every mesh
to the longest series.

Checks: the counts and steps equal the last nonzero harmonic and the greatest common divisor of
the nonzero harmonics found here from the model's own series (a cracked two-stage train: stage
1 over g1's revolution, H x 19 harmonics, stage 2 H; a planetary set with a longer sun than ring
series, signed zeros; a set over Z_f = 5 mesh cycles whose ring series has only every 5th
harmonic); simulate (the per-lane functions: shared recurrence, two flanks, own phases) and
run_lanes (the lane-block forms, lanes whose counts and steps differ in one block) give bitwise
the trajectories of the same vectors with every count and step unset (the kernels then add
every one of the ``n_harmonics`` terms: the padded path), and a count one short of a mesh's
series or a step twice its own changes them (the comparison sees a dropped harmonic).
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

import geardyn
from geardyn.io.toml import builtin_study_text, load_study
from geardyn.models import planetary_kernels as pk
from geardyn.solvers.ensemble import run_lanes
from geardyn.solvers.kernels import kernels_for

H = 3  # mesh harmonics of the train's potential-energy series (short runs)
RUN = geardyn.RunSettings(transient=20.0, samples=3, steps_per_period=64)


def _count_rows(model: geardyn.Model, entry: int = pk.M_NH) -> list[int]:
    """Per mesh the index of its ``harmonics`` entry (or of the block entry ``entry``)."""
    lay = model._layout
    nm = int(model.params[pk.N_MESH])
    return [lay["mesh"] + m * lay["block"] + entry for m in range(nm)]


def _unset(P: np.ndarray, model: geardyn.Model, lanes: slice | int = slice(None)) -> np.ndarray:
    """A copy of ``P`` with every mesh's count and step unset in ``lanes`` (the padded path)."""
    out = P.copy()
    out[lanes, _count_rows(model) + _count_rows(model, pk.M_HSTEP)] = 0.0
    return out


def _last_nonzero(model: geardyn.Model) -> np.ndarray:
    """Per mesh: the last harmonic (1-based) whose drive or coast coefficients are not both
    zero in the model's own series (``fourier``, ``fourier_coast``), at least 1."""
    both = np.abs(model.fourier) + np.abs(model.fourier_coast)
    pairs = both[:, 0::2] + both[:, 1::2]
    out = [max([h + 1 for h in np.nonzero(row)[0]], default=0) for row in pairs]
    return np.maximum(np.array(out), 1)


def _gcd_nonzero(model: geardyn.Model) -> np.ndarray:
    """Per mesh: the greatest common divisor of the harmonics (1-based) whose drive or coast
    coefficients are not both zero in the model's own series, 1 where there is none."""
    both = np.abs(model.fourier) + np.abs(model.fourier_coast)
    pairs = both[:, 0::2] + both[:, 1::2]
    return np.array([max(math.gcd(*(np.nonzero(row)[0] + 1).tolist()), 1) for row in pairs])


def _with_counts(model: geardyn.Model, counts: dict[int, float] | float,
                 entry: int = pk.M_NH) -> geardyn.Model:
    """A copy whose mesh ``harmonics`` entries (or the block entry ``entry``) are set (a
    number: every mesh; 0 unsets them)."""
    out = copy.copy(model)
    out.params = model.params.copy()
    rows = _count_rows(model, entry)
    for m, row in enumerate(rows):
        if isinstance(counts, dict):
            if m in counts:
                out.params[row] = counts[m]
        else:
            out.params[row] = counts
    return out


def _padded(model: geardyn.Model) -> geardyn.Model:
    """A copy with every mesh's count and step unset: the kernels add all ``n_harmonics``
    terms of every mesh (the padded path)."""
    out = copy.copy(model)
    out.params = _unset(model.params[None, :], model)[0]
    return out


def _trajectory(model: geardyn.Model) -> np.ndarray:
    """Every recorded value of a simulate of 3 forcing periods, 64 steps a mesh cycle."""
    steps = 64 * int(round(model.mesh_order))
    ds = geardyn.simulate(model, run=geardyn.RunSettings(transient=0.0, samples=3,
                                                         steps_per_period=steps))
    out = np.concatenate([ds[v].values.ravel() for v in ds.data_vars])
    assert np.all(np.isfinite(out))
    return out


@pytest.fixture(scope="module")
def cracked_train() -> geardyn.Model:
    text = builtin_study_text("two_stage_train")
    text = text.replace('stiffness = "iso"', 'stiffness = "potential_energy"\n'
                        'bore_radius = "10 mm"').replace("stiffness_fluctuation = 0.25\n",
                                                         f"harmonics = {H}\n")
    text += '\n[[train.faults]]\nkind = "crack"\ngear = "g1"\ntooth = 3\ndepth = "1 mm"\n'
    return geardyn.build_model(load_study(text))


def test_train_counts_are_each_meshs_last_harmonic(cracked_train):
    model = cracked_train
    nh = int(model.params[pk.N_HARM])
    assert model.mesh_order == 19 and nh == 19 * H
    counts = model.params[_count_rows(model)]
    np.testing.assert_array_equal(counts, _last_nonzero(model))
    assert counts[0] > 18 * H and counts[1] == H  # stage 1 over the revolution; stage 2 not
    np.testing.assert_array_equal(model.params[_count_rows(model, pk.M_HSTEP)],
                                  _gcd_nonzero(model))


def test_cracked_train_trajectory_is_bitwise_the_padded_ones(cracked_train):
    """simulate (per-lane functions: two flanks, stage 2 at its own phase): the same bits with
    the counts as with every mesh summed to n_harmonics; stage 1 one harmonic short differs."""
    model = cracked_train
    got = _trajectory(model)
    np.testing.assert_array_equal(got, _trajectory(_padded(model)))
    short = model.params[_count_rows(model)[0]] - 1
    assert not np.array_equal(got, _trajectory(_with_counts(model, {0: short})))


def test_cracked_train_sweep_lanes_are_bitwise_the_padded_ones(cracked_train):
    """run_lanes (lane-block forms: the own-phase cache for stage 2) in input speed, lane 0's
    counts unset (all n_harmonics) and the others' their own: the padded lanes' bits."""
    model = cracked_train
    P = model.lane_params("input_speed", [2000.0, 3000.0, 4500.0])
    rows = _count_rows(model)
    padded = _unset(P, model)
    mixed = _unset(P, model, 0)
    y0 = model.initial_state()
    run = geardyn.RunSettings(transient=2.0 * 2.0 * np.pi / P[:, pk.OMEGA].min(), samples=2,
                              steps_per_period=19 * 64)
    want = run_lanes(model, padded, y0, run=run)
    assert np.all(want.status == 0) and np.all(np.isfinite(want.samples))
    for Q in (P, mixed):
        got = run_lanes(model, Q, y0, run=run)
        np.testing.assert_array_equal(got.samples, want.samples)
    short = P.copy()
    short[:, rows[1]] = H - 1
    assert not np.array_equal(run_lanes(model, short, y0, run=run).samples, want.samples)


def _planetary(**kw) -> geardyn.PlanetaryGearSet:
    M = geardyn.Member
    args = dict(
        n_planets=3, sun=M(0.4, 0.39, 1e8, 0.0, radius=0.03), ring=M(2.35, 3.0, 1e8, 1e9),
        carrier=M(5.43, 6.29, 1e8, 0.0), planet=M(0.66, 0.61, 1e8),
        sun_mesh_stiffness=5e8, ring_mesh_stiffness=5e8, sun_mesh_phase=[0.0, 0.3, 0.6],
        ring_mesh_phase=[0.1, 0.4, 0.7], sun_backlash="2 um", ring_backlash="1 um",
        modal_damping=0.02, sun_torque=50.0,
        waveform={"sun": ([0.08, -0.03, 0.02, 0.01, -0.005], [0.02, 0.01, 0.0, -0.01, 0.004]),
                  "ring": ([0.1, -0.0], [0.0, -0.0])})
    args.update(kw)
    return geardyn.PlanetaryGearSet(**args)


@pytest.mark.parametrize("kw", [
    {},                                                        # one flank: shared recurrence
    {"coast_waveform": ([0.05, 0.01], [0.0, 0.02])},           # two flanks: per mesh
    {"waveform": {"sun": ([0.08, 0.0, 0.02], [0.02, 0.0, 0.01]),
                  "ring": ([-0.0, 0.0], [-0.0, -0.0])}},       # a series of signed zeros
])
def test_planetary_simulate_is_bitwise_the_padded_one(kw):
    gs = _planetary(**kw)
    nh = int(gs.params[pk.N_HARM])
    counts = gs.params[_count_rows(gs)]
    np.testing.assert_array_equal(counts, _last_nonzero(gs))
    assert counts.min() < nh  # a mesh sums fewer harmonics than the longest
    np.testing.assert_array_equal(gs.params[_count_rows(gs, pk.M_HSTEP)], _gcd_nonzero(gs))
    got = _trajectory(gs)
    np.testing.assert_array_equal(got, _trajectory(_padded(gs)))
    np.testing.assert_array_equal(got, _trajectory(_with_counts(gs, float(nh))))
    short = {m: c - 1 for m, c in enumerate(counts) if c == nh}
    assert not np.array_equal(got, _trajectory(_with_counts(gs, short)))


def test_planetary_lanes_whose_counts_differ_are_bitwise_the_padded_ones():
    """A block whose lane 0 has no sun fluctuation (sun counts 1) and whose other lanes have
    the rectangular series: the block sums each mesh to its longest lane's count; every lane's
    bits are those of the padded lanes and of its own simulate."""
    gs = _planetary(waveform="rectangular", harmonics=7, sun_stiffness_fluctuation=0.1,
                    ring_stiffness_fluctuation=0.05)
    values = [0.0, 0.1, 0.2]
    P = gs.lane_params("sun_stiffness_fluctuation", values)
    rows = _count_rows(gs)
    assert np.all(P[0, rows[:3]] == 1.0) and np.all(P[1:, rows[:3]] > 1.0)
    padded = _unset(P, gs)
    y0 = gs.initial_state()
    got = run_lanes(gs, P, y0, run=RUN)
    assert np.all(got.status == 0)
    np.testing.assert_array_equal(got.samples, run_lanes(gs, padded, y0, run=RUN).samples)
    for j in (0, 2):
        ds = geardyn.simulate(gs.with_params(sun_stiffness_fluctuation=values[j]), run=RUN,
                              y0=y0)
        np.testing.assert_array_equal(got.samples[j], ds["poincare"].values[1:])


Z = 5  # mesh cycles per forcing period of the stepped set
#: A coast flank at harmonic Z alone (the ring meshes keep their step).
COAST = ([0.0] * (Z - 1) + [0.05], [0.0] * (Z - 1) + [0.02])


def _stepped(**kw) -> geardyn.PlanetaryGearSet:
    """A set over Z mesh cycles (``mesh_order``): the sun meshes' series has every harmonic up
    to 2 Z, the ring meshes' only the harmonics Z and 2 Z (a healthy mesh of a faulty set)."""
    h = np.arange(1, 2 * Z + 1)
    sun = (0.04 / h, 0.02 * np.cos(h))
    ring = (np.where(h % Z == 0, 0.1 / h, 0.0), np.where(h % Z == 0, -0.03, 0.0))
    return _planetary(mesh_order=Z, waveform={"sun": sun, "ring": ring}, **kw)


@pytest.mark.parametrize("kw", [{}, {"coast_waveform": COAST}])
def test_stepped_series_simulate_is_bitwise_the_padded_one(kw):
    gs = _stepped(**kw)
    steps = gs.params[_count_rows(gs, pk.M_HSTEP)]
    np.testing.assert_array_equal(steps, _gcd_nonzero(gs))
    np.testing.assert_array_equal(gs.params[_count_rows(gs)], _last_nonzero(gs))
    assert list(steps) == [1] * 3 + [Z] * 3
    got = _trajectory(gs)
    np.testing.assert_array_equal(got, _trajectory(_padded(gs)))
    assert not np.array_equal(got, _trajectory(_with_counts(gs, {3: 2 * Z}, pk.M_HSTEP)))


def test_stepped_series_at_its_own_phase_is_bitwise_the_padded_one():
    """A ring mesh at order 2 (a raw override: the own-phase forms) with its step Z."""
    gs = _stepped().with_params(r1_order=2.0)
    assert gs.params[pk.MULTI_ORDER] == 1.0
    got = _trajectory(gs)
    np.testing.assert_array_equal(got, _trajectory(_padded(gs)))
    assert not np.array_equal(got, _trajectory(_with_counts(gs, {3: 2 * Z}, pk.M_HSTEP)))
    P = gs.lane_params("Omega", [0.15, 0.2, 0.25])
    y0 = gs.initial_state()
    want = run_lanes(gs, _unset(P, gs), y0, run=RUN)
    assert np.all(want.status == 0) and np.all(np.isfinite(want.samples))
    for Q in (P, _unset(P, gs, 1)):
        np.testing.assert_array_equal(run_lanes(gs, Q, y0, run=RUN).samples, want.samples)


@pytest.mark.parametrize("kw", [{}, {"coast_waveform": COAST}])
def test_stepped_series_lanes_are_bitwise_the_padded_ones(kw):
    """run_lanes of the stepped set (shared phase: one or two flanks), with the lanes' own
    counts and steps, and with lane 1's unset (the block then adds every term): the padded
    lanes' bits; the ring's step doubled in every lane differs."""
    gs = _stepped(**kw)
    P = gs.lane_params("Omega", [0.15, 0.2, 0.25])
    y0 = gs.initial_state()
    want = run_lanes(gs, _unset(P, gs), y0, run=RUN)
    assert np.all(want.status == 0) and np.all(np.isfinite(want.samples))
    for Q in (P, _unset(P, gs, 1)):
        np.testing.assert_array_equal(run_lanes(gs, Q, y0, run=RUN).samples, want.samples)
    wrong = P.copy()
    wrong[:, _count_rows(gs, pk.M_HSTEP)[3:]] = 2 * Z
    assert not np.array_equal(run_lanes(gs, wrong, y0, run=RUN).samples, want.samples)


def test_sets_and_trains_of_any_counts_share_one_compiled_kernel(cracked_train):
    """The counts and steps are entries of the vector, not of the code: sets of 3 and 5 planets,
    stepped or not, and the cracked train run on one kernel module and one compiled trajectory
    signature."""
    models = [_planetary(), _stepped(), cracked_train,
              _planetary(n_planets=5, sun_mesh_phase=0.0, ring_mesh_phase=0.0)]
    modules = {id(kernels_for(m.kernel)) for m in models}
    assert len(modules) == 1
    for m in models:
        _trajectory(m)
    assert len(kernels_for(models[0].kernel).trajectory.signatures) == 1


def test_reloaded_slots_take_their_lanes_counts_anew():
    """400 lanes (more than the blocks of 64: slots refilled as lanes finish, at different Omega),
    the first 300 without sun fluctuation (sun counts 1), the others with the rectangular series:
    the lanes' bits are the padded lanes' (whatever slots the full lanes are loaded into)."""
    gs = _planetary(waveform="rectangular", harmonics=7, sun_stiffness_fluctuation=0.1,
                    ring_stiffness_fluctuation=0.05)
    flat = gs.with_params(sun_stiffness_fluctuation=0.0)
    omegas = np.linspace(0.5, 1.4, 400)
    P = np.vstack([flat.lane_params("Omega", omegas[:300]), gs.lane_params("Omega", omegas[300:])])
    rows = _count_rows(gs)
    assert np.all(P[:300, rows[0]] == 1.0) and np.all(P[300:, rows[0]] == 7.0)
    y0 = gs.initial_state()
    run = RUN.replace(transient=5.0)
    want = run_lanes(gs, _unset(P, gs), y0, run=run)
    assert np.all(want.status == 0) and np.all(np.isfinite(want.samples))
    np.testing.assert_array_equal(run_lanes(gs, P, y0, run=run).samples, want.samples)
