"""Archard wear on a gear of a train that meets several meshes (geardyn.trains.faults.
shared_wear_profiles, geardyn.gears.potential_energy.combined_wear_profile).

The convention checked: over one revolution of the gear each of its meshes wears the flank it
loads under the mean torques (positive static mesh force: the drive flank), by Archard's rate of
that mesh (load share x slip) times its load per unit face width; the depth along the flank is
their sum, scaled to the fault's ``depth`` at its largest.

Checks: an idler's two meshes load opposite flanks (its static forces worked out here from the
torques), so its drive-flank wear is that of its input mesh alone and its coast-flank wear that
of its output mesh alone: the loading mesh's table equals potential_energy_stiffness of that
pair with the same wear, and the other mesh's contacts on the worn flank open the loading
mesh's wear depth at their flank point (0 below its path of contact); a pinion driving two
wheels at loads set here by the torques takes the load-weighted sum of the two meshes' Archard
rates (computed here mesh by mesh from the pairs, on a grid of their own), in the gap of every
contact of the worn tooth in both meshes; a flank that no mesh loads (no torques, or an idler
on an unloaded branch whose forces are round-off) is refused naming ``wear.flank``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import geardyn.gears as g
from geardyn.errors import ParameterError
from geardyn.gears import GearMesh, SpurGear, potential_energy_stiffness
from geardyn.gears.potential_energy import prepare_pair
from geardyn.trains import Bearing, Gear, GearTrain, Mesh, TrainModel
from test_trains_faults import _idler

DEPTH = 20e-6
BORE = 8e-3


def _gears(*teeth: int) -> list[SpurGear]:
    return [SpurGear(z, 3e-3, math.radians(20.0), 0.02) for z in teeth]


def _roll_and_gap(table, pair, role: str, tooth: int, coast: bool):
    """(roll angles [rad] of ``role``'s flank, gaps [m]) at the contacts of its ``tooth`` on
    the drive (``coast``: coast) flank of ``table``."""
    suffix = "_coast" if coast else ""
    inside = table[f"in_contact{suffix}"].values
    mine = inside & (table[f"tooth_{role}{suffix}"].values == tooth)
    position = table[f"position{suffix}"].values[mine]
    return pair._flank(role)[1](position), table[f"fault_gap{suffix}"].values[mine]


@pytest.mark.parametrize("flank", ["drive", "coast"])
def test_idler_flank_takes_the_wear_of_the_mesh_that_loads_it(flank):
    """g1 drives the idler g2, which drives g3: F_m1 = T_1 / r_b1 > 0 and F_m2 = -F_m1 (the
    idler's torque balance), so Archard wear on the idler's drive flank follows m1's sliding
    (g2 the wheel of m1), on its coast flank m2's (g2 the pinion of m2)."""
    g1, g2, g3 = _gears(19, 31, 23)
    torque = 20.0
    wear = g.Wear(depth=DEPTH, gear="g2", tooth=5, profile="archard", flank=flank)
    model = _idler((wear,))
    loads = model.static_loads()
    f1 = torque / g1.base_radius
    assert loads["m1"] == pytest.approx(f1, rel=1e-9)
    assert loads["m2"] == pytest.approx(-f1, rel=1e-9)
    offsets = model._fault_offsets()
    # g2, gear a of m2, turns in the negative sense: m2's table is read backwards in time, the
    # tooth passing its pitch point at c = j the table's tooth -j
    assert model.backward_meshes() == ("m2",)
    on = {"m1": ("wheel", GearMesh(g1, g2), BORE, 5),
          "m2": ("pinion", GearMesh(g2, g3), BORE, -(5 + offsets["m2"]) % 31)}
    assert_wear_follows_the_loading_mesh(model, on, flank, DEPTH, 31)


def assert_wear_follows_the_loading_mesh(model: TrainModel, on, flank: str, depth: float,
                                         cycles: int) -> None:
    """Archard wear of ``depth`` [m] on ``flank`` of a gear of two meshes, ``on``: {mesh:
    (the gear's role in the mesh's pair, the pair, its bore radii, the worn tooth's number in
    the mesh's table)}, the first mesh loading the drive flank, the second the coast flank.
    The loading mesh's table over ``cycles`` mesh cycles equals potential_energy_stiffness of
    its pair with the same wear (to 1e-8 of its largest value; its deepest gap within 0.9 to 1
    of ``depth``), and the other mesh's contacts on the worn flank open the loading mesh's
    depth at their flank point (rtol 1e-8; 0 below the loading mesh's lowest contact on the
    flank)."""
    first, second = on
    loading, other = (first, second) if flank == "drive" else (second, first)
    role, pair, bores, tooth = on[loading]
    own = g.Wear(depth=depth, gear=role, tooth=tooth, profile="archard", flank=flank)
    ref = potential_energy_stiffness(pair, bore_radius=bores, faults=(own,), cycles=cycles)
    tables = model.fault_tables()
    for var in ("mesh_stiffness", "mesh_stiffness_coast", "fault_gap", "fault_gap_coast"):
        got, want = tables[loading][var].values, ref[var].values
        np.testing.assert_allclose(got, want, rtol=0.0, atol=1e-8 * np.max(np.abs(want)))
    deepest = np.max(ref["fault_gap_coast" if flank == "coast" else "fault_gap"].values)
    assert 0.9 * depth < deepest <= depth * (1.0 + 1e-9)
    # the other mesh's contacts on the worn flank: the loading mesh's depth at their flank point
    # (0 below the loading mesh's lowest contact on the flank)
    depth_at = prepare_pair(pair, bore_radius=bores, faults=(own,)).wear_profiles[0][1].depth_at
    s_p = pair.pinion.base_radius * math.tan(pair.operating_pressure_angle)
    if role == "pinion":
        lowest = (s_p - pair.approach_length) / pair.pinion.base_radius
    else:
        lowest = (pair.line_of_action_length - s_p - pair.recess_length) / pair.wheel.base_radius
    o_role, o_pair, o_bores, o_tooth = on[other]
    t, gap = _roll_and_gap(tables[other], prepare_pair(o_pair, bore_radius=o_bores), o_role,
                           o_tooth, coast=flank == "coast")
    worn = t > lowest
    assert worn.sum() > 20
    np.testing.assert_allclose(gap[worn], depth_at(t[worn]), rtol=1e-8, atol=1e-12 * depth)
    assert np.all(gap[~worn] == 0.0)


def _splitter(torques: dict[str, float] | None) -> TrainModel:
    """Pinion g1 (19) drives g2 (31) and, on its other side, g3 (47)."""
    gears = _gears(19, 31, 47)
    bodies = [Gear(f"g{i + 1}", 0.01 * (i + 1), geometry=gears[i]) for i in range(3)]
    train = GearTrain(bodies, bearings=[Bearing(f"b{i + 1}", f"g{i + 1}", math.inf)
                                        for i in range(3)],
                      meshes=[Mesh("m2", "g1", "g2", "potential_energy", bore_radius=BORE),
                              Mesh("m3", "g1", "g3", "potential_energy", bore_radius=BORE,
                                   angle=math.pi)],
                      driven="g1", free=True,
                      faults=g.Wear(depth=DEPTH, gear="g1", tooth=4, profile="archard"))
    return TrainModel(train, torques=torques, load=None if torques is None else "g3",
                      harmonics=6, mesh_phase="geometry")


def test_pinion_of_two_meshes_takes_the_load_weighted_sum_of_their_archard_rates():
    """g1 carries 20 N m, g2 takes 12 N m: F_2 = 12 / r_b2, F_3 = 20 / r_b1 - F_2, both on
    g1's drive flank. The depth at roll angle t of g1's flank is DEPTH R(t) / max R, R = F_2
    r_2(t) + F_3 r_3(t) (r_m each pair's Archard rate, 0 off its path of contact; equal face
    widths), max R over a grid of its own: every contact of the worn tooth in
    either mesh opens that gap, to 1e-7 of DEPTH (the maxima at one-sided limits)."""
    g1, g2, g3 = _gears(19, 31, 47)
    model = _splitter({"g1": 20.0, "g2": 12.0})
    f2 = 12.0 / g2.base_radius
    f3 = 20.0 / g1.base_radius - f2
    loads = model.static_loads()
    assert loads["m2"] == pytest.approx(f2, rel=1e-9)
    assert loads["m3"] == pytest.approx(f3, rel=1e-9)
    pairs = {"m2": prepare_pair(GearMesh(g1, g2), bore_radius=BORE),
             "m3": prepare_pair(GearMesh(g1, g3), bore_radius=BORE)}
    s_p = {m: p.mesh.pinion.base_radius * math.tan(p.mesh.operating_pressure_angle)
           for m, p in pairs.items()}
    r_b = g1.base_radius

    def path(m):  # g1's roll angles at the ends of mesh m's path of contact
        mesh = pairs[m].mesh
        return ((s_p[m] - mesh.approach_length) / r_b, (s_p[m] + mesh.recess_length) / r_b)

    def rate(t):
        out = np.zeros_like(t)
        for m, f in (("m2", f2), ("m3", f3)):
            lo, hi = path(m)
            on = (t > lo) & (t < hi)
            out[on] += f * pairs[m].archard_rate("pinion", r_b * t[on] - s_p[m])
        return out

    # R is smooth between the path ends, the single-contact ends and the pitch point of each
    # mesh (positions -g_f, g_a - p_b, 0, p_b - g_f, g_a): its largest value over 400 points
    # of each stretch between them, the ends nudged in
    breaks = []
    for m, p in pairs.items():
        mesh = p.mesh
        p_b, g_f, g_a = mesh.base_pitch, mesh.approach_length, mesh.recess_length
        breaks += [(s_p[m] + x) / r_b for x in (-g_f, g_a - p_b, 0.0, p_b - g_f, g_a)]
    breaks = np.unique(breaks)
    grid = np.concatenate([np.linspace(a + 1e-11, b - 1e-11, 400)
                           for a, b in zip(breaks[:-1], breaks[1:], strict=True)])
    top = float(np.max(rate(grid)))
    tables = model.fault_tables()
    offsets = model._fault_offsets()
    for m in ("m2", "m3"):
        t, gap = _roll_and_gap(tables[m], pairs[m], "pinion", (4 + offsets[m]) % 19, False)
        assert t.size > 20
        np.testing.assert_allclose(gap, DEPTH * rate(t) / top, rtol=0.0, atol=1e-7 * DEPTH)
    # both meshes wear it: the sum differs from either mesh's own profile
    for m in pairs:
        own = prepare_pair(pairs[m].mesh, bore_radius=BORE,
                           faults=(g.Wear(DEPTH, tooth=4, profile="archard"),))
        t, gap = _roll_and_gap(tables[m], pairs[m], "pinion", (4 + offsets[m]) % 19, False)
        assert np.max(np.abs(gap - own.wear_profiles[0][1].depth_at(t))) > 1e-3 * DEPTH


def test_archard_wear_on_a_flank_no_mesh_loads_is_refused():
    """No torques: no mesh loads g1's drive flank, and Archard's profile of a gear of several
    meshes follows the meshes that load it."""
    with pytest.raises(ParameterError) as err:
        _splitter(None)
    assert err.value.field == "wear.flank"


def _branch(faults=()) -> TrainModel:
    """Pinion g1 (19) drives the loaded g2 (31) and, on its other side, the idler g3 (23),
    which drives g4 (29), free (no torque, no shaft)."""
    gears = _gears(19, 31, 23, 29)
    bodies = [Gear(f"g{i + 1}", 0.01 * (i + 1), geometry=gears[i]) for i in range(4)]
    train = GearTrain(bodies, bearings=[Bearing(f"b{i + 1}", f"g{i + 1}", math.inf)
                                        for i in range(4)],
                      meshes=[Mesh("m1", "g1", "g2", "potential_energy", bore_radius=BORE),
                              Mesh("m2", "g1", "g3", "potential_energy", bore_radius=BORE,
                                   angle=math.pi),
                              Mesh("m3", "g3", "g4", "potential_energy", bore_radius=BORE,
                                   angle=math.pi)],
                      driven="g1", free=True, faults=faults)
    return TrainModel(train, torques={"g1": 20.0}, load="g2", harmonics=4,
                      mesh_phase="geometry")


@pytest.mark.parametrize("flank", ["drive", "coast"])
def test_archard_wear_on_an_idler_under_round_off_forces_is_refused(flank):
    """g4 is free, so the idler g3's branch carries nothing (g4's and then g3's torque
    balance): m2's and m3's static forces are round-off, below 1e-12 of m1's T_1 / r_b1, and
    Archard wear on the idler's either flank is refused naming ``wear.flank``."""
    loads = _branch().static_loads()
    f1 = 20.0 / _gears(19)[0].base_radius
    assert loads["m1"] == pytest.approx(f1, rel=1e-9)
    assert max(abs(loads["m2"]), abs(loads["m3"])) < 1e-12 * f1
    with pytest.raises(ParameterError) as err:
        _branch((g.Wear(DEPTH, gear="g3", tooth=5, profile="archard", flank=flank),))
    assert err.value.field == "wear.flank"
    assert "round-off" in str(err.value)


def test_wear_profiles_must_belong_to_archard_wear_of_the_faults():
    """potential_energy_stiffness's wear_profiles: keys that are not Archard wear among the
    faults are refused naming ``wear_profiles``."""
    g1, g2 = _gears(19, 31)
    wear = g.Wear(DEPTH, tooth=2, profile="archard")
    profile = prepare_pair(GearMesh(g1, g2), bore_radius=BORE,
                           faults=(wear,)).wear_profiles[0][1]
    for key in (g.Wear(DEPTH, tooth=3, profile="archard"), g.Wear(DEPTH, tooth=2)):
        with pytest.raises(ParameterError) as err:
            potential_energy_stiffness(GearMesh(g1, g2), bore_radius=BORE, faults=(wear,),
                                       wear_profiles={key: profile})
        assert err.value.field == "wear_profiles"
