import time
import numpy as np, geardyn
from geardyn.solvers.reference import reference_solution

def period_map(g, y, T, n=1):
    return reference_solution(g, y, [n * T], rtol=1e-12, atol=1e-12)[0]

def orbit(g, y, n=1, iters=8):
    T = 2 * np.pi / g.omega
    for _ in range(iters):
        f = period_map(g, y, T, n) - y
        M = monodromy(g, y, T, n)
        dy = np.linalg.solve(M - np.eye(y.size), -f)
        y = y + dy
        if np.max(np.abs(dy)) < 1e-13:
            break
    return y, np.linalg.eigvals(monodromy(g, y, T, n))

def monodromy(g, y, T, n=1, e=1e-6):
    M = np.empty((y.size, y.size))
    for j in range(y.size):
        d = np.zeros(y.size); d[j] = e
        M[:, j] = (period_map(g, y + d, T, n) - period_map(g, y - d, T, n)) / (2 * e)
    return M

if __name__ == "__main__":
    pars = dict(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
    for om in [0.85, 0.87, 0.88, 0.885, 0.89, 0.895, 0.9]:
        g = geardyn.GearPair(**pars, Omega=om)
        t0 = time.time()
        ds = geardyn.bifurcation(g, "Omega", [om], transient=3000.0, samples=8)
        y0 = ds.poincare.values[0, -1]
        y, mu = orbit(g, y0)
        print(om, int(ds.period[0]), y, mu, time.time() - t0)
