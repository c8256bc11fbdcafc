"""
The paper's Fig. 3: bifurcation diagram of the device
======================================================

The sun-inside planet mesh displacement ``X_sq`` at the Poincaré section (once per mesh
period) against the dimensionless mesh frequency Omega, for the CATT device of the paper with
damping ratios xi1 = xi2 = 0.05 (Tables 1 and 2 otherwise), under the ``consistent``
interpretation of its formulas.

This page uses 160 values of Omega, a transient of 1000 and 32 sampled periods per point so
that the site builds quickly; the paper (and ``make demo``) uses 1000 values, a transient of
4000 and 64 periods:

.. code-block:: sh

    geardyn bifurcation paper_fig3 --out fig3.nc --plot fig3.png

How to read it: at each Omega the points are the section values of the steady motion. One
point is a period-1 (T-periodic) motion, two points period 2, a vertical smear of many points
a chaotic (or quasi-periodic) motion. The colour is the period found by the classifier; the
shaded bands mark where a mesh loses contact (backlash) during the motion.
"""

# %%
import numpy as np

import geardyn
from geardyn.plotting import plot_bifurcation

p = geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05)  # Tables 1 and 2, SI units
model = geardyn.CATTDevice(p, interpretation="consistent")
print(f"omega_n = {model.omega_n:.4g} rad/s")

run = geardyn.RunSettings(transient=1000.0, samples=32)
bif = geardyn.bifurcation(model, "Omega", np.linspace(0.1, 4.0, 160), run)

# %%
# The dataset holds the section points, the period and contact regime of every point, and
# the status of each lane (0: ok).
print(bif["period"].to_series().value_counts().sort_index().to_string())
print("lanes not ok:", int((bif["status"] != 0).sum()))

fig = plot_bifurcation(bif, state="X_sq")

# %%
# The paper reports period-2 motion near Omega = 1-1.2; the detail of one such point (time
# history, phase portrait, Poincaré section and labelled spectrum) comes from
# :func:`geardyn.simulate`.
from geardyn.plotting import plot_simulation  # noqa: E402

ds = geardyn.simulate(model, omega=1.1, run=run)  # 1000 time units, then 32 periods
fig_point = plot_simulation(ds, state="X_sq")
