"""
The softening jump of a single gear pair, swept up and down
===========================================================

The classic single-degree-of-freedom gear pair with backlash (:class:`geardyn.GearPair`:
damping ratio ``zeta``, stiffness variation ``kappa``, mean load ``Fm``, transmission-error
amplitude ``Fa``, all dimensionless). Near the primary resonance the teeth separate and the
response curve bends to lower frequencies (a softening nonlinearity): sweeping the mesh
frequency up and sweeping it down follow different branches, with jumps at different
frequencies and a band of coexisting motions between them.

:func:`geardyn.frequency_response` runs both sweeps by continuation (each point starts from
the previous one's final state) and returns the RMS and peak dynamic transmission error, the
dynamic factor, the hysteresis band and the located jumps. Command line:
``geardyn frc STUDY.toml --range 0.4:1.6:241 --out frc.nc --plot frc.png``.
"""

# %%
import numpy as np

import geardyn
from geardyn.plotting.frc import plot_frc

pair = geardyn.GearPair(zeta=0.05, kappa=0.0, Fm=0.1, Fa=0.05)
frc = geardyn.frequency_response(pair, np.linspace(0.4, 1.6, 121),
                                 geardyn.RunSettings(transient=300.0, samples=8))
print(frc[["jump_sweep", "jump_lo", "jump_hi"]].to_dataframe().to_string())

fig = plot_frc(frc)

# %%
# The same two sweeps by hand with :func:`geardyn.continued_sweeps`, which runs several sweeps
# by continuation together (each bitwise as if alone); their section points show the two
# branches.
from geardyn import ContinuedSweep  # noqa: E402

omegas = np.linspace(0.6, 1.2, 61)
run = geardyn.RunSettings(transient=300.0, samples=8)
up, down = geardyn.continued_sweeps(  # sweeps without a run of their own take this one
    [ContinuedSweep(pair, "Omega", omegas, d) for d in ("up", "down")], run)
for name, ds in (("up", up), ("down", down)):
    x = ds["poincare"].sel(state="x").isel(sample=-1).values
    print(f"{name:>4}: section x at Omega = 0.8: {x[np.argmin(abs(omegas - 0.8))]:.3f}")
