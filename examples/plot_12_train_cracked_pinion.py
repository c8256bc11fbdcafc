"""
A cracked pinion tooth in a two-stage gear train
================================================

The built-in ``two_stage_train`` study (pinion g1, 19 teeth, drives g2, 61; g3, 23, on the same
shaft drives g4, 71; module 3 mm) with both meshes on the potential-energy stiffness of their
own teeth (:mod:`geardyn.trains`, docs/trains.md "Stiffness from the teeth"), once healthy and
once with a 2 mm root crack on tooth 3 of the input pinion g1 (``[[train.faults]]``). With the
fault the forcing period becomes one revolution of g1 (19 stage-1 mesh cycles): stage 1's
stiffness is the series of its potential-energy table over that revolution, so the crack acts
once per revolution, while tooth 3 is in contact. Stage 2 meshes at 23/61 of stage 1's
frequency, a non-integer ratio: the forcing is quasi-periodic, which the model and its datasets
say.

The stage-1 mesh force's spectrum over eight revolutions of g1 (Hann window) shows the
signature a diagnosis researcher looks for: sidebands at g1's rotation frequency f_r around the
stage-1 mesh frequency f_m1 = 19 f_r, which the healthy train lacks; the lines of stage 2 (f_m2 =
19 x 23 / 61 f_r) and their combinations with f_m1 are in both.
"""

# %%
import math

import numpy as np
from matplotlib.figure import Figure

import geardyn
from geardyn.io import load_study
from geardyn.io.toml import builtin_study_text
from geardyn.study import build_model

text = builtin_study_text("two_stage_train")
text = text.replace('stiffness = "iso"', 'stiffness = "potential_energy"\nbore_radius = "10 mm"')
text = text.replace("stiffness_fluctuation = 0.25\n", "")  # the teeth give the waveform
crack = ('\n[[train.faults]]\nkind = "crack"\ngear = "g1"\ntooth = 3\ndepth = "{}"\n'
         'angle = "45 deg"\n')
models = {name: build_model(load_study(text + crack.format(depth)))
          for name, depth in (("healthy", "0 mm"), ("cracked tooth", "2 mm"))}
cracked = models["cracked tooth"]
print(cracked)
print({k: cracked.dataset_attrs()[k] for k in ("forcing", "forcing_period", "faults")})

# %%
# Stage 1's drive-flank stiffness over one revolution of g1: the series the model integrates
# (9 x 19 = 171 harmonics of the revolution). The zero-size crack gives the healthy series.
fig_k = Figure(figsize=(7.5, 3.0), layout="constrained")
ax = fig_k.add_subplot()
cycles = np.linspace(0.0, 19.0, 4000)
for (name, model), colour in zip(models.items(), ("C0", "C3"), strict=True):
    coef = np.concatenate([[1.0], model.fourier[0]])
    h = np.arange(1, (coef.size - 1) // 2 + 1)
    theta = 2 * math.pi * cycles / 19
    k = model.mesh_stiffnesses()[0] * (coef[0] + coef[1::2] @ np.cos(np.outer(h, theta))
                                       + coef[2::2] @ np.sin(np.outer(h, theta)))
    ax.plot(cycles, k / 1e6, color=colour, lw=1.0, label=name)
ax.set_xlim(0.0, 8.0)
ax.set_xlabel("g1 rotation [stage-1 mesh cycles]; tooth 3 passes the pitch point at 3")
ax.set_ylabel("stage-1 stiffness [N/um]")
ax.legend(loc="lower right")

# %%
# Ten revolutions of transient, eight recorded at 3000 rpm; the spectrum of the stage-1 mesh
# force in g1 orders (multiples of f_r = 50 Hz).
revs = 8
spectra = {}
for name, model in models.items():
    revolution = 2 * math.pi / model.omega
    ds = geardyn.simulate(model, run=geardyn.RunSettings(transient=10 * revolution,
                                                         samples=revs,
                                                         steps_per_period=19 * 128))
    spectra[name] = geardyn.amplitude_spectrum(ds, "F_stage1", window="hann")
print("forcing:", ds.attrs["forcing"], "| sections:", ds.attrs["section"])

fig_s = Figure(figsize=(7.5, 4.0), layout="constrained")
ax = fig_s.add_subplot()
for (name, spec), colour, width in zip(spectra.items(), ("C0", "C3"), (2.2, 0.9),
                                       strict=True):
    keep = (spec["frequency"] > 0.5) & (spec["frequency"] < 45)
    ax.semilogy(spec["frequency"][keep], spec[keep], color=colour, lw=width, label=name)
spec_c, spec_h = spectra["cracked tooth"], spectra["healthy"]


def amplitude(spec, order: float) -> float:
    return float(spec.sel(frequency=order, method="nearest"))


for order, label in ((19, "f_m1"), (38, "2 f_m1"), (19 * 23 / 61, "f_m2")):
    ax.annotate(label, (order, amplitude(spec_h, order)), textcoords="offset points",
                xytext=(0, 5), ha="center", fontsize=8)
for sign in (-1, 1):
    order = 19 + sign
    ax.annotate(f"f_m1 {'+' if sign > 0 else '-'} f_r", (order, amplitude(spec_c, order)),
                textcoords="offset points", xytext=(sign * 45, 40), ha="center", fontsize=7,
                color="C3", arrowprops={"arrowstyle": "-", "color": "C3", "lw": 0.5})
ax.set_ylim(1e-3, None)
ax.set_xlabel("frequency [g1 orders, f / f_r]")
ax.set_ylabel("amplitude of the stage-1 mesh force [N]")
ax.legend(loc="lower left")
mesh_line = amplitude(spec_h, 19)
print("f_m1 -+ f_r over the mesh line, cracked:",
      [f"{amplitude(spec_c, 19 + s) / mesh_line:.2g}" for s in (-1, 1)],
      "healthy:", [f"{amplitude(spec_h, 19 + s) / mesh_line:.2g}" for s in (-1, 1)])
