"""
The rattle map of a gear pair: contact regions in speed and mean load
=====================================================================

Where does a gear pair run without rattle? :func:`geardyn.envelope` answers in the plane of
the mesh frequency Omega (the speed) and the mean load Fm: it follows the **grazing curves**
of the period-1 orbit (:func:`geardyn.grazing_curve`: the orbit's least distance to a dead-zone
edge is zero) of the drive flank (contact loss) and the back flank (back-flank impacts begin),
and fills the regions they bound: contact kept, one-sided impacts (rattle), two-sided impacts.

A coarse brute-force map of the same plane (:func:`geardyn.map2d`, one start per cell) is drawn
beneath as markers in the regions' colours: where the map's attractor is the curves' orbit its
marker disappears into its region; where it stands out, the map's start fell on another
response (coexisting with the period-1 orbit, or chaotic: hatched).

The command line version reads the plane from a study's ``[envelope]`` table:

.. code-block:: sh

    geardyn envelope gear_pair.toml --x Omega:0.5:2 --y Fm:0.02:0.3 --map 16:12 \\
        --out curves/ --plot rattle.png
"""

# %%
import numpy as np

import geardyn
from geardyn.plotting import plot_envelope

pair = geardyn.GearPair(zeta=0.05, kappa=0.2, Fa=0.1, Fm=0.1)
x_range, y_range = (0.5, 2.0), (0.02, 0.3)
grid = geardyn.map2d(pair, ("Omega", np.linspace(*x_range, 16)),
                     ("Fm", np.linspace(*y_range, 12)),
                     geardyn.RunSettings(transient=400.0, samples=16))
env = geardyn.envelope(pair, "Omega", "Fm", x_range, y_range, map=grid, resolution=120)
for curve in env.grazing():
    print(curve.attrs["flank"], curve.sizes["point"], "points:", curve.attrs["message"])

# %%
# Below the drive flank's curve (light load at the resonance) the teeth separate once per
# period; more mean load keeps them in contact. The back flank's curve bounds the two-sided
# impacts at the lightest loads. Each curve is a ``"curve"`` dataset (``geardyn_kind``), its
# orbit's section point, Floquet multipliers and the grazing time at every point.
fig = plot_envelope(env, title="gear pair (zeta 0.05, kappa 0.2, Fa 0.1): rattle map")
