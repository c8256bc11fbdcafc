"""
What a sensor on the ring sees: planet-pass modulation and sidebands
=====================================================================

A vibration sensor fixed on the ring of a planetary stage hears each planet's ring-planet mesh
force mostly while that planet passes under it. :func:`geardyn.planetary_sensor_signal` weights
the mesh forces ``F_r1 .. F_rN`` of a :func:`geardyn.simulate` run by a window in the angle
between each planet and the sensor (a Hann window 90 degrees wide here; the transfer model of
McFadden & Smith 1985 and Inalpolat & Kahraman 2009, see ``docs/sensor.md``) and adds them.

The stage is the built-in ``planetary_example``: ring 71 teeth, four equally spaced planets.
The spectrum, in orders of the carrier's rotation, has no line at the mesh order 71 itself:
only the orders that are multiples of N = 4 survive the planets' phasing, 68 = 71 - 3,
72 = 71 + 1 and 76 = 71 + 5 around the first mesh harmonic (asymmetric about it), 140 and 144
around the second (142 = 2 x 71 = 2 mod 4).
"""

# %%
import math

import geardyn
from geardyn.analysis.sensor import label_sidebands, sensor_spectrum, surviving_orders
from geardyn.io import builtin_study
from geardyn.plotting.sensor import plot_sensor

gs = geardyn.build_model(builtin_study("planetary_example"))
z_r, n_p = gs.geometry.ring.teeth, gs.n_planets
revolutions = 3  # carrier revolutions recorded: 3 x 71 mesh cycles
omega = 0.2
print(f"input (sun) speed {gs.with_omega(omega).input_speed:.0f} rpm")
run = geardyn.RunSettings(transient=3000.0, samples=revolutions * z_r)
ds = geardyn.simulate(gs, omega=omega, run=run, record_every=15)
sig = geardyn.planetary_sensor_signal(ds.isel(time=slice(0, -1)), gs, sensor_angle=0.0,
                                      width=math.pi / 2, window="hann")

# %%
# The lines the phasing keeps (derived in ``docs/sensor.md``: carrier order m Z_r + k survives
# where it is a multiple of N) and the labelled peaks of the spectrum.
for m in (1, 2):
    print(f"mesh harmonic {m}: sidebands k = {surviving_orders(z_r, n_p, m, 8)}")
spec = sensor_spectrum(sig["signal"].values, revolutions)
for order, amp, label in label_sidebands(spec, z_r, harmonics=2, span=8):
    print(f"{label:>7s}  order {order:5.0f}  {amp:8.3f} N")

fig = plot_sensor(sig, harmonics=2, span=8)
