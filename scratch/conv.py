import sys, time
sys.path.insert(0, "scratch")
import numpy as np, geardyn
from floquet import orbit
pars = dict(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
for om in [0.899, 0.9, 0.903, 0.906]:
    g = geardyn.GearPair(**pars, Omega=om)
    t0 = time.time()
    c = geardyn.bifurcation(g, "Omega", [om], transient=200.0, samples=8, converge=1e-8, transient_max=40000.0)
    f = geardyn.bifurcation(g, "Omega", [om], transient=40000.0, samples=8)
    pc, pf = int(c.period[0]), int(f.period[0])
    xc, xf = c.poincare.values[0], f.poincare.values[0]
    # align phase of period-2: compare against both shifts
    err = min(np.max(np.abs(xc - xf)), np.max(np.abs(xc[1:] - xf[:-1])))
    print(om, "conv", pc, int(c.converged[0]), float(c.transient_periods[0]), "fixed", pf, "err %.2e" % err, "split %.2e" % np.max(np.abs(xf[1] - xf[0])), time.time() - t0)
