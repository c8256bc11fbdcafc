"""
A planetary gear set from its geometry
======================================

:meth:`geardyn.PlanetaryGearSet.from_geometry` builds the Lin & Parker lumped model of a
planetary stage from its gears: ISO 6336-1 mean mesh stiffnesses, the single/double tooth
contact stiffness waves and the Parker & Lin mesh phases of the planets. The built-in study
``planetary_example`` is such a stage: sun 25, planets 23, ring 71 teeth, module 2 mm, four
equally spaced planets, 10 um backlash in every mesh and a light sun torque, so that the meshes
lose contact near the resonances.

First the linear modes (at mean stiffness), classified as rotational, translational and
planet modes, then a short sweep of the mesh frequency.
"""

# %%
import numpy as np

import geardyn
from geardyn.io import builtin_study
from geardyn.plotting import plot_bifurcation

study = builtin_study("planetary_example")
gs = geardyn.build_model(study)
modes = gs.modes()
print(modes[["frequency", "multiplicity", "type"]].to_dataframe().to_string())

# %%
# The mesh stiffness waves that the geometry gives (sun-planet and ring-planet meshes).
from matplotlib.figure import Figure  # noqa: E402

w_sun, w_ring = gs.stiffness_waveforms
fig_waves = Figure(figsize=(7.0, 3.0), layout="constrained")
ax = fig_waves.add_subplot()
for name, w in (("sun-planet", w_sun), ("ring-planet", w_ring)):
    s = np.linspace(0.0, 2.0, 400)  # two mesh cycles
    ax.plot(s, w(2.0 * np.pi * s) / 1e6, label=name)
ax.set_xlabel("mesh cycles")
ax.set_ylabel("mesh stiffness [N/um]")
ax.legend()

# %%
# A sweep of Omega (the mesh frequency over the model's time scale) through the lowest
# resonances: 70 points and a short transient (the study's ``[sweep]`` has 400). The stage is
# lightly damped (mesh damping only), and within this page's short transient its Poincaré points
# have not settled (the classifier finds no period: grey); the bands below show where each
# sun-planet (s) and ring-planet (r) mesh loses contact near the resonances. For settled motion
# add ``modal_damping`` to the study's ``[params]`` and a transient by convergence
# (``RunSettings(converge=1e-8)``).
run = geardyn.RunSettings(transient=200.0, samples=16)
bif = geardyn.bifurcation(gs, "Omega", np.linspace(0.05, 1.2, 70), run)
fig = plot_bifurcation(bif, state=study.plot_state)
