"""
Lyapunov exponents of your own model
====================================

Any model goes through the same compiled solvers and analyses: wrap a ``numba.njit``
right-hand side ``rhs(t, y, dydt, p)`` in :class:`geardyn.UserModel`. Here the forced
double-well Duffing oscillator

.. math:: \\ddot x + \\delta \\dot x - x + x^3 = \\gamma \\cos(\\Omega t),

with delta = 0.3 and gamma = 0.5, chaotic near Omega = 1.2 (Guckenheimer & Holmes). Naming a
parameter ``"Omega"`` makes it the forcing frequency: sweeps over ``"Omega"`` work and the
forcing period is 2 pi / Omega.

A sweep with ``lyapunov=True`` gives every point its largest Lyapunov exponent (per unit
time), its standard error and a motion class; :func:`geardyn.lyapunov` gives the exponent (or
the whole spectrum) at one point.

The right-hand side is a ``numba.njit`` function in a small module beside this script,
``examples/duffing_model.py`` (in a module that can be imported, its kernels are cached on disk;
defined in the script itself it would work the same, compiled anew in every process):

.. literalinclude:: ../../examples/duffing_model.py
   :pyobject: duffing
"""

# %%
import math

import numpy as np
from duffing_model import duffing

import geardyn
from geardyn.plotting import plot_bifurcation

model = geardyn.UserModel(duffing, n_states=2, params=[0.3, 0.5, 1.2],
                          param_names=["delta", "gamma", "Omega"], state_names=["x", "v"],
                          name="Duffing", natural_frequency=math.sqrt(2.0))

# %%
# Check the model against the model contract first (rule 10 compares a short run with the
# adaptive reference integrator, DOP853 at rtol 1e-12).
from geardyn.testing import check_model  # noqa: E402

print(check_model(model, y0=[1.0, 0.0]))

# %%
# A sweep over Omega with the exponent at every point (80 points, short runs).
run = geardyn.RunSettings(transient=300.0, samples=32)
bif = geardyn.bifurcation(model, "Omega", np.linspace(0.8, 1.6, 80), run, lyapunov=True,
                          y0=np.array([1.0, 0.0]))
print(bif["motion"].to_series().value_counts().to_string())
fig = plot_bifurcation(bif, state="x")

# %%
# The spectrum at Omega = 1.2: the exponents sum to -delta (the divergence of the flow),
# a check that needs no reference.
lam = geardyn.lyapunov(model.with_omega(1.2), y0=[1.0, 0.0],
                       run=geardyn.RunSettings(transient=300.0),
                       settings=geardyn.LyapunovSettings(duration=3000.0), spectrum=True)
print("spectrum:", lam, " sum:", lam.sum(), " (expected -0.3)")
