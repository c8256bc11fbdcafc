"""
A damping map: motion type over Omega and the damping ratio
===========================================================

:func:`geardyn.map2d` classifies the steady motion on a grid of two parameters: here the mesh
frequency Omega against the damping ratio ``xi`` (both meshes) of the paper's device. Each grid
point is one lane of the compiled sweep kernel, started independently, so the map can also be
run in chunks on a Dask cluster and resumed from a Zarr store (``client=...``,
``store="map.zarr"``, see the user guide).

A coarse grid (48 x 5 points, short transient) keeps the build fast; the command line version
at higher resolution:

.. code-block:: sh

    geardyn map paper_fig3 --x Omega:0.1:4:400 --y xi:0.01:0.3:200 --out map.zarr --plot map.png
"""

# %%
import numpy as np

import geardyn
from geardyn.plotting.map2d import plot_map

model = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(), interpretation="consistent")
run = geardyn.RunSettings(transient=600.0, samples=32)
grid = geardyn.map2d(model, ("Omega", np.linspace(0.2, 4.0, 48)),
                     ("xi", [0.02, 0.05, 0.1, 0.15, 0.2]), run)
print(grid["period"].to_pandas())

# %%
# Period 0 means that no period up to ``max_period`` was found in the sampled periods: a chaotic
# or quasi-periodic motion, or (with this page's short transient, at light damping) one that has
# not settled yet; the map at full resolution uses the paper's transient of 4000. Heavier
# damping leaves period-1 motion almost everywhere.
fig = plot_map(grid)
