import sys, time
sys.path.insert(0, "scratch")
import numpy as np
import geardyn
from geardyn.models.user import UserModel
from geardyn.analysis.lyapunov import lyapunov
from models import vdp_rhs, sub_rhs

def blocks(model, y0, B, n, transient=100.0):
    S = [0.0]
    for j in range(1, n + 1):
        S.append(lyapunov(model, y0=y0, transient=transient, duration=j * B) * j * B)
    S = np.array(S)
    means = np.diff(S) / B
    return S[-1] / (n * B), means.std(ddof=1) / np.sqrt(n), S

if __name__ == "__main__":
  for mu, F, Om in [(0.5, 0.3, 2.5), (0.5, 0.3, 1.7), (1.0, 0.5, 3.3), (0.5, 0.2, np.sqrt(2))]:
      m = UserModel(vdp_rhs, 2, [mu, F, Om], param_names=["mu", "F", "Omega"])
      t0 = time.time()
      ds = geardyn.bifurcation(m, "Omega", [Om], transient=500.0, samples=64, max_period=16)
      y = ds["poincare"].values[0, -1]
      T = 2 * np.pi / Om
      B = 40 * T
      lam, err, S = blocks(m, y, B, 8)
      print(mu, F, Om, "period", int(ds["period"].values[0]), "lam %.2e err %.2e  5/T %.2e" % (lam, err, 5 / (8 * B)), "S-range", np.ptp(S - lam * np.arange(9) * B), time.time() - t0)
