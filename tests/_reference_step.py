"""Test entry points to the step core's inlined pieces (:mod:`geardyn.solvers._step_core`), for
one model's core module: one RK4 step, the events along a step's interpolant, the first
crossing on it, and the Illinois root finder on the model's events. The kernels inline these
pieces. The wrappers are written, per core module, into a module file in the kernel cache's
folder (``kernels/``, named by a hash of the wrappers and of the core module's source) that
imports the core module's functions, and are compiled and cached there as geardyn's kernels are:
a second process loads them. A core module without a file (an in-memory one) gets wrappers
compiled in memory, once per process."""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import os
import sys
import types
from pathlib import Path

import numba as nb

from geardyn.solvers import kernels

#: The names the wrappers take from the core module.
_CORE_NAMES = ("rhs", "_rk4_stages", "_interpolant_events", "_first_crossing", "_illinois",
               "_forced")
_JIT = '''_JIT = {"cache": True, "error_model": "numpy", "boundscheck": False}
'''
_SOURCE = '''
@nb.njit(**_JIT)
def rk4(t, y, h, p, s0, c0, s1, c1, s2, c2, k1, kst, acc, tmp, out):
    """One RK4 step of size h from (t, y) into out (forcing phase s0, c0 at its start, s1, c1
    at its middle, s2, c2 at its end): the kernels' step (_rk4_stages after k1 = f(t, y))."""
    rhs(t, y, k1, p, s0, c0)
    _rk4_stages(y, h, t + 0.5 * h, p, s1, c1, t + h, p, s2, c2, k1, kst, acc, tmp, out)


@nb.njit(**_JIT)
def interpolant_events(y0, f0, y1, f1, dt, t, p, ybuf, gbuf, pc):
    """The events along the step's interpolant at theta = 0, 1/3, 2/3 into rows 0, 3, 4 of
    gbuf (_interpolant_events)."""
    _interpolant_events(y0, f0, y1, f1, dt, t, p, ybuf, gbuf[0], gbuf[3], gbuf[4], pc)


@nb.njit(**_JIT)
def first_crossing(j, side_j, g1j, y0, f0, y1, f1, dt, t, p, ybuf, gbuf, pc):
    """Fraction in (0, 1] of the step where event j first leaves side side_j, or 2.0
    (_first_crossing with the graze test; gbuf rows 0, 3, 4 from interpolant_events, row 1
    scratch)."""
    return _first_crossing(j, side_j, True, g1j, y0, f0, y1, f1, dt, t, p, ybuf, gbuf, gbuf[1],
                           pc)


@nb.njit(**_JIT)
def illinois(j, side_j, g0j, b, fb, y0, f0, y1, f1, dt, t, p, ybuf, g, pc):
    """Fraction in (0, b] of the step where event j leaves side side_j, by the Illinois method
    on the model's events along the interpolant from the bracket [0, b] (g0j: the event at the
    start, taken as on side side_j; fb: at b, off it)."""
    return _illinois(j, side_j, 0.0, _forced(g0j, side_j), b, fb, y0, f0, y1, f1, dt, t, p,
                     ybuf, g, pc)
'''

_BOUND: dict[str, types.SimpleNamespace] = {}


def _module(core: types.ModuleType) -> types.ModuleType:
    """The wrappers of ``core`` as a cached module file in the kernel cache's folder
    (``core`` has a file), else compiled in memory."""
    names = ("rk4", "interpolant_events", "first_crossing", "illinois")
    path = getattr(core, "__file__", None)
    if path is None:
        env = {"nb": nb, **{name: getattr(core, name) for name in _CORE_NAMES}}
        exec(compile(_JIT.replace("True", "False") + _SOURCE,
                     f"<reference step of {core.__name__}>", "exec"), env)
        return types.SimpleNamespace(**{name: env[name] for name in names})
    text = (f"import numba as nb\nfrom {core.__name__} import {', '.join(_CORE_NAMES)}\n"
            + _JIT + _SOURCE)
    h = hashlib.sha256(text.encode() + nb.__version__.encode() + Path(path).read_bytes())
    for shared in kernels.SHARED_MODULES:  # the core module's code inlines theirs
        h.update(Path(importlib.import_module(shared).__file__).read_bytes())
    name = f"geardyn_refstep_{h.hexdigest()[:20]}"
    folder = kernels.cache_dir()
    folder.mkdir(parents=True, exist_ok=True)
    file = folder / f"{name}.py"
    if not file.exists():
        tmp = file.with_name(f"{name}.{os.getpid()}.tmp")
        tmp.write_text(text)
        tmp.replace(file)  # atomic: a second process never reads half a file
    spec = importlib.util.spec_from_file_location(name, file)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    kernels._quiet_module(module)  # compiled as geardyn's kernels are (names, lock, warnings)
    return module


def step_pieces(core: types.ModuleType) -> types.SimpleNamespace:
    """``rk4``, ``interpolant_events``, ``first_crossing`` and ``illinois`` bound to the core
    module ``core`` (a model's, ``kernels_for(model.kernel, "core")``, or
    :mod:`geardyn.solvers._step_core` itself: the template oscillator)."""
    if core.__name__ not in _BOUND:
        module = _module(core)
        _BOUND[core.__name__] = types.SimpleNamespace(
            **{name: getattr(module, name) for name in ("rk4", "interpolant_events",
                                                        "first_crossing", "illinois")})
    return _BOUND[core.__name__]
