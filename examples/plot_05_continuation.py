"""
Continuation of a periodic orbit and its bifurcations
=====================================================

:func:`geardyn.continuation` follows a periodic orbit of the stroboscopic map in a parameter
by pseudo-arclength continuation, stable or not, through folds, and locates its bifurcations
from the Floquet multipliers: folds (LP), period doublings (PD), Neimark-Sacker points (NS) and
contact changes (CC, where a mesh starts or stops losing contact). Here the period-1 orbit of
the softening gear pair from the previous example, over a brute-force diagram of the same
range: the unstable middle branch that the sweeps never show joins the two stable ones at the
folds, which are the jump points.
"""

# %%
import numpy as np

import geardyn
from geardyn.plotting.branch import plot_branch

pair = geardyn.GearPair(zeta=0.05, Fm=0.1, Fa=0.05)
branch = geardyn.continuation(pair, "Omega", 0.5, 1.6)
print("branch:", branch.attrs.get("message", ""))
for kind, value in zip(
    branch["bifurcation_kind"].values, branch["bifurcation_value"].values, strict=True
):
    print(f"{kind:>8} at Omega = {value:.6f}")

sweep = geardyn.bifurcation(pair, "Omega", np.linspace(0.5, 1.6, 56),
                            run=geardyn.RunSettings(transient=300.0, samples=16))
fig = plot_branch(branch, over=sweep)

# %%
# With ``switch=True`` the continuation starts the period-2 branch at each located period
# doubling (a stiffness variation ``kappa`` makes one appear).
pair2 = geardyn.GearPair(zeta=0.02, Fm=0.1, Fa=0.1, kappa=0.2)
both = geardyn.continuation(pair2, "Omega", 1.9, 1.5, switch=True)
print(sorted(set(both["bifurcation_kind"].values.tolist())))
fig_switch = plot_branch(both)
