import sys, time
sys.path.insert(0, "scratch")
import numpy as np
import geardyn
from geardyn.models.user import UserModel
from geardyn.analysis.lyapunov import lyapunov
from models import sub_rhs
from exp1 import blocks
for zeta, q in [(0.05, 20), (0.02, 17)]:
    Om = 1.3
    m = UserModel(sub_rhs, 2, [zeta, 0.5, 0.5, q, Om], param_names=["zeta", "F", "G", "q", "Omega"])
    ds = geardyn.bifurcation(m, "Omega", [Om], transient=1000.0, samples=64, max_period=16)
    ds2 = geardyn.bifurcation(m, "Omega", [Om], transient=1000.0, samples=64, max_period=24)
    y = ds["poincare"].values[0, -1]
    T = 2 * np.pi / Om * q
    lam, err, S = blocks(m, y, 2 * T, 8)
    print(zeta, q, int(ds.period[0]), int(ds2.period[0]), lam, err, 5 / (16 * T))
g = geardyn.GearPair(zeta=0.02, kappa=0.2, Fm=0.1, Fa=0.3, Omega=0.92)
ds = geardyn.bifurcation(g, "Omega", [0.92], transient=500.0, samples=64)
y = ds["poincare"].values[0, -1]
T = 2 * np.pi / 0.92
for B in (20, 40):
    lam, err, S = blocks(g, y, B * T, 8)
    print("gear", int(ds.period[0]), lam, err, 5 / (8 * B * T))
