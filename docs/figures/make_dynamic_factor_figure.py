"""The figure and the measured figures of docs/dynamic-factor.md: the healthy 19/48 spur pair
(m 3.2 mm, b 16 mm, steel, bores 12 and 35 mm; 10 um backlash half-width, zeta 0.05) swept in
pinion speed at three torques, its dynamic factor beside ISO 6336-1 K_v (method B; f_pb 9 um,
f_falpha 8 um, y_p = y_f = 0.7 um, no tip relief), and the peak dynamic factor near N = 1 at
three damping ratios; then the built-in planetary_example stage (sun 20 N m, input speed
1000-20 000 rpm), its sun-planet and ring-planet meshes beside ISO's K_v of each; then the
built-in two_stage_train (60 and 240 N m on the input pinion, 500-6000 rpm), both stages; then
the NREL 5 MW gearbox at rated torque over 2-25 rpm (f_pb = f_falpha = 15 um, stand-ins).

    python docs/figures/make_dynamic_factor_figure.py   (from the repository root; ~2 min)
"""

from __future__ import annotations

import math

import numpy as np

import geardyn
from geardyn.analysis.dynamic_factor import dynamic_factor_sweep
from geardyn.gears import GearMesh, SpurGear
from geardyn.plotting.dynamic_factor import plot_dynamic_factor

ACCURACY = dict(base_pitch_deviation=9.0, profile_form_deviation=8.0, pitch_running_in=0.7,
                profile_running_in=0.7, tip_relief=0.0)
RUN = geardyn.RunSettings(transient=0.05, samples=32, converge=1e-8)


def pair(zeta: float = 0.05) -> geardyn.SpurPair:
    mesh = GearMesh(SpurGear(19, 3.2e-3, math.radians(20.0), 0.016, name="pinion"),
                    SpurGear(48, 3.2e-3, math.radians(20.0), 0.016, name="wheel"))
    return geardyn.SpurPair.from_geometry(mesh, bore_radius=(0.012, 0.035), speed=3000.0,
                                          torque=80.0, speed_unit="rpm", backlash="10 um",
                                          zeta=zeta, period="mesh", angles=64, harmonics=16)


def main() -> None:
    speeds = np.linspace(2000.0, 44000.0, 85)
    ds = dynamic_factor_sweep(pair(), speeds, [20.0, 80.0, 200.0], RUN, **ACCURACY)
    plot_dynamic_factor(ds, "docs/figures/dynamic-factor.png")
    print(f"model linear resonance {ds.attrs['natural_speeds'][0]:.0f} rpm")
    for j, t1 in enumerate(ds["torque"].values):
        row = ds.isel(torque=j, group=0)
        df, kv = row["dynamic_factor"].values, row["K_v"].values
        lost = row["contact"].values.astype(str) != "none"
        print(f"T1 {t1:5.0f} N m: line load {float(row['line_load']):6.1f} N/mm, "
              f"N_M {float(row['resonance_speed']):6.0f} rpm, N_S "
              f"{float(row['lower_resonance_limit']):.3f}; "
              f"model max {df[np.isfinite(df)].max():.2f} at "
              f"{speeds[np.nanargmax(np.where(np.isfinite(df), df, -1))]:.0f} rpm (finite), "
              f"K_v max {kv.max():.2f}; unbounded {int(np.sum(~np.isfinite(df)))}; contact lost at "
              f"{speeds[lost].min() if lost.any() else float('nan'):.0f}-"
              f"{speeds[lost].max() if lost.any() else float('nan'):.0f} rpm; "
              f"periods {sorted(set(row['period'].values.tolist()))}")
        for rpm in (5000.0, 10000.0, 13500.0, 40000.0):
            i = int(np.argmin(abs(speeds - rpm)))
            print(f"    {speeds[i]:6.0f} rpm: N {float(row['resonance_ratio'][i]):.2f}, "
                  f"model {df[i]:.2f} (period {int(row['period'][i])}), K_v {kv[i]:.2f}")
    near = np.linspace(16000.0, 26000.0, 41)
    for zeta in (0.02, 0.05, 0.10):
        d = dynamic_factor_sweep(pair(zeta), near, [80.0], RUN, **ACCURACY)
        print(f"zeta {zeta:.2f}: model peak {float(d['dynamic_factor'].max()):.2f} "
              f"(unbounded {int(np.sum(~np.isfinite(d['dynamic_factor'].values)))}), "
              f"K_v peak {float(d['K_v'].max()):.2f}")

    planetary()
    train()
    nrel()


def nrel() -> None:
    from geardyn.io import builtin_study

    model = geardyn.build_model(builtin_study("nrel_5mw_gearbox_sweep"))
    speeds = np.linspace(2.0, 25.0, 24)
    low = model.with_params(input_speed=2.0).omega  # the study's transient_periods there
    run = geardyn.RunSettings(transient=200 * 2.0 * math.pi / low, samples=16)
    ds = dynamic_factor_sweep(model, speeds, None, run, base_pitch_deviation=15.0,
                              profile_form_deviation=15.0)
    plot_dynamic_factor(ds, "docs/figures/dynamic-factor-nrel.png")
    for g in ds["group"].values:
        row = ds.sel(group=g).isel(torque=0)
        df, kv = row["dynamic_factor"].values, row["K_v"].values
        rated = {k: float(row[k].interp(speed=12.1)) for k in ("dynamic_factor", "K_v")}
        print(f"{g}: N_M {float(row['resonance_speed']):.1f} rpm, line load "
              f"{float(row['line_load']):.0f} N/mm, c_gamma {float(row['mesh_stiffness']):.2f};"
              f" model max {np.nanmax(df):.3f} at {speeds[np.nanargmax(df)]:.2f} rpm, K_v "
              f"{kv.min():.3f}-{kv.max():.3f}; at 12.1 rpm model {rated['dynamic_factor']:.3f},"
              f" K_v {rated['K_v']:.3f}; contact lost at "
              f"{speeds[row['contact'].values.astype(str) != 'none'].tolist()}")


def train() -> None:
    from geardyn.io import builtin_study

    model = geardyn.build_model(builtin_study("two_stage_train"))
    speeds = np.linspace(500.0, 6000.0, 45)
    low = model.with_params(input_speed=500.0).omega  # the study's transient_periods there
    run = geardyn.RunSettings(transient=300 * 2.0 * math.pi / low, samples=32)
    ds = dynamic_factor_sweep(model, speeds, [60.0, 240.0], run, **ACCURACY)
    plot_dynamic_factor(ds, "docs/figures/dynamic-factor-train.png")
    print("train natural frequencies as input speeds [rpm]:", ds.attrs["natural_speeds"])
    for j, t1 in enumerate(ds["torque"].values):
        for g in ds["group"].values:
            row = ds.sel(group=g).isel(torque=j)
            df, kv = row["dynamic_factor"].values, row["K_v"].values
            lost = row["contact"].values.astype(str) != "none"
            print(f"{t1:g} N m {g}: N_M {float(row['resonance_speed']):.0f} rpm, line load "
                  f"{float(row['line_load']):.1f} N/mm, c_gamma "
                  f"{float(row['mesh_stiffness']):.2f}; model max {np.nanmax(df):.2f} at "
                  f"{speeds[np.nanargmax(df)]:.0f} rpm, K_v {kv.min():.2f}-{kv.max():.2f}; "
                  f"contact lost at {speeds[lost].round().tolist()}")


def planetary() -> None:
    from geardyn.io import builtin_study

    gs = geardyn.build_model(builtin_study("planetary_example"))
    speeds = np.linspace(1000.0, 20000.0, 77)
    run = geardyn.RunSettings(transient=200.0, samples=32, converge=1e-6)
    ds = dynamic_factor_sweep(gs, speeds, None, run, **ACCURACY)
    plot_dynamic_factor(ds, "docs/figures/dynamic-factor-planetary.png")
    nat = gs.natural_frequencies()
    per = gs.mesh_frequency_per_input_speed()
    print("planetary natural frequencies as input speeds [rpm]:",
          [round(float(f) * 60.0 / per) for f in nat if 0 < f * 60.0 / per < 25000.0])
    for g in ds["group"].values:
        row = ds.sel(group=g).isel(torque=0)
        df, kv = row["dynamic_factor"].values, row["K_v"].values
        lost = row["contact"].values.astype(str) != "none"
        print(f"{g}: N_M {float(row['resonance_speed']):.0f} rpm, line load "
              f"{float(row['line_load']):.1f} N/mm, c_gamma {float(row['mesh_stiffness']):.2f}; "
              f"model max {np.nanmax(df):.2f} at {speeds[np.nanargmax(df)]:.0f} rpm, K_v max "
              f"{kv.max():.2f}; contact lost at {speeds[lost].round().tolist()}")


if __name__ == "__main__":
    main()
