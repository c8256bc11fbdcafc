"""The SI spur pair on the potential-energy stiffness (geardyn.SpurPair).

The references are written out here: the equation of motion in SI integrated by scipy's DOP853
(rtol 1e-10) with the stiffness table linearly interpolated, or with the Fourier series summed
here with numpy; the Fourier coefficients by a direct quadrature of the table; the equivalent
mass and the base radius from the textbook relations.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import geardyn
from geardyn.core.plan import default_steps_per_period
from geardyn.errors import ParameterError
from geardyn.gears import GearMesh, RootCrack, SpurGear, potential_energy_stiffness

Z1, Z2, M, ALPHA, B = 19, 48, 3.2e-3, math.radians(20.0), 0.016
BORES = (0.012, 0.035)
I1, I2 = 4.3659e-4, 8.3602e-3  # kg m^2, the 19/48 pair of the cracked-tooth literature
RB1, RB2 = M * Z1 * math.cos(ALPHA) / 2.0, M * Z2 * math.cos(ALPHA) / 2.0
MASS = I1 * I2 / (I1 * RB2 ** 2 + I2 * RB1 ** 2)
RPM, TORQUE, ZETA, HALF_B = 1000.0, 50.0, 0.05, 10e-6
ANGLES = 256  # table points per mesh cycle


def _mesh() -> GearMesh:
    return GearMesh(SpurGear(Z1, M, ALPHA, B, name="pinion"),
                    SpurGear(Z2, M, ALPHA, B, name="wheel"))


@pytest.fixture(scope="module")
def tables():
    mesh = _mesh()
    healthy = potential_energy_stiffness(mesh, bore_radius=BORES, angles=ANGLES, cycles=Z1)
    cracked = potential_energy_stiffness(mesh, bore_radius=BORES, angles=ANGLES, cycles=Z1,
                                         faults=RootCrack("1.5 mm"))
    return mesh, healthy, cracked


def _pair(mesh, table, **kw) -> geardyn.SpurPair:
    args = dict(speed=f"{RPM} rpm", torque=f"{TORQUE} N m", inertia=(I1, I2), zeta=ZETA,
                backlash=HALF_B)
    args.update(kw)
    return geardyn.SpurPair(mesh, table, **args)


def _rhs(kd, kc, omega, torque, kmean, error=0.0):
    """dy/dt of m x'' + c x' + f(x, theta) = T / r_b1 + m e (z1 Omega)^2 cos(z1 Omega t), the
    flank stiffnesses kd(theta), kc(theta) given as functions of theta = Omega t."""
    c = 2.0 * ZETA * math.sqrt(kmean * MASS)  # kmean: the table's mean drive stiffness [N/m]
    wm = Z1 * omega

    def f(t, y):
        x, v = y
        th = omega * t
        if x > HALF_B:
            fe = kd(th) * (x - HALF_B)
        elif x < -HALF_B:
            fe = kc(th) * (x + HALF_B)
        else:
            fe = 0.0
        return [v, (torque / RB1 - c * v - fe) / MASS + error * wm * wm * math.cos(wm * t)]
    return f


def _interp(table: np.ndarray):
    n = table.size

    def k(th: float) -> float:
        u = (th / (2.0 * math.pi)) % 1.0 * n
        j = int(u)
        return table[j] * (1.0 - (u - j)) + table[(j + 1) % n] * (u - j)
    return k


def _quadrature_series(table: np.ndarray, harmonics: int) -> tuple[float, np.ndarray, np.ndarray]:
    """k0, a_h, b_h by the rectangle rule over the period (exact for the trigonometric
    interpolant of the samples)."""
    th = 2.0 * math.pi * np.arange(table.size) / table.size
    h = np.arange(1, harmonics + 1)[:, None]
    a = 2.0 * np.mean(table[None, :] * np.cos(h * th), axis=1)
    b = 2.0 * np.mean(table[None, :] * np.sin(h * th), axis=1)
    return float(np.mean(table)), a, b


def _series_fn(k0, a, b):
    h = np.arange(1, a.size + 1)

    def k(th: float) -> float:
        return float(k0 + a @ np.cos(h * th) + b @ np.sin(h * th))
    return k


# ---------------------------------------------------------------------------------------------
# the stiffness series


def test_series_coefficients_are_the_tables_fourier_coefficients(tables):
    mesh, healthy, cracked = tables
    for table in (healthy, cracked):
        m = _pair(mesh, table, harmonics=50)
        for flank, var in (("kd", "mesh_stiffness"), ("kc", "mesh_stiffness_coast")):
            k0, a, b = _quadrature_series(table[var].values, 50)
            p = m.coefficient_values()
            got_a = np.array([p[f"{flank}_a{h}"] for h in range(1, 51)])
            got_b = np.array([p[f"{flank}_b{h}"] for h in range(1, 51)])
            assert p[f"{flank}0"] == pytest.approx(k0, rel=1e-13)
            np.testing.assert_allclose(got_a, a, rtol=0, atol=1e-9 * k0)
            np.testing.assert_allclose(got_b, b, rtol=0, atol=1e-9 * k0)
        assert p["k_mean"] == pytest.approx(float(table["mesh_stiffness"].mean()), rel=1e-13)


def test_stated_truncation_error_of_the_default_series(tables):
    """The default H = 16 z1 = 304 harmonics of the pinion speed: the series deviates from the
    table by at most 25 % of the mean stiffness (the Gibbs overshoot at the contact jumps, about
    half a jump) and by 4 % rms; the rms error falls as harmonics are added."""
    mesh, healthy, cracked = tables
    for table in (healthy, cracked):
        m = _pair(mesh, table)
        assert m.n_harmonics == 16 * Z1
        theta = 2.0 * math.pi * np.arange(table.sizes["angle"]) / table.sizes["angle"]
        for flank, var in (("drive", "mesh_stiffness"), ("coast", "mesh_stiffness_coast")):
            e = m.stiffness_at(theta, flank) - table[var].values
            k0 = float(table["mesh_stiffness"].mean())
            rms, peak = float(np.sqrt(np.mean(e * e)) / k0), float(np.max(np.abs(e)) / k0)
            assert rms < 0.04 and peak < 0.25
            err = m.stiffness_error()
            assert err[f"{flank}_rms"] == pytest.approx(rms, rel=1e-9)
            assert err[f"{flank}_max"] == pytest.approx(peak, rel=1e-9)
        rms = [_pair(mesh, table, harmonics=h).stiffness_error()["drive_rms"]
               for h in (2 * Z1, 8 * Z1, 32 * Z1)]
        assert rms[0] > rms[1] > rms[2]


# ---------------------------------------------------------------------------------------------
# the trajectory against independent integrations


def _compare(model, kd, kc, revs: int, every: int = 8, y0: np.ndarray | None = None, *,
             kmean: float) -> tuple[np.ndarray, np.ndarray]:
    """(geardyn's x, DOP853's x) on the geardyn grid (every ``every``-th point) from ``y0``
    (default the static deflection at rest); ``kmean`` is the table's mean drive stiffness."""
    if y0 is None:
        y0 = np.array([TORQUE / RB1 / kmean + HALF_B, 0.0])
    ds = geardyn.simulate(model, run=geardyn.RunSettings(transient=0.0, samples=revs), y0=y0)
    t = ds["time"].values[::every]
    err = model.params[model.param_index("error")]
    ref = solve_ivp(_rhs(kd, kc, model.omega, TORQUE, kmean, err), (0.0, t[-1]), y0,
                    method="DOP853", rtol=1e-10, atol=1e-16, t_eval=t)
    assert ref.status == 0
    assert ds.attrs["status"] == 0
    return ds["x"].values[::every], ref.y[0]


def test_trajectory_matches_dop853_on_the_same_series(tables):
    """The same truncated series summed here (H = 4 z1, so that DOP853 stays quick): the model's
    RK4 at the default step agrees to 1e-6 of the motion, with the transmission error on,
    started in coast-flank contact so that the teeth cross the dead zone onto the drive flanks
    (both flanks and the dead zone used)."""
    mesh, _, cracked = tables
    kmean = float(cracked["mesh_stiffness"].mean())
    H = 4 * Z1
    m = _pair(mesh, cracked, harmonics=H, error="3 um")
    kd = _series_fn(*_quadrature_series(cracked["mesh_stiffness"].values, H))
    kc = _series_fn(*_quadrature_series(cracked["mesh_stiffness_coast"].values, H))
    x, ref = _compare(m, kd, kc, revs=1, kmean=kmean, y0=np.array([-3.0 * HALF_B, 0.0]))
    assert (ref < -HALF_B).any() and (ref > HALF_B).any()  # both flanks in contact
    assert np.max(np.abs(x - ref)) < 1e-6 * np.ptp(ref)  # measured 2.6e-7


@pytest.mark.parametrize("which", ["healthy", "cracked"])
def test_trajectory_matches_dop853_on_the_interpolated_table(tables, which):
    """The tabulated stiffness (linear between the 256 angles per mesh cycle, jumps and all)
    against the model with H = 32 z1 = 608 harmonics: within 3 % of the peak-to-peak motion
    over a pinion revolution. The deviation is the series' rounding of the contact jumps,
    which excite the contact mode: H Omega = 2.4 omega_n here (measured 0.8 %, healthy); at the
    default H = 16 z1 4.9 %, at 12 z1 (H Omega = 0.9 omega_n) 14 %, at 2 z1 41 % (docs/gears.md)."""
    mesh, healthy, cracked = tables
    table = healthy if which == "healthy" else cracked
    kmean = float(table["mesh_stiffness"].mean())
    m = _pair(mesh, table, harmonics=32 * Z1)
    x, ref = _compare(m, _interp(table["mesh_stiffness"].values),
                      _interp(table["mesh_stiffness_coast"].values), revs=1, kmean=kmean)
    assert np.max(np.abs(x - ref)) < 0.03 * np.ptp(ref)


# ---------------------------------------------------------------------------------------------
# the spectrum: mesh harmonics, and sidebands at the pinion speed from the crack


def _spectrum(model):
    ds = geardyn.simulate(model, run=geardyn.RunSettings(transient=3.0 * 2 * math.pi
                                                         / model.omega, samples=4))
    spec = geardyn.amplitude_spectrum(ds, "x", window="boxcar")
    return spec.sel(frequency=np.arange(0, 4 * Z1 + 1), method="nearest")


def test_healthy_spectrum_has_mesh_harmonics_only_and_the_crack_adds_sidebands(tables):
    """Frequencies in pinion orders (multiples of Omega, the pinion speed): the healthy pair's
    lines sit at the mesh harmonics 19, 38, 57 only (every other order below 1e-10 of the mesh
    line, measured ~1e-14: rounding); the cracked pinion's (1.5 mm root crack) has sidebands at
    19 k +- j (k = 1, 2; j = 1, 2, 3) above 5e-4 of the mesh line (measured 6e-4 to 2e-2) and
    the pinion order itself."""
    mesh, healthy, cracked = tables
    spec_h = _spectrum(_pair(mesh, healthy)).values
    spec_c = _spectrum(_pair(mesh, cracked)).values
    mesh_line = spec_h[Z1]
    orders = np.arange(1, 3 * Z1 + 4)
    off = np.array([o for o in orders if o % Z1])
    assert np.max(spec_h[off]) < 1e-10 * mesh_line
    assert min(spec_h[Z1], spec_h[2 * Z1]) > 1e-3 * mesh_line
    for k in (1, 2):
        for j in (1, 2, 3):
            assert spec_c[k * Z1 + j] > 5e-4 * mesh_line
            assert spec_c[k * Z1 - j] > 5e-4 * mesh_line
    assert spec_c[1] > 0.01 * mesh_line  # the pinion order itself


# ---------------------------------------------------------------------------------------------
# RK4's order, units, errors, analyses


def test_rk4_error_falls_16_fold_when_the_step_halves(tables):
    """In drive-flank contact (no dead-zone crossing): the state after a quarter revolution at
    n, 2n steps per revolution against 16 n (n = 16384, about 0.6 of the default step); the
    error ratio is 16 within 20 % (measured 15.7 in x, 17.4 in v)."""
    mesh, _, cracked = tables
    m = _pair(mesh, cracked, harmonics=2 * Z1)
    y0 = m.initial_state()
    n0 = 16384

    def end(n):
        ds = geardyn.simulate(m, run=geardyn.RunSettings(transient=0.0, samples=1,
                                                         steps_per_period=n), y0=y0)
        assert int(ds["edge_crossings"].sum()) == 0
        return np.array([ds["x"].values[n // 4], ds["v"].values[n // 4]])

    fine = end(16 * n0)
    e1 = np.abs(end(n0) - fine)
    e2 = np.abs(end(2 * n0) - fine)
    ratio = e1 / e2
    assert np.all((ratio > 12.8) & (ratio < 19.2)), ratio


def test_units_are_taken_and_labelled(tables):
    mesh, healthy, _ = tables
    a = _pair(mesh, healthy, harmonics=Z1)
    b = geardyn.SpurPair(mesh, healthy, speed=RPM * 2 * math.pi / 60, torque=TORQUE,
                         inertia=("4.3659e-4 kg m^2", "8.3602e-3 kg*m**2"), zeta=ZETA,
                         backlash="10 um", harmonics=Z1)
    np.testing.assert_allclose(a.params, b.params, rtol=1e-14, atol=0)
    assert a.omega == pytest.approx(RPM * 2 * math.pi / 60, rel=1e-15)
    assert a.params[a.param_index("mass")] == pytest.approx(MASS, rel=1e-13)
    assert a.mean_force() == pytest.approx(TORQUE / RB1, rel=1e-13)
    c = a.with_params(speed="3000 rpm", torque="0.1 kN m")
    assert c.omega == pytest.approx(3000 * 2 * math.pi / 60, rel=1e-13)
    assert c.mean_force() == pytest.approx(100.0 / RB1, rel=1e-13)
    ds = geardyn.simulate(a, run=geardyn.RunSettings(transient=0.0, samples=1))
    assert ds["time"].attrs["units"] == "s"
    assert (ds["x"].attrs["units"], ds["v"].attrs["units"]) == ("m", "m/s")
    assert ds["F"].attrs["units"] == "N"
    assert ds.attrs["time_unit"] == "s"
    assert float(ds["F"].mean()) == pytest.approx(TORQUE / RB1, rel=0.05)


@pytest.mark.parametrize(("kw", "field"), [
    ({"speed": "1000 1/s"}, "speed"),
    ({"speed": "-5 rpm"}, "speed"),
    ({"torque": "5 m"}, "torque"),
    ({"inertia": (1.0,)}, "inertia"),
    ({"inertia": (1.0, "-1 kg m^2")}, "inertia[1]"),
    ({"backlash": "2 N"}, "backlash"),
    ({"backlash": "-1 um"}, "backlash"),
    ({"zeta": -0.1}, "zeta"),
    ({"harmonics": 0}, "harmonics"),
    ({"harmonics": 10 * ANGLES * Z1}, "harmonics"),
])
def test_bad_input_names_the_field(tables, kw, field):
    mesh, healthy, _ = tables
    with pytest.raises(ParameterError) as err:
        _pair(mesh, healthy, **kw)
    assert err.value.field == field


def test_derived_coefficients_are_refused_by_name(tables):
    mesh, healthy, _ = tables
    m = _pair(mesh, healthy, harmonics=Z1)
    with pytest.raises(ParameterError, match="mesh_stiffness") as err:
        m.with_params(kd_a3=1.0)
    assert err.value.field == "kd_a3"
    with pytest.raises(ParameterError) as err:
        m.with_params(torque="3 kg")
    assert err.value.field == "torque"


def test_a_crack_needs_whole_revolutions_of_its_gear():
    mesh = _mesh()
    one = potential_energy_stiffness(mesh, bore_radius=BORES, angles=64, cycles=5,
                                     faults=RootCrack("1 mm"))
    with pytest.raises(ParameterError, match="stiffness"):
        _pair(mesh, one, harmonics=10)
    with pytest.raises(ParameterError, match="period"):
        geardyn.SpurPair.from_geometry(mesh, bore_radius=BORES, speed="1000 rpm", torque=50,
                                       faults=RootCrack("1 mm"), period="mesh")
    both = (RootCrack("1 mm"), RootCrack("1 mm", gear="wheel"))
    with pytest.raises(ParameterError, match="both gears") as err:
        geardyn.SpurPair.from_geometry(mesh, bore_radius=BORES, speed="1000 rpm", torque=50,
                                       faults=both)
    assert err.value.field == "faults"
    hunting = potential_energy_stiffness(mesh, bore_radius=BORES, angles=8,
                                         cycles=math.lcm(mesh.pinion.teeth, mesh.wheel.teeth),
                                         faults=both)
    with pytest.raises(ParameterError, match="both gears") as err:
        _pair(mesh, hunting, harmonics=10)
    assert err.value.field == "stiffness"


def test_bifurcation_over_speed_runs(tables):
    """A short sweep over the pinion speed (the fused sweep path): every lane ends ok, the axis
    in rad/s, the mesh frequency [Hz] and speed [rpm] given."""
    mesh, _, cracked = tables
    m = _pair(mesh, cracked, harmonics=2 * Z1)
    speeds = np.array([800.0, 1000.0, 1200.0]) * 2 * math.pi / 60
    ds = geardyn.bifurcation(m, "speed", speeds,
                             run=geardyn.RunSettings(transient=0.1, samples=2))
    assert np.all(ds["status"].values == 0)
    assert ds["speed"].attrs["units"] == "rad/s"
    assert np.all(np.isfinite(ds["poincare"].values))


# ---------------------------------------------------------------------------------------------
# a missing tooth: the stiffness falls to 0 where no pair is in contact


@pytest.fixture(scope="module")
def missing():
    """The 19/48 pair with pinion tooth 0 missing, over a pinion revolution."""
    from geardyn.gears import BrokenTooth

    mesh = _mesh()
    table = potential_energy_stiffness(mesh, bore_radius=BORES, angles=ANGLES, cycles=Z1,
                                       faults=BrokenTooth("pinion", 0))
    return mesh, table


def test_a_missing_tooth_runs_on_the_series_clipped_at_zero(missing):
    """The table is 0 where the missing tooth would have carried alone; the series rings below
    0 about that gap, and the model runs on max(series, 0): its stiffness_at is the series
    summed here with numpy and clipped, and its trajectory agrees with DOP853 (rtol 1e-10) on
    that clipped series over a revolution with the gap crossed (the gears run free over it and
    the motion grows 30-fold). The clip is a kink in time that RK4 does not locate: at the
    default step the error is 1.2e-6 of the motion (tested: < 3e-6), and halving the step
    lowers it (measured 2.2x; 4x: 30x)."""
    mesh, table = missing
    k_table = table["mesh_stiffness"].values
    assert k_table.min() == 0.0 and k_table.max() > 0.0
    kmean = float(k_table.mean())
    H = 4 * Z1
    m = _pair(mesh, table, harmonics=H)
    raw_d = _series_fn(*_quadrature_series(k_table, H))
    raw_c = _series_fn(*_quadrature_series(table["mesh_stiffness_coast"].values, H))
    theta = 2.0 * math.pi * np.arange(k_table.size) / k_table.size
    raw = np.array([raw_d(t) for t in theta])
    assert raw.min() < 0.0  # the ringing the kernels clip
    np.testing.assert_allclose(m.stiffness_at(theta), np.maximum(raw, 0.0), rtol=0,
                               atol=1e-9 * kmean)

    def clipped(fn):
        return lambda th: max(fn(th), 0.0)

    x, ref = _compare(m, clipped(raw_d), clipped(raw_c), revs=1, kmean=kmean, every=1)
    err = np.max(np.abs(x - ref))
    assert err < 3e-6 * np.ptp(ref)
    n = default_steps_per_period(m)
    x2 = geardyn.simulate(m, run=geardyn.RunSettings(transient=0.0, samples=1,
                                                     steps_per_period=2 * n),
                          y0=np.array([TORQUE / RB1 / kmean + HALF_B, 0.0]))["x"].values
    assert np.max(np.abs(x2[::2] - ref)) < err / 1.5


def test_a_missing_tooth_sets_the_gears_free_where_its_pair_would_carry(missing):
    """Over the gap the mesh force is 0 (no stiffness): the force observable is the damping
    term alone there, and the mean stiffness over the revolution is 1/z below the healthy one
    (the table's own figure, docs/gears.md)."""
    mesh, table = missing
    healthy = potential_energy_stiffness(mesh, bore_radius=BORES, angles=ANGLES, cycles=Z1)
    m = _pair(mesh, table)
    ratio = m.coefficient_values()["k_mean"] / float(healthy["mesh_stiffness"].mean())
    assert ratio == pytest.approx(1.0 - 1.0 / Z1, rel=1e-6)
    theta = 2.0 * math.pi * np.arange(table.sizes["angle"]) / table.sizes["angle"]
    gap = table["mesh_stiffness"].values == 0.0
    kmean = float(table["mesh_stiffness"].mean())
    assert np.all(m.stiffness_at(theta[gap]) < 0.25 * kmean)  # the series' rounding only


# ---------------------------------------------------------------------------------------------
# the table form: the table itself in the kernels, linear between its angles


def test_table_form_is_the_table_linear_between_its_angles(tables):
    mesh, _, cracked = tables
    m = _pair(mesh, cracked, stiffness_form="table")
    n = cracked.sizes["angle"]
    theta = 2.0 * math.pi * (np.arange(n) + 0.3) / n
    for flank, var in (("drive", "mesh_stiffness"), ("coast", "mesh_stiffness_coast")):
        k = cracked[var].values
        expected = 0.7 * k + 0.3 * np.roll(k, -1)
        np.testing.assert_allclose(m.stiffness_at(theta, flank), expected, rtol=1e-12)
    assert max(m.stiffness_error().values()) < 1e-12  # the table at its angles (rounding)
    assert m.dataset_attrs()["stiffness_form"] == "table"


@pytest.mark.parametrize("which", ["healthy", "cracked"])
def test_table_form_matches_dop853_on_the_same_table(tables, which):
    """The table form at the step rule against DOP853 on the table linear between its angles,
    over a pinion revolution started in coast contact (both flanks and the dead zone): within
    1e-4 of the peak-to-peak motion (measured 2.1e-5)."""
    mesh, healthy, cracked = tables
    table = healthy if which == "healthy" else cracked
    kmean = float(table["mesh_stiffness"].mean())
    m = _pair(mesh, table, stiffness_form="table")
    x, ref = _compare(m, _interp(table["mesh_stiffness"].values),
                      _interp(table["mesh_stiffness_coast"].values), revs=1, kmean=kmean,
                      y0=np.array([-3.0 * HALF_B, 0.0]))
    assert (ref < -HALF_B).any() and (ref > HALF_B).any()
    assert np.max(np.abs(x - ref)) < 1e-4 * np.ptp(ref)


def test_fourier_form_converges_to_the_table_form_as_harmonics_grow(tables):
    """The series of H = 4, 16, 64 z1 harmonics against the table form over a revolution: the
    largest difference falls with H, and at 64 z1 is under 1 % of the motion (measured 34 %,
    5.3 %, 0.38 %; the series converges to the table's trigonometric interpolant, which the
    linear one approaches between the jumps)."""
    mesh, _, cracked = tables
    table_form = _pair(mesh, cracked, stiffness_form="table")
    y0 = table_form.initial_state()
    run = geardyn.RunSettings(transient=0.0, samples=1)
    ref = geardyn.simulate(table_form, run=run, y0=y0)
    gaps = []
    for h in (4, 16, 64):
        ds = geardyn.simulate(_pair(mesh, cracked, harmonics=h * Z1), run=run, y0=y0)
        x = np.interp(ref["time"].values, ds["time"].values, ds["x"].values)
        gaps.append(np.max(np.abs(x - ref["x"].values)) / np.ptp(ref["x"].values))
    assert gaps[0] > gaps[1] > gaps[2] and gaps[2] < 0.01, gaps


def test_table_form_error_falls_at_least_second_order_with_the_step(tables):
    """The table form against DOP853 on the same table over a quarter revolution in drive
    contact, at n = 8192 .. 65536 steps per revolution (the rule's 27583 in between), compared
    at the coarsest grid's points: each halving of the step divides the largest error by more
    than 3 (second order, RK4's fourth lost at the table's kinks: measured 3.9, 4.6, 5.8),
    and at 32768 steps it is under 2e-4 of the motion (measured 9e-5)."""
    mesh, _, cracked = tables
    kmean = float(cracked["mesh_stiffness"].mean())
    m = _pair(mesh, cracked, stiffness_form="table")
    y0 = m.initial_state()
    n0 = 4096
    t = np.arange(n0 // 4 + 1) * (2.0 * math.pi / m.omega) / n0
    ref = solve_ivp(_rhs(_interp(cracked["mesh_stiffness"].values),
                         _interp(cracked["mesh_stiffness_coast"].values), m.omega, TORQUE, kmean),
                    (0.0, t[-1]), y0, method="DOP853", rtol=1e-10, atol=1e-16, t_eval=t).y[0]
    errors = []
    for k in (2, 4, 8, 16):
        ds = geardyn.simulate(m, run=geardyn.RunSettings(
            transient=0.0, samples=1, steps_per_period=n0 * k), y0=y0)
        assert int(ds["edge_crossings"].sum()) == 0
        x = ds["x"].values[: n0 * k // 4 + 1: k]
        errors.append(np.max(np.abs(x - ref)) / np.ptp(ref))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all(ratios > 3.0), ratios
    assert errors[2] < 2e-4


def test_table_form_refuses_harmonics_and_unknown_forms(tables):
    mesh, healthy, _ = tables
    with pytest.raises(ParameterError, match="harmonics"):
        _pair(mesh, healthy, stiffness_form="table", harmonics=40)
    with pytest.raises(ParameterError, match="stiffness_form"):
        _pair(mesh, healthy, stiffness_form="spline")
