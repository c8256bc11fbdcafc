"""
The NREL 5 MW reference gearbox: natural frequencies, Campbell diagram, rotor-speed sweep
=========================================================================================

The reference gearbox of Nejad, Guo, Gao and Moan (Wind Energy 19, 2016) between the rotor and
the generator of the NREL 5 MW turbine: two planetary stages (three planets each, ring held) and
a parallel helical stage, 1:96.35 in all. The built-in study ``nrel_5mw_gearbox`` describes it
from elements (its ``[train]`` table); every number is sourced in the study file, or a stated
stand-in where none is published (docs/trains.md, "The NREL 5 MW reference gearbox").

The linear model at mean ISO 6336-1 mesh stiffness gives the natural frequencies, the share of
each mode's strain energy held by every mesh, shaft and bearing, and the Campbell diagram over
the rotor speed (rated 12.1 rpm). The same from the command line:

.. code-block:: sh

    geardyn modes nrel_5mw_gearbox --speed "0..15 rpm" --campbell campbell.png --plot shares.png
"""

# %%
import matplotlib.pyplot as plt
import numpy as np

import geardyn
from geardyn.io.toml import builtin_study
from geardyn.plotting.campbell import plot_campbell
from geardyn.plotting.modes import plot_energy_shares

train = builtin_study("nrel_5mw_gearbox").gear_train
print(train)
for name, mesh in train.mesh_data.items():
    if name in ("sun1_pa1", "pa1_ring1", "sun2_pb1", "pb1_ring2", "stage3"):
        print(f"{name:10s} ISO 6336-1 mesh stiffness {mesh.stiffness:.4g} N/m"
              f" (base helix angle {np.degrees(mesh.base_helix_angle):.3g} deg)")

# %%
# Natural frequencies, with the mode classes of the planetary stages and the elements that
# hold most of each mode's strain energy. Mode 0 is the drivetrain turning as a whole; mode 1
# is the torsion of the rotor against the generator on the main shaft (published: 2.18 Hz).
modes = train.modes()
elements = modes["element"].values
for k in range(modes.sizes["mode"]):
    share = modes["energy_share"].values[k]
    top = ", ".join(f"{elements[j]} {100 * share[j]:.0f}%" for j in np.argsort(share)[::-1][:2]
                    ) if np.isfinite(share).all() else "rigid-body mode"
    print(f"{k:2d} {modes['frequency'].values[k]:9.4g} Hz  {modes['type'].values[k]:13s} {top}")

fig = plot_energy_shares(modes)

# %%
# The Campbell diagram over the rotor speed: the mesh orders are 56 (stage 1), 367 (stage 2)
# and 2313 (stage 3) times the rotor speed, each with its second harmonic; a circle marks
# each speed where a harmonic meets a natural frequency.
campbell = train.campbell(np.linspace(0.0, 15.0, 301), harmonics=2)
fig_campbell = plot_campbell(campbell)

# %%
# The nonlinear model over the rotor speed (the built-in study ``nrel_5mw_gearbox_sweep``:
# backlash, a 20 % stiffness fluctuation, rated torque, the planets phased from the geometry),
# at 24 rotor speeds with the study's own transient (200 periods of stage 3's mesh at the
# lowest speed): each stage's dynamic factor (peak over static mesh force) and where a mesh
# loses contact. At rated torque none does; the peaks sit where the Campbell diagram above has
# a mesh order cross a mode (stage 3 near 4.1 rpm, stage 2 near 15 rpm). The same from the
# command line:
#
# .. code-block:: sh
#
#     geardyn bifurcation nrel_5mw_gearbox_sweep --param input_speed --range 2:25:24
study = builtin_study("nrel_5mw_gearbox_sweep")
model = geardyn.build_model(study)
speeds = np.linspace(2.0, 25.0, 24)
lowest = model.with_params(input_speed=float(speeds[0])).omega
sweep = geardyn.bifurcation(model, "input_speed", speeds,
                            study.run_settings(sweep=True, omega=lowest))
fig_sweep, ax = plt.subplots(figsize=(7.0, 3.8), layout="constrained")
for mesh in ("stage3", "sun1_pa1", "pa1_ring1", "sun2_pb1", "pb1_ring2"):
    factor = sweep["dynamic_factor"].sel(mesh=mesh).values
    lost = sweep["contact"].sel(mesh=mesh).values.astype(str) != "none"
    line, = ax.plot(speeds, factor, "-o", ms=3, label=mesh)
    ax.plot(speeds[lost], factor[lost], "o", mfc="none", ms=7, color=line.get_color())
ax.axvline(12.1, color="0.6", ls=":", label="rated 12.1 rpm")
ax.set_xlabel("rotor speed [rpm]")
ax.set_ylabel("dynamic factor [-]")
ax.legend(ncols=3, fontsize="small")
lost_any = int((sweep["contact"].values.astype(str) != "none").sum())
print(f"contact lost at {lost_any} of {sweep['contact'].size} (speed, mesh) points")
