"""Sweep kernel benchmark, old against new in one run (issue 11, "Engine 2").

The old kernel is the sweep template and step core of git revision ``--old`` (default e8ac560:
blocks of one step count, 35 positional arguments), spliced and compiled exactly as
``geardyn.solvers.kernels`` does, and driven with its own calling convention (a copy of that
revision's ``run_plan`` below); the new one is the working tree's. Both run the same lanes through
``geardyn.solvers.ensemble.run_lanes`` (its ``kernels_for`` swapped), one after the other, in
this process, so the ratios are fair on a shared machine. Reports, per kernel and workload:
warm wall time (median of ``--repeat``), ns per lane-step per thread, located edge crossings
per lane-step (counted while sampling) and the cost per located crossing (time with edge
location minus time without, over the crossings of the whole run, estimated from the sampled
rate), and the largest difference of the section points, old against new.

    .venv/bin/python bench/kernel.py [--repeat 3] [--paper] [--old REV]
"""

from __future__ import annotations

import argparse
import hashlib
import importlib.util
import re
import statistics
import subprocess
import sys
import time
import types
from pathlib import Path

import numba
import numpy as np

import geardyn
import geardyn.solvers.ensemble as ens
from geardyn.core.plan import LanePlan, LaneSettings
from geardyn.core.settings import RunSettings
from geardyn.solvers import kernels as kmod

ROOT = Path(__file__).resolve().parents[1]
OLD_REV = "e8ac560"


def _git_show(rev: str, path: str) -> str:
    return subprocess.run(["git", "show", f"{rev}:{path}"], cwd=ROOT, check=True,
                          capture_output=True, text=True).stdout


def old_kernels(source: kmod.KernelSource, rev: str, template: str = "rk4"):
    """The kernel module of ``template`` (``rk4``: the sweep's, or ``lyapunov``) of revision
    ``rev`` for a model (compiled, cached on disk)."""
    path = kmod.TEMPLATES[template].replace(".", "/")
    tmpl = _git_show(rev, f"src/{path}.py")
    core = [ln for ln in _git_show(rev, "src/geardyn/solvers/_step_core.py").splitlines()
            if not ln.startswith("from __future__")]
    lines = tmpl.splitlines()
    k = next(i for i, ln in enumerate(lines) if ln.rstrip().endswith(kmod._CORE_MARK))
    end = k
    while ")" not in lines[end]:
        end += 1
    if source.one_form is not None:  # the model's layouts, generated from its one form
        marks = [i for i, ln in enumerate(core) if ln.startswith("# MODEL-ADAPTERS")]
        if not marks:
            raise ValueError(f"revision {rev} predates the one model form: a one-form model "
                             "cannot run on its kernels")
        core = [*core[:marks[0]], kmod._adapters(source, False), *core[marks[0]:]]
    text = "\n".join([*lines[:k], *core, *lines[end + 1:]]) + "\n"
    funcs = source.functions()
    funcs.update(_old_lane_functions(funcs, rev))
    code = kmod._replace_import(text, kmod._import_line(funcs))
    name = f"geardyn_{template}old_" + hashlib.sha256(code.encode()).hexdigest()[:16]
    folder = kmod.cache_dir()
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name}.py"
    if not path.exists():
        path.write_text(code)
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def _old_schedule(n_per: np.ndarray, periods: np.ndarray, block: int):
    """e8ac560's ``ensemble._schedule``: lockstep blocks of one step count over lanes sorted by
    it, longest block first to the least loaded worker."""
    workers = numba.get_num_threads()
    first, nl, nper, cost = [], [], [], []
    L = n_per.size
    a = 0
    while a < L:
        b = a + 1
        while b < L and b - a < block and n_per[b] == n_per[a]:
            b += 1
        first.append(a)
        nl.append(b - a)
        nper.append(int(n_per[a]))
        cost.append(float(np.max(periods[a:b])) * int(n_per[a]) * (b - a + block) / 2)
        a = b
    load = np.zeros(workers)
    assigned: list[list[int]] = [[] for _ in range(workers)]
    for blk in np.argsort(cost, kind="stable")[::-1]:
        w = int(np.argmin(load))
        assigned[w].append(int(blk))
        load[w] += cost[blk]
    start = np.cumsum([0] + [len(x) for x in assigned]).astype(np.int64)
    blocks = np.array([b for x in assigned for b in x], dtype=np.int64)
    return (np.array(first, np.int64), np.array(nl, np.int64), np.array(nper, np.int64), start,
            blocks)


def old_run_plan(k):
    """e8ac560's ``ensemble.run_plan`` bound to the kernel module ``k`` (old calling
    convention: 35 positional arguments, lanes reordered by step count)."""

    def run_plan(model, P, y0, plan, converge_depth=16, **_):
        P = np.ascontiguousarray(np.atleast_2d(P), dtype=float)
        L = P.shape[0]
        ns = model.n_states
        Y0 = np.ascontiguousarray(np.broadcast_to(np.asarray(y0, dtype=float), (L, ns)))
        run = plan.settings
        samples = run.samples
        n_lane, period, every = plan.steps_per_period, plan.period, plan.sample_every
        n_ev, n_obs = model.n_events, model.n_observables
        out = ens.LaneResults(
            samples=np.full((L, samples, ns), np.nan), final=np.full((L, ns), np.nan),
            final_time=np.zeros(L), status=np.zeros(L, np.int64),
            event_min=np.zeros((L, n_ev)), event_max=np.zeros((L, n_ev)),
            crossings=np.zeros((L, n_ev), np.int64), obs_max=np.zeros((L, n_obs)),
            obs_min=np.zeros((L, n_obs)), obs_rms=np.zeros((L, n_obs)),
            unresolved=np.zeros(L, np.int64), steps_per_period=n_lane,
            transient_periods=plan.transient_periods.copy(),
            converged=np.full(L, -1, np.int64), sample_every=every.copy(),
            commensurate=plan.commensurate.copy(), steps=np.zeros(L, np.int64))
        order = np.lexsort((period, n_lane))
        first, nl, nper, w_start, w_blocks = _old_schedule(n_lane[order],
                                                           plan.total_periods[order], k.BLOCK)
        s_parts, c_parts, tab_of, pos = [], [], {}, 0
        for n in np.unique(n_lane):
            s, c = k.phase_table(int(n), True)
            tab_of[int(n)] = pos
            s_parts.append(s)
            c_parts.append(c)
            pos += s.size
        s_tab, c_tab = np.concatenate(s_parts), np.concatenate(c_parts)
        tr_steps = np.empty(L, np.int64)
        conv = np.empty(L, np.int64)
        smp = np.empty((L, samples, ns))
        fin = np.empty((L, ns))
        st = np.empty(L, np.int64)
        gmin, gmax = np.empty((L, n_ev)), np.empty((L, n_ev))
        nc = np.empty((L, n_ev), np.int64)
        omax, omin, orms = np.empty((L, n_obs)), np.empty((L, n_obs)), np.empty((L, n_obs))
        unres = np.empty(L, np.int64)
        k.sweep(P[order], Y0[order], plan.step[order], plan.omega[order], plan.t0[order],
                plan.transient_steps[order], plan.transient_max_steps[order],
                float(run.converge_tol), int(converge_depth), int(samples),
                plan.sample_steps[order], bool(run.locate_edges), float(run.bound), n_ev,
                n_obs, first, nl, nper, np.array([tab_of[int(n)] for n in nper], np.int64),
                s_tab, c_tab, w_start, w_blocks, smp, fin, st, gmin, gmax, nc, omax, omin,
                orms, unres, tr_steps, conv)
        for name, v in (("samples", smp), ("final", fin), ("status", st), ("event_min", gmin),
                        ("event_max", gmax), ("crossings", nc), ("obs_max", omax),
                        ("obs_min", omin), ("obs_rms", orms), ("unresolved", unres),
                        ("converged", conv)):
            getattr(out, name)[order] = v
        out.transient_periods[order] = tr_steps // n_lane[order]
        out.final_time = plan.final_time(out.transient_periods)
        return out

    return run_plan


class _Use:
    """Within the block, the ensemble runs with kernel module ``mod`` (and, for the old kernel,
    the old ``run_plan``)."""

    def __init__(self, mod, old: bool):
        self.mod, self.old = mod, old

    def __enter__(self):
        ens.kernels_for = lambda src, template="rk4": self.mod
        if self.old:
            ens.run_plan = old_run_plan(self.mod)

    def __exit__(self, *exc):
        ens.kernels_for = kmod.kernels_for
        ens.run_plan = _NEW_RUN_PLAN


_NEW_RUN_PLAN = ens.run_plan


def _load_file(name: str, text: str) -> types.ModuleType:
    """The module ``name`` of source ``text``, written to the kernel cache folder and imported
    (registered in ``sys.modules``, so that a kernel file can import it by name)."""
    if name in sys.modules:
        return sys.modules[name]
    folder = kmod.cache_dir()
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name}.py"
    if not path.exists():
        path.write_text(text)
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def _old_lane_functions(funcs: dict, rev: str) -> dict:
    """The model's lane-block functions as revision ``rev`` had them (their forcing-phase
    arguments changed from scalars to arrays since), from a copy of that revision's module."""
    out = {}
    for alias in ("rhs_lanes", "events_lanes", "observe_lanes"):
        if alias not in funcs:
            continue
        py = funcs[alias].py_func
        text = _git_show(rev, "src/" + py.__module__.replace(".", "/") + ".py")
        name = "geardyn_oldmodel_" + hashlib.sha256(text.encode()).hexdigest()[:16]
        out[alias] = getattr(_load_file(name, text), py.__name__)
    return out


class Workload:
    def __init__(self, name, model, omegas, transient_periods, samples, n_per):
        self.name = name
        self.model = model
        self.P = model.lane_params("Omega", omegas)
        self.omegas = np.asarray(omegas, float)
        self.transient = transient_periods * 2 * np.pi / self.omegas  # whole periods per lane
        self.samples = samples
        self.n_per = n_per  # None: automatic

    def run(self, locate: bool = True):
        return ens.run_lanes(self.model, self.P, self.model.initial_state(),
                             run=RunSettings(samples=self.samples, locate_edges=locate),
                             lanes=LaneSettings(transient=self.transient,
                                                steps_per_period=self.n_per, sample_every=1))


def lane_steps(r) -> tuple[int, int]:
    """(all lane-steps, lane-steps while sampling) of a run_lanes result."""
    n = r.steps_per_period.astype(np.int64)
    samp = int(np.sum(r.samples.shape[1] * r.sample_every * n))
    return int(np.sum(r.transient_periods * n)) + samp, samp


def timed(fn, repeat):
    times, out = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times), out


def measure(w: Workload, mod, repeat: int, old: bool) -> dict:
    with _Use(mod, old):
        w.run()  # compile / load
        t_on, r = timed(w.run, repeat)
        t_off, _ = timed(lambda: w.run(False), repeat)
    steps, samp = lane_steps(r)
    threads = numba.get_num_threads()
    rate = float(np.sum(r.crossings)) / samp
    n_cross = rate * steps
    return dict(t=t_on, t_off=t_off, steps=steps, rate=rate,
                ns=t_on * threads / steps * 1e9, ns_off=t_off * threads / steps * 1e9,
                ns_cross=(t_on - t_off) * threads / max(n_cross, 1.0) * 1e9, r=r)


def paper_workload(mod, repeat: int, old: bool):
    """Warm time of the paper's reference workload and its section points."""
    model = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05))
    values = np.linspace(0.1, 4.0, 1000)
    with _Use(mod, old):
        geardyn.bifurcation(model, "Omega", values[:4],
                            run=geardyn.RunSettings(transient=20.0, samples=2))
        run = geardyn.RunSettings(transient=2000.0, samples=200)
        t, ds = timed(lambda: geardyn.bifurcation(model, "Omega", values, run), repeat)
    return t, ds


def fresh_kernels(source: kmod.KernelSource) -> types.ModuleType:
    """The working tree's sweep kernel module compiled in memory (numba does not show the
    assembly of cached code)."""
    code = kmod._replace_import(kmod._template_text("rk4"), "pass  " + kmod._IMPORT_MARK)
    module = types.ModuleType("geardyn_rk4_fresh")
    module.__dict__.update(source.functions())
    exec(compile(code.replace("_CACHE = True", "_CACHE = False"), module.__name__, "exec"),
         module.__dict__)
    return module


def vector_report(w: Workload) -> str:
    """Packed double-precision instructions in the compiled sweep kernel (zmm: 8 doubles, ymm:
    4), scalar ones (sd), and packed fused multiply-adds (none: no contraction)."""
    mod = fresh_kernels(w.model.kernel)
    with _Use(mod, False):
        ens.run_lanes(w.model, w.P[:8], w.model.initial_state(),
                      run=RunSettings(transient=1.0, samples=1, steps_per_period=64))
    fn = getattr(mod, "_block_run", getattr(mod, "_sweep_worker", mod.sweep))  # the block loop
    asm = fn.inspect_asm(fn.signatures[0])
    z, y, sd = (len(re.findall(r"\n\s+v\w+" + r, asm))
                for r in (r"pd\s+[^\n]*%zmm", r"pd\s+[^\n]*%ymm", r"sd\s"))
    fma = len(re.findall(r"vfmadd\w*pd", asm))
    ops = sorted({m for m in re.findall(r"\n\s+(v\w+pd)\s+[^\n]*%zmm", asm)})
    return (f"{w.name}: {z} zmm / {y} ymm packed-double and {sd} scalar-double instructions, "
            f"{fma} packed FMA; "
            f"zmm ops: {' '.join(ops)}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--paper", action="store_true", help="also the paper's reference workload")
    ap.add_argument("--old", default=OLD_REV, help="git revision of the old kernel")
    ap.add_argument("--lanes", type=int, default=256)
    ap.add_argument("--asm", action="store_true", help="also inspect the new kernel's assembly")
    ap.add_argument("--paper-only", action="store_true", help="only the paper's workload")
    args = ap.parse_args()
    catt = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05))
    gp = geardyn.GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
    works = [
        Workload("reduced CATT (4 states, 4 edges), default steps", catt,
                 np.linspace(0.1, 4.0, args.lanes), 100, 50, None),
        Workload("gear pair (2 states, 2 edges), 128 steps/period", gp,
                 np.linspace(0.2, 3.0, args.lanes), 400, 100, 128),
    ]
    print(f"# geardyn {geardyn.__version__}, numba {numba.__version__}, "
          f"{numba.get_num_threads()} threads; old kernel: {args.old}; median of {args.repeat}; "
          f"SIMD {geardyn._jit_target.APPLIED.split(':')[0]}")
    print("| workload | kernel | wall [s] | ns/lane-step/thread | same, no edge location "
          "| crossings/lane-step | ns/located crossing |")
    print("|---|---|---|---|---|---|---|")
    for w in [] if args.paper_only else works:
        old = old_kernels(w.model.kernel, args.old)
        new = kmod.kernels_for(w.model.kernel)
        res = {}
        for label, mod in (("old", old), ("new", new)):
            m = measure(w, mod, args.repeat, label == "old")
            res[label] = m
            print(f"| {w.name} | {label} | {m['t']:.3f} | {m['ns']:.1f} | {m['ns_off']:.1f} | "
                  f"{m['rate']:.2e} | {m['ns_cross']:.0f} |")
        a, b = res["old"]["r"], res["new"]["r"]
        scale = np.nanmax(np.abs(a.samples))
        diff = np.nanmax(np.abs(a.samples - b.samples)) / scale
        same_cross = np.array_equal(a.crossings, b.crossings)
        print(f"|  | new/old | {res['new']['t'] / res['old']['t']:.3f} | "
              f"{res['new']['ns'] / res['old']['ns']:.3f} | "
              f"{res['new']['ns_off'] / res['old']['ns_off']:.3f} | max rel. diff of the "
              f"section points {diff:.1e}, crossings equal: {same_cross} | |")
    if args.asm:
        for w in works:
            print(vector_report(w))
    if args.paper or args.paper_only:
        model = catt
        old = old_kernels(model.kernel, args.old)
        new = kmod.kernels_for(model.kernel)
        t_old, ds_old = paper_workload(old, args.repeat, True)
        t_new, ds_new = paper_workload(new, args.repeat, False)
        same = all(np.array_equal(ds_old[v].values, ds_new[v].values, equal_nan=True)
                   for v in ("poincare", "status", "period"))
        plan = LanePlan.build(model, model.lane_params("Omega", np.linspace(0.1, 4.0, 1000)),
                              RunSettings(transient=2000.0, samples=200))
        steps = float(np.sum(plan.total_periods * plan.steps_per_period))
        per = numba.get_num_threads() * 1e9 / steps
        print(f"\npaper reference workload (1000 Omega in [0.1, 4], transient 2000, 200 samples, "
              f"xi = 0.05): old {t_old:.2f} s ({t_old * per:.1f} ns/lane-step/thread), new "
              f"{t_new:.2f} s ({t_new * per:.1f}), new/old {t_new / t_old:.3f}; section "
              f"points, status and period bitwise equal: {same}")


if __name__ == "__main__":
    main()
