"""The generated kernel source of every built-in model, for every kernel template: it parses,
keeps no template marker or template binding, imports the model's own functions (and from
geardyn nothing else but the modules every model shares), and its kernel runs: the RK4
kernel's ``trajectory`` matches the reference integrator, and the Lyapunov kernel's exponents
sum to the divergence of the vector field."""

from __future__ import annotations

import ast
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from _lyapunov_rows import one_lane
from conformance_cases import IDS, cases
from geardyn.analysis.lyapunov import lyapunov_variational
from geardyn.core.plan import default_steps_per_period
from geardyn.core.settings import DEFAULT_BOUND
from geardyn.solvers.kernels import SHARED_MODULES, TEMPLATES, cache_dir, kernels_for
from geardyn.solvers.reference import reference_solution

#: Modules a generated kernel may import besides the model's own (the shared modules: kernel
#: code that does not evaluate the model, compiled once for every model; the compile settings
#: of geardyn._jit_target and geardyn._bound_calls).
_ALLOWED = {"__future__", "math", "numba", "numpy", "llvmlite", "geardyn._jit_target",
            "geardyn._bound_calls", "geardyn.core._noop",
            "geardyn.core.kernel_source", "geardyn.core.one_form", "geardyn.core.dual",
            "geardyn.solvers._parallel",
            *SHARED_MODULES}
#: Packages whose submodules a generated kernel may import too (numba.extending, numba.core:
#: the sweep template's prefetch intrinsic).
_ALLOWED_PACKAGES = {"numba", "llvmlite"}
_TEMPLATE_MODULES = {"geardyn.solvers._template_model", "geardyn.solvers._step_core",
                     *TEMPLATES.values()}


@pytest.fixture(scope="module")
def all_cases():
    return cases()


def _imports(tree: ast.Module) -> set[tuple[str, str, str]]:
    """(module, name, alias) of every ``from module import name as alias`` in the module."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            out |= {(node.module, a.name, a.asname or a.name) for a in node.names}
        elif isinstance(node, ast.Import):
            out |= {(a.name, "", a.asname or a.name) for a in node.names}
    return out


@pytest.mark.parametrize("template", list(TEMPLATES))
@pytest.mark.parametrize("case", IDS)
def test_generated_source_keeps_its_contract(all_cases, case, template):
    """On the pointer path, the modules generated with the model's functions inlined (its part
    imports them; tests/test_pointer_path.py covers the pointer path's own modules)."""
    model, _ = all_cases[case]
    source = dataclasses.replace(model.kernel, path=None)
    module = kernels_for(source, template)
    path = Path(module.__file__)
    assert path.parent.resolve() == cache_dir().resolve()
    text = path.read_text()
    tree = ast.parse(text)  # valid Python
    lines = text.splitlines()
    assert not [line for line in lines if line.rstrip().endswith("# CORE-IMPORT")]
    marked = [line for line in lines if line.rstrip().endswith("# MODEL-IMPORT")]
    assert marked and not any("_template_model" in line for line in marked)
    imports = _imports(tree)
    funcs = model.kernel.functions()
    own = {(f.py_func.__module__, f.py_func.__name__, alias) for alias, f in funcs.items()}
    assert own <= imports  # the model's own functions, under the interface names
    for alias, f in funcs.items():
        assert getattr(module, alias) is f
    modules = {m for m, _, _ in imports if m.split(".")[0] not in _ALLOWED_PACKAGES}
    assert not modules & _TEMPLATE_MODULES  # no binding to the template's test model or core
    # and the model's own core module (the shared step machinery, one per model)
    core = {kernels_for(model.kernel, "core").__name__} if template != "core" else set()
    assert modules <= _ALLOWED | {m for m, _, _ in own} | core, modules
    # one module per model and template, kept for the process
    assert kernels_for(source, template) is module


def _grid(model, periods: int) -> tuple[int, float, int]:
    """Steps per period, step and steps for ``periods`` forcing periods at the default step."""
    n = default_steps_per_period(model)
    return n, 2.0 * math.pi / (model.omega * n), periods * n


@pytest.mark.parametrize("case", IDS)
def test_generated_rk4_trajectory_matches_reference(all_cases, case):
    model, y0 = all_cases[case]
    k = kernels_for(model.kernel, "rk4")
    n, h, steps = _grid(model, periods=2)
    stride = n // 4 if n % 4 == 0 else n
    p = np.ascontiguousarray(model.params)
    Y, O, G, ncross, status, unresolved, done = k.trajectory(
        p, y0, h, model.omega, n, 0, steps, stride, True, DEFAULT_BOUND, model.n_events,
        model.n_observables)
    assert status == 0 and unresolved == 0 and done == steps
    assert Y.shape == (steps // stride + 1, model.n_states)
    assert O.shape == (Y.shape[0], model.n_observables)
    assert G.shape == (Y.shape[0], model.n_events)
    if model.n_events:
        assert ncross.sum() > 0  # the run crosses edges: their location is exercised
    t = np.arange(Y.shape[0]) * stride * h
    ref = reference_solution(model, y0, t)
    scale = np.max(np.abs(ref), axis=0)
    err = np.max(np.abs(Y - ref), axis=0) / np.where(scale > 0, scale, 1.0)
    assert np.max(err) < 1e-5, err


def _trace(model, y: np.ndarray) -> float:
    """Divergence of the vector field at y (t = 0), by central differences of the model's rhs
    (exact for these models: each derivative is linear in the velocity that drives it)."""
    k = kernels_for(model.kernel, "rk4")
    p = np.ascontiguousarray(model.params)
    tr = 0.0
    f1, f2 = np.empty(model.n_states), np.empty(model.n_states)
    for q in range(model.n_states):
        e = 1e-3 * max(abs(y[q]), 1.0)
        for f, d in ((f1, e), (f2, -e)):
            yy = y.copy()
            yy[q] += d
            k.rhs(0.0, yy, f, p, 0.0, 1.0)
        tr += (f1[q] - f2[q]) / (2 * e)
    return tr


@pytest.mark.parametrize("case", IDS)
def test_generated_lyapunov_exponents_sum_to_the_divergence(all_cases, case):
    """With as many tangent vectors as states, the exponents sum to the time average of the
    divergence of the vector field (Liouville), a constant for every model here. For
    DimensionalCATT (SI body angles) this holds only because the tangent vectors live in the
    model's ``state_scale`` (a perturbation of 1e-6 rad would be ~0.1 % of the backlash: the
    sum was +7e4 /s instead of -4.0e4 /s)."""
    model, y0 = all_cases[case]
    k = kernels_for(model.kernel, "lyapunov")
    n, h, steps = _grid(model, periods=1)
    p = np.ascontiguousarray(model.params)
    scale = np.ascontiguousarray(model.state_scale, dtype=float)
    # one lane of the lane blocks with n_states tangent vectors, as geardyn.lyapunov(...,
    # spectrum=True) runs it
    exps, _, _, status, _, _ = one_lane(k, p, y0, scale, 0.0, h, model.omega, n, 0, steps, 8,
                                        model.n_states, DEFAULT_BOUND, model.n_events, 16,
                                        lyapunov_variational(model))
    assert status == 0
    tr = _trace(model, y0)
    assert abs(np.sum(exps) - tr) <= 1e-6 * abs(tr), (np.sum(exps), tr)


def test_kernel_compilation_silences_only_numbas_internal_notes():
    """Compiling the generated kernels fires numba's pedantic IR check and its debug-line notes
    by the hundred (pages of them on a first ``geardyn reproduce``); geardyn's compiles ignore
    exactly those two categories, inside the compile only: importing the kernel module adds no
    global filter, so a numba deprecation or performance warning of the user's own code still
    reaches them. Checked in a fresh interpreter, as the CLI runs (pytest resets the warning
    filters around every test)."""
    import subprocess
    import sys

    probe = (  # the ignore filters that apply to numba's warnings, wherever they are raised
        "import warnings, numba.core.errors as e, geardyn.solvers.kernels as k\n"
        "ig = {f[2].__name__ for f in warnings.filters if f[0] == 'ignore' and f[3] is None\n"
        "      and f[1] is None and issubclass(e.NumbaWarning, f[2]) | issubclass(f[2],\n"
        "      e.NumbaWarning)}\n"
        "print(sorted(ig), sorted(c.__name__ for c in k.QUIET_WARNINGS))\n"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == "[] ['NumbaDebugInfoWarning', 'NumbaIRAssumptionWarning']"
