import numpy as np, geardyn
for pars in [dict(zeta=0.02, kappa=0.2, Fm=0.1, Fa=0.3), dict(zeta=0.05, kappa=0.2, Fm=0.2, Fa=0.1), dict(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)]:
    g = geardyn.GearPair(**pars, Omega=1.0)
    om = np.linspace(0.3, 3.0, 271)
    ds = geardyn.bifurcation(g, "Omega", om, transient=1500.0, samples=32, continuation="up")
    p = ds.period.values
    print(pars)
    for i in range(1, om.size):
        if p[i] != p[i-1]:
            print("  %.3f %d -> %d" % (om[i], p[i-1], p[i]))
