"""
A cracked pinion tooth in the vibration spectrum
================================================

:class:`geardyn.SpurPair` is a spur pair in SI units whose mesh stiffness is the
potential-energy stiffness of its own teeth (:func:`geardyn.gears.potential_energy_stiffness`),
drive and coast flank, over one revolution of the pinion. The 19/48 pair of the cracked-tooth
literature (module 3.2 mm, 20 deg, 16 mm face, bores 12 and 35 mm) runs at 1000 rpm under
50 N m, once healthy and once with a 1.5 mm root crack on one pinion tooth. The crack weakens
the mesh once per pinion revolution, while that tooth is in contact: the time signal shows a
dip once per revolution, and the spectrum gains sidebands at the pinion's rotation frequency
f_r around every mesh harmonic k f_m (f_m = 19 f_r), the signature a diagnosis researcher looks
for.

Each flank's stiffness enters as a Fourier series in the pinion angle with H = 16 x 19 = 304
harmonics (every sideband up to the 16th mesh harmonic): the series rounds the jumps where a
tooth pair enters or leaves contact (first figure), the only approximation of the model.
"""

# %%
import math

import numpy as np
from matplotlib.figure import Figure

import geardyn
from geardyn.gears import GearMesh, RootCrack, SpurGear

mesh = GearMesh(SpurGear(19, "3.2 mm", "20 deg", "16 mm", name="pinion"),
                SpurGear(48, "3.2 mm", "20 deg", "16 mm", name="wheel"))
common = dict(bore_radius=("12 mm", "35 mm"), speed="1000 rpm", torque="50 N m",
              inertia=("4.3659e-4 kg m^2", "8.3602e-3 kg m^2"), zeta=0.05, backlash="10 um")
healthy = geardyn.SpurPair.from_geometry(mesh, **common)
cracked = geardyn.SpurPair.from_geometry(mesh, faults=RootCrack("1.5 mm", "45 deg"), **common)
print(healthy, cracked, sep="\n")
print("series against the table (relative to the mean stiffness):", cracked.stiffness_error())

# %%
# The drive-flank mesh stiffness over one pinion revolution: the table (thin) and the series the
# model integrates (thick). The cracked tooth is in contact from about cycle 0 to 1.6.
fig_k = Figure(figsize=(7.5, 3.2), layout="constrained")
ax = fig_k.add_subplot()
for model, name, colour in ((healthy, "healthy", "C0"), (cracked, "cracked tooth", "C3")):
    table = model.stiffness
    cycles = table["cycle"].values
    ax.plot(cycles, table["mesh_stiffness"].values / 1e6, color=colour, lw=0.6, alpha=0.6)
    ax.plot(cycles, model.stiffness_at(model.table_phase()) / 1e6, color=colour, lw=1.4,
            label=name)
ax.set_xlim(-0.2, 4.0)
ax.set_xlabel("pinion rotation [mesh cycles]")
ax.set_ylabel("mesh stiffness [N/um]")
ax.legend(loc="lower right")

# %%
# The same speed and torque, three revolutions of transient, four recorded. The time signal is
# the mesh deflection x along the line of action.
run = geardyn.RunSettings(transient=3 * 2 * math.pi / healthy.omega, samples=4)
sims = {name: geardyn.simulate(model, run=run)
        for name, model in (("healthy", healthy), ("cracked tooth", cracked))}

fig_t = Figure(figsize=(7.5, 5.0), layout="constrained")
ax_all, ax_zoom = fig_t.subplots(2, 1)
rev = 2 * math.pi / healthy.omega  # one pinion revolution [s]
for (name, ds), colour in zip(sims.items(), ("C0", "C3"), strict=True):
    t = ds["time"].values - ds["time"].values[0]
    x = ds["x"].values * 1e6
    keep = t <= 2 * rev
    ax_all.plot(t[keep] * 1e3, x[keep], color=colour, lw=0.6, label=name)
    near = (t >= rev - 0.1 * rev) & (t <= rev + 0.2 * rev)  # the cracked tooth in mesh
    ax_zoom.plot(t[near] * 1e3, x[near], color=colour, lw=0.9, label=name)
ax_all.set_ylabel("x [um]")
ax_all.legend(loc="upper right")
ax_zoom.set_xlabel("time [ms] (one pinion revolution: 60 ms; the cracked tooth meshes from 60 ms)")
ax_zoom.set_ylabel("x [um]")

# %%
# The amplitude spectra at whole pinion orders (multiples of f_r = 16.7 Hz). The healthy pair
# (thick, blue) has lines at the mesh harmonics only: between them it lies at rounding level,
# ~1e-14 of the mesh line, below the axis. The crack (thin, red) adds the sidebands
# k f_m +- j f_r around every mesh harmonic, and the pinion orders j f_r themselves.
spectra = {name: geardyn.amplitude_spectrum(ds, "x", window="boxcar")
           for name, ds in sims.items()}
fig_s = Figure(figsize=(7.5, 4.0), layout="constrained")
ax = fig_s.add_subplot()
orders = list(range(1, 3 * 19 + 6))
floor = 1e-6  # um; the healthy spectrum between the mesh harmonics lies far below
for (name, spec), colour, width in zip(spectra.items(), ("C0", "C3"), (3.0, 1.2), strict=True):
    amp = spec.sel(frequency=orders, method="nearest").values * 1e6
    ax.vlines(orders, floor, np.maximum(amp, floor), color=colour, lw=width, label=name)
spec_c = spectra["cracked tooth"]


def amplitude(order: int) -> float:
    return float(spec_c.sel(frequency=order, method="nearest")) * 1e6


for k in (1, 2, 3):
    ax.annotate(f"{k} f_m", (19 * k, amplitude(19 * k)), textcoords="offset points",
                xytext=(0, 4), ha="center", fontsize=8)
for k in (1, 2):
    for sign in (-1, 1):
        order = 19 * k + sign
        ax.annotate(f"{k} f_m {'+' if sign > 0 else '-'} f_r", (order, amplitude(order)),
                    textcoords="offset points", xytext=(sign * 22, 14), ha="center",
                    fontsize=7, color="C3", arrowprops={"arrowstyle": "-", "color": "C3",
                                                        "lw": 0.5})
ax.set_yscale("log")
ax.set_ylim(floor, None)
ax.set_xlabel("frequency [pinion orders, f / f_r]")
ax.set_ylabel("amplitude of x [um]")
ax.legend(loc="upper right")
side = [float(spec_c.sel(frequency=19 * k + s * j, method="nearest")
              / spectra["healthy"].sel(frequency=19 * k, method="nearest"))
        for k in (1, 2) for j in (1, 2, 3) for s in (-1, 1)]
print(f"sidebands k f_m +- j f_r (k = 1, 2; j = 1..3) over the healthy mesh line: "
      f"{min(side):.2g} to {max(side):.2g}")
