"""What an analysis compiles: only the kernels it runs, the shared step machinery once per model.

A numba dispatcher lists the signatures it has compiled or loaded from the cache in this
process (``signatures``). An entry point called from Python appears there whether it was
compiled or loaded; a function it calls appears only where it was compiled (a cached caller
carries its callees' code). So these tests count the entry points an analysis calls, and hold
with a cold and with a warm cache alike: each lane form has its own entry point, called only
for lanes of that form.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import geardyn
from geardyn.core.kernel_source import FORM_GENERAL, FORM_LOAD, FORM_QUIET
from geardyn.solvers import _step_shared
from geardyn.solvers.kernels import TEMPLATES, kernels_for


def paper_device() -> geardyn.CATTDevice:
    return geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05))


def _lane_forms(model, P: np.ndarray) -> set[int]:
    k = kernels_for(model.kernel)
    PT = np.ascontiguousarray(P.T)
    return {int(k._lane_form(PT, i)) for i in range(P.shape[0])}


def test_templates_share_one_core_module_per_model():
    """The split step, the tangent rows and the phase table are one set of functions per
    model, imported by its trajectory/sweep, Lyapunov and monodromy modules (each template
    compiled its own copy of them before)."""
    model = geardyn.GearPair(Omega=1.3, kappa=0.2, Fa=0.2)
    mods = [kernels_for(model.kernel, t) for t in TEMPLATES if t != "core"]
    core = kernels_for(model.kernel, "core")
    for name in ("_split_step", "_rows_step", "_rk4_stages"):
        assert all(getattr(m, name) is getattr(core, name) for m in mods), name
    # the model-independent step functions: one for every model, from where they are defined
    shared = _step_shared.phase_table
    assert any(hasattr(m, "phase_table") for m in mods)
    assert all(getattr(m, "phase_table", shared) is shared for m in mods)
    # and another model has its own
    other = kernels_for(paper_device().kernel, "core")
    assert other is not core and other._split_step is not core._split_step


# The analyses run in a fresh process, in this order, each followed by a census of the kernels
# loaded or compiled so far: in the test process another test may have run them already.
_SCRIPT = """
import json
import numpy as np
import geardyn
from geardyn.solvers.kernels import kernels_for

def census(model, template, names):
    k = kernels_for(model.kernel, template)
    return {n: len(getattr(k, n).signatures) if hasattr(k, n) else -1 for n in names}

pair = geardyn.GearPair(Omega=1.3, kappa=0.2, Fa=0.2)
dev = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05))
sweep = ["trajectory", "_sweep_worker", "_sweep_worker_form0", "_sweep_worker_form1",
         "_sweep_worker_form2"]
lyap = ["_lyap_block_worker", "_lyap_block_worker_form1",
        "_lyap_block_worker_form2", "_lyap_var_worker_form0", "_lyap_var_worker_form1",
        "_lyap_var_worker_form2", "_lyap_spec_worker_form0", "_lyap_spec_worker_form1",
        "_lyap_spec_worker_form2"]
out = {}
geardyn.simulate(pair, omega=1.3, run=geardyn.RunSettings(transient=0.0, samples=2))
out["simulate"] = census(pair, "rk4", sweep)
geardyn.bifurcation(dev, "Omega", np.linspace(0.8, 1.6, 6),
                    run=geardyn.RunSettings(transient=10.0, samples=2))
out["sweep"] = census(dev, "rk4", sweep)
lam = geardyn.lyapunov_lanes(dev, dev.lane_params("Omega", np.linspace(0.8, 1.6, 4)),
                             run=geardyn.RunSettings(transient=5.0),
                             settings=geardyn.LyapunovSettings(duration=10.0))
out["lanes"] = census(dev, "lyapunov", lyap)
out["lanes_finite"] = bool(np.all(np.isfinite(lam)))
gen = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05), reduced=False)
lam = geardyn.lyapunov_lanes(gen, gen.lane_params("Omega", np.linspace(0.8, 1.6, 4)),
                             run=geardyn.RunSettings(transient=5.0),
                             settings=geardyn.LyapunovSettings(duration=10.0))
out["general_lanes"] = census(gen, "lyapunov", lyap)
out["general_finite"] = bool(np.all(np.isfinite(lam)))
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def census() -> dict:
    res = subprocess.run([sys.executable, "-c", _SCRIPT], capture_output=True, text=True,
                         check=True, env=dict(os.environ))
    return json.loads(res.stdout.strip().splitlines()[-1])


def test_simulate_compiles_the_trajectory_path_only(census):
    c = census["simulate"]
    assert c["trajectory"] == 1
    assert not any(v > 0 for n, v in c.items() if n != "trajectory"), c


def test_sweep_compiles_the_lane_forms_its_lanes_take_only(census):
    """A sweep whose lanes all take FORM_QUIET (the paper device: one stiffness harmonic, no
    load fluctuation) loads or compiles that form's fused loop and no other (before, the
    sweep compiled all three forms' loops whatever its lanes)."""
    model = paper_device()
    assert _lane_forms(model, model.lane_params("Omega", np.linspace(0.8, 1.6, 6))) == {
        FORM_QUIET}
    c = census["sweep"]
    assert c["_sweep_worker_form1"] == 1, c
    for n in ("_sweep_worker", "_sweep_worker_form0", "_sweep_worker_form2"):
        assert c[n] == 0, (n, c)


def test_lyapunov_lanes_compile_the_lane_form_they_take_only(census):
    """The Lyapunov lane blocks of FORM_QUIET lanes of the paper's device (a one-form model:
    the variational tangent, k = 1) run that form's variational fused loop only (not the other
    forms' copies, nor the spectrum's k > 1 workers, nor the difference-row blocks)."""
    c = census["lanes"]
    assert census["lanes_finite"]
    assert c["_lyap_var_worker_form1"] == 1, c
    for n in ("_lyap_var_worker_form0", "_lyap_var_worker_form2", "_lyap_block_worker",
              "_lyap_block_worker_form1", "_lyap_block_worker_form2", "_lyap_spec_worker_form0",
              "_lyap_spec_worker_form1", "_lyap_spec_worker_form2"):
        assert c[n] == 0, (n, c)
    assert FORM_LOAD != FORM_QUIET != FORM_GENERAL


def test_lyapunov_lanes_of_a_model_without_a_one_form_compile_its_lane_form_only(census):
    """The Lyapunov lanes of a model without a one form (the general N-set CATT kernel: its
    lanes take FORM_GENERAL, no fused loop, no variational tangent) run the difference-row
    block worker of FORM_GENERAL only: not the fused loops of the other forms, not the
    variational workers."""
    model = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05), reduced=False)
    assert model.kernel.one_form is None
    assert _lane_forms(model, model.lane_params("Omega", np.linspace(0.8, 1.6, 4))) == {
        FORM_GENERAL}
    c = census["general_lanes"]
    assert census["general_finite"]
    assert c["_lyap_block_worker"] == 1, c
    for n in ("_lyap_block_worker_form1", "_lyap_block_worker_form2", "_lyap_var_worker_form0",
              "_lyap_var_worker_form1", "_lyap_var_worker_form2", "_lyap_spec_worker_form0",
              "_lyap_spec_worker_form1", "_lyap_spec_worker_form2"):
        assert c[n] == 0, (n, c)
