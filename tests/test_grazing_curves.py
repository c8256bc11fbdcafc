"""Contact-change (grazing) curves and the envelope, against independent results: the closed
form of the linear gear pair's contact loss, a brute-force 2-D map of the same plane, a crossing
known in closed form; and the errors of bad input."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import geardyn
from geardyn.analysis.envelope import envelope, intersect_curves
from geardyn.analysis.grazing import grazing_curve
from geardyn.core.results import finish

ZETA, FM = 0.05, 0.1


def _closed_form_fa(omega, zeta=ZETA, fm=FM):
    """F_a on the contact-loss curve of the linear gear pair (see the test below)."""
    omega = np.asarray(omega, dtype=float)
    return fm * np.abs(1.0 - omega**2 + 2j * zeta * omega) / omega**2


@pytest.fixture(scope="module")
def pair():
    return geardyn.GearPair(zeta=ZETA, kappa=0.0, Fm=FM, Fa=0.05, Omega=0.8)


@pytest.fixture(scope="module")
def drive_curve(pair):
    return grazing_curve(pair, "Omega", "Fa", (0.5, 2.0), (0.0, 0.5))


def test_contact_loss_curve_of_the_linear_pair_is_its_closed_form(drive_curve):
    """In contact (x > b) the gear pair with constant stiffness (kappa = 0) is linear:

        x'' + 2 zeta x' + (x - b) = Fm + Fa Omega^2 cos(Omega tau).

    With u = x - b its steady response is u = Fm + A cos(Omega tau - phi), the mean Fm (static
    deflection, unit stiffness) plus the forced amplitude A = Fa Omega^2 / |1 - Omega^2 +
    2 i zeta Omega| (the transfer function of u'' + 2 zeta u' + u at Omega). The orbit keeps
    contact while min u = Fm - A > 0; it grazes the drive edge (min (x - b) = 0) where A = Fm:

        Fa = Fm |1 - Omega^2 + 2 i zeta Omega| / Omega^2,

    and contact is kept below this curve (smaller Fa). The curve is followed by Newton shooting
    on the located-edge RK4 map, nothing of the closed form is used."""
    ds = drive_curve
    geardyn.testing.assert_result(ds, "curve")
    assert ds.attrs["status"] == int(geardyn.BranchStatus.COMPLETED), ds.attrs["message"]
    om, fa = ds["Omega"].values, ds["Fa"].values
    assert om.min() < 0.52 and om.max() > 1.98  # the whole box, across the resonance
    np.testing.assert_allclose(fa, _closed_form_fa(om), rtol=2e-5)
    # contact is kept on the side of smaller Fa: the normal's y component is negative
    assert np.all(ds["kept_y"].values < 0)
    assert np.max(np.abs(ds["grazing_value"].values)) < 1e-6
    assert ds.attrs["flank"] == "drive" and ds.attrs["separates"] == "none / single"


def test_contact_loss_curve_in_the_mean_load_plane(pair):
    """The same closed form solved for Fm: Fm = Fa Omega^2 / |1 - Omega^2 + 2 i zeta Omega|,
    contact kept above it (larger mean load)."""
    m = pair.with_params(Fm=0.06, Fa=0.05, Omega=1.6)
    ds = grazing_curve(m, "Omega", "Fm", (1.2, 2.5), (0.01, 0.3))
    om, fm = ds["Omega"].values, ds["Fm"].values
    assert ds.sizes["point"] > 5
    np.testing.assert_allclose(fm, 0.05 * om**2 / np.abs(1 - om**2 + 2j * ZETA * om), rtol=2e-5)
    assert np.all(ds["kept_y"].values > 0)


def test_a_continuation_contact_point_starts_the_curve(pair):
    br = geardyn.continuation(pair.with_params(Fa=0.05), "Omega", 0.6, 1.0)
    kinds = list(br["bifurcation_kind"].values)
    assert "contact" in kinds
    ds = grazing_curve(pair.with_params(Fa=0.05), "Omega", "Fa", (0.5, 2.0), (0.0, 0.5),
                       branch=br, bifurcation=kinds.index("contact"),
                       settings=geardyn.analysis.grazing.GRAZING_SETTINGS)
    np.testing.assert_allclose(ds["Fa"].values, _closed_form_fa(ds["Omega"].values), rtol=2e-5)
    at = float(br["bifurcation_value"].values[kinds.index("contact")])
    assert np.min(np.abs(ds["Omega"].values - at) + np.abs(ds["Fa"].values - 0.05)) < 1e-3


def _line_curve(omega: float, fa: np.ndarray) -> xr.Dataset:
    """A hand-made fold curve: the vertical line Omega = omega."""
    n = fa.size
    ds = xr.Dataset(coords={"point": np.arange(n), "Omega": ("point", np.full(n, omega)),
                            "Fa": ("point", fa), "state": ["x", "v"], "multiplier": [0, 1],
                            "special": np.arange(0)})
    ds["section_point"] = (("point", "state"), np.zeros((n, 2)))
    ds["multiplier_real"] = (("point", "multiplier"), np.ones((n, 2)))
    ds["multiplier_imag"] = (("point", "multiplier"), np.zeros((n, 2)))
    ds["period_time"] = ("point", np.full(n, 2 * np.pi / omega), {"units": "1"})
    ds["special_kind"] = ("special", np.zeros(0, dtype=str), {"meaning": "-"})
    for name in ("special_x", "special_y", "special_error"):
        ds[name] = ("special", np.zeros(0))
    ds.attrs.update(curve_kind="fold", x="Omega", y="Fa", period=1, status=0, message="",
                    status_meaning="0 completed", time_unit="1")
    return finish(ds, "curve")


@pytest.mark.parametrize("omega", [0.9, 1.5])
def test_intersect_locates_a_known_crossing(drive_curve, omega):
    line = _line_curve(omega, np.linspace(0.0, 0.5, 7))
    out = intersect_curves(drive_curve, line)
    geardyn.testing.assert_result(out, "curve")
    assert list(out["special_kind"].values) == ["grazing-fold"]
    x, y, err = (float(out[k].values[0]) for k in ("special_x", "special_y", "special_error"))
    assert x == pytest.approx(omega, abs=1e-12)
    exact = float(_closed_form_fa(omega))
    # the error bound holds and is small (scaled plane: Fa over its span 0.5)
    assert abs(y - exact) / drive_curve.attrs["y_scale"] <= err + 2e-5
    assert err < 5e-3


def test_no_crossing_gives_no_special_point(drive_curve):
    out = intersect_curves(drive_curve, _line_curve(3.0, np.linspace(0.0, 0.5, 4)))
    assert out.sizes["special"] == 0


#: The map's pair: damped enough that one start per cell finds the period-1 orbit in most of
#: the box (with zeta = 0.05 period-3 responses with two-sided impacts coexist there).
MAP_ZETA = 0.15


@pytest.fixture(scope="module")
def coarse_map():
    om, fa = np.linspace(1.5, 3.0, 6), np.linspace(0.02, 2.46, 13)
    return geardyn.map2d(geardyn.GearPair(zeta=MAP_ZETA, kappa=0.0, Fm=FM), ("Omega", om),
                         ("Fa", fa), geardyn.RunSettings(transient=600.0, samples=16))


def _crossed_pairs(curve, mp):
    """(cell a, cell b) of neighbouring map cells (along x or y) whose joining segment the
    curve's polyline crosses where its orbit is stable (the attractor a map's start finds),
    a on the curve's kept side."""
    x, y = curve.attrs["x"], curve.attrs["y"]
    mx, my = mp[x].values, mp[y].values
    P = np.column_stack([curve[x].values, curve[y].values])
    mu = np.hypot(curve["multiplier_real"].values, curve["multiplier_imag"].values).max(axis=1)
    out = []
    for j in range(my.size):
        for i in range(mx.size):
            for dj, di in ((0, 1), (1, 0)):
                if j + dj >= my.size or i + di >= mx.size:
                    continue
                a = np.array([mx[i], my[j]])
                b = np.array([mx[i + di], my[j + dj]])
                for k in range(len(P) - 1):
                    r, s = b - a, P[k + 1] - P[k]
                    den = r[0] * s[1] - r[1] * s[0]
                    if den == 0:
                        continue
                    d = P[k] - a
                    t = (d[0] * s[1] - d[1] * s[0]) / den
                    u = (d[0] * r[1] - d[1] * r[0]) / den
                    if 0 <= t <= 1 and 0 <= u <= 1 and max(mu[k], mu[k + 1]) < 1.0:
                        n = np.array([curve["kept_x"].values[k] / curve.attrs["x_scale"],
                                      curve["kept_y"].values[k] / curve.attrs["y_scale"]])
                        kept_a = (a - P[k]) @ n > (b - P[k]) @ n
                        out.append(((j, i), (j + dj, i + di)) if kept_a
                                   else ((j + dj, i + di), (j, i)))
                        break
    return out


def test_curves_agree_with_the_brute_force_map(coarse_map):
    """Every pair of neighbouring map cells a grazing curve passes between has the labels the
    curve separates: the drive flank's curve 'none' on its kept side and contact lost on the
    other; the back flank's no back-flank contact on its kept side and 'double' on the other.
    The map shows the attractor its start falls on: only the crossings where the curve's orbit
    is stable and the map found a period-k orbit on both sides (k the curve's) are checked; the
    others are coexisting responses, which one start per cell cannot show."""
    pair = geardyn.GearPair(zeta=MAP_ZETA, kappa=0.0, Fm=FM)
    env = envelope(pair, "Omega", "Fa", (1.5, 3.0), (0.0, 2.5), starts=[2.25], scan=16,
                   resolution=20)
    labels = coarse_map["contact"].isel(mesh=0).transpose("Fa", "Omega").values
    period = coarse_map["period"].transpose("Fa", "Omega").values
    checked = {"drive": 0, "back": 0}
    for curve in env.grazing():
        flank = curve.attrs["flank"]
        for a, b in _crossed_pairs(curve, coarse_map):
            if not (period[a] == period[b] == curve.attrs["period"]):
                continue  # the map's start fell on another attractor (coexisting responses)
            if flank == "drive":
                assert labels[a] == "none" and labels[b] in ("single", "double"), (a, b)
            else:
                assert labels[a] in ("none", "single") and labels[b] == "double", (a, b)
            checked[flank] += 1
    assert checked["drive"] >= 5 and checked["back"] >= 5, checked
    # the regions the curves give agree with the map away from the curves too
    X, Y = np.meshgrid(coarse_map["Omega"].values, coarse_map["Fa"].values)
    codes = env.contact_at(X, Y)
    names = np.array(["none", "single", "double"])[codes]
    same = period == 1
    assert np.mean(names[same] == labels[same]) > 0.9


@pytest.mark.parametrize("kwargs,match", [
    ({"flank": "left"}, "flank"),
    ({"mesh": "sun"}, "mesh"),
    ({"x_range": (2.0, 0.5)}, "x_range"),
    ({"y_range": (0.0,)}, "y_range"),
    ({"at": (3.0, 0.1)}, "outside"),
    ({"at": 3.0}, "at"),
    ({"y": "Omega"}, "different"),
    ({"y": "stiffness"}, "stiffness"),
    ({"branch": xr.Dataset()}, "branch"),
    ({"bifurcation": 0}, "bifurcation"),
])
def test_bad_input_names_the_field(pair, kwargs, match):
    args = {"x": "Omega", "y": "Fa", "x_range": (0.5, 2.0), "y_range": (0.0, 0.5)}
    args.update(kwargs)
    with pytest.raises((ValueError, KeyError), match=match):
        grazing_curve(pair, **args)


@pytest.mark.parametrize("kwargs,match", [
    ({"flanks": ("drive", "top")}, "flank"),
    ({"scan": 1}, "scan"),
    ({"resolution": 1}, "resolution"),
    ({"starts": [5.0]}, "starts"),
    ({"curves": [xr.Dataset()]}, "curves"),
])
def test_bad_envelope_input_names_the_field(pair, kwargs, match):
    with pytest.raises(ValueError, match=match):
        envelope(pair, "Omega", "Fa", (0.5, 2.0), (0.0, 0.5), **kwargs)


@pytest.mark.parametrize("fa_box,code", [((0.0, 0.03), 0), ((0.2, 0.3), 1)])
def test_a_box_no_curve_crosses_takes_the_orbit_s_regime(pair, fa_box, code):
    """No grazing curve in the box (the closed form puts the drive flank's at Fa 0.057 to
    0.076 for Omega in [1.5, 2]): the whole box takes the regime of the orbit at its centre,
    contact kept below the curve, one-sided impacts above it."""
    assert _closed_form_fa(1.5) > 0.03 and _closed_form_fa(2.0) < 0.2
    env = envelope(pair, "Omega", "Fa", (1.5, 2.0), fa_box, flanks=("drive", "back"),
                   scan=6, resolution=8)
    assert env.grazing() == []
    assert np.all(env.contact == code)


def test_a_fold_curve_given_marks_the_coexisting_region(pair):
    """A fold curve's wedge (closed between its ends) is the coexisting region; the envelope
    intersects it with the grazing curves it crosses."""
    wedge_om = np.array([1.6, 1.75, 1.9])
    wedge = _line_curve(1.75, np.array([0.01, 0.45, 0.01]))
    wedge = wedge.assign_coords(Omega=("point", wedge_om))
    env = envelope(pair, "Omega", "Fa", (1.5, 2.0), (0.0, 0.5), flanks=("drive",),
                   starts=[1.55], y_starts=[], scan=12, resolution=41, curves=[wedge])
    row = np.argmin(abs(env.yv - 0.2))
    assert env.coexisting[row, np.argmin(abs(env.xv - 1.75))]
    assert not env.coexisting[row, np.argmin(abs(env.xv - 1.55))]
    (drive,) = env.grazing("drive")
    kinds = list(drive["special_kind"].values)
    assert kinds == ["grazing-fold", "grazing-fold"]
    # both crossings on the closed-form curve
    np.testing.assert_allclose(drive["special_y"].values,
                               _closed_form_fa(drive["special_x"].values), rtol=1e-3)
