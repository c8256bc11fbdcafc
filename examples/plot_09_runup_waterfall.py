"""
A run-up of a gear pair through its resonances, and its waterfall
=================================================================

A test rig does not sweep a gearbox point by point: it ramps the speed and records.
:func:`geardyn.runup` ramps the mesh frequency Omega of the gear pair (:class:`geardyn.GearPair`,
dimensionless, time in units of its natural period) from 0.3 to 2.2 at a constant rate, the
mesh phase the integral of the speed, and records the mesh deflection and force.

:func:`geardyn.waterfall` cuts the record into short spectra: drawn against speed and
frequency, the mesh orders are rays from the origin and the natural frequency a horizontal
line; where an order crosses it, a resonance is passed (the primary one at Omega = 1, the
super-harmonic ones of the stiffness and error harmonics at Omega = 1/2, 1/3). Near Omega = 1
the teeth separate and the impacts spread energy over many orders.
:func:`geardyn.order_spectrum` resamples the record on the phase instead, so that each order is
a vertical line. Command line:
``geardyn runup STUDY.toml --start 0.3 --stop 2.2 --rate 1e-3 --out runup.nc --plot wf.png``
(or a ``[runup]`` table in the study).
"""

# %%
import geardyn
from geardyn.plotting.orders import plot_order_map, plot_waterfall

pair = geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.05)
run = geardyn.runup(pair, geardyn.RunupSettings(start=0.3, stop=2.2, rate=1e-3,
                                                sample_rate=4.0, outputs=("x", "F")))
print(f"{run.sizes['time']} samples over {run.attrs['ramp_duration']:g} time units, "
      f"RK4 step {run.attrs['step']:.4f} ({run.attrs['steps_per_period']} per period at the "
      f"top speed), status {run.attrs['status']}")

wf = geardyn.waterfall(run, "F")
fig = plot_waterfall(wf, run, harmonics=4)

# %%
# The same record by order: the meshing orders 1, 2, ... stay on their lines at every speed,
# and the resonance near Omega = 1 lights up the band between them.
fig = plot_order_map(geardyn.order_spectrum(run, "F"), max_order=5)
