"""geardyn against its peers on one workload, all measured in one run (issue 11).

Workload: the single gear pair ``GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)``, 400 values of
Omega in [0.2, 3], from the model's initial state at t = 0, a transient of ``TRANSIENT`` time
units rounded up to whole forcing periods in every lane (geardyn's rule; 500 pi is 400 periods
at the middle of the range, 160 000 transient periods in all, 50 to 750 per lane), then 100
sampled periods (one Poincare point at the end of each).

Rows (wall time: median of ``--repeat`` warm runs unless the row says otherwise; the full-sweep
rows 1-3 are timed round-robin, one run of each per round):

1. ``geardyn.bifurcation`` at 128 steps per period and at its default step (edges located);
2. a plain numba RK4 kernel written here (``rk4_lanes``: ``prange`` over Omega, no edge
   location, the right-hand side written out independently of geardyn), at 128 steps per
   period, and the same with a forcing-phase table (``rk4_lanes_table``);
3. the plain kernel at the step it needs for an error of ``TARGET`` (doubling from 128);
4. SciPy LSODA (``solve_ivp``) with a numba-compiled right-hand side at the loosest tolerance
   (rtol = atol, decades) that reaches ``TARGET``;
5. diffrax (JAX, CPU, Tsit5 and Dopri8 with a PID controller) likewise, and numbalsoda when
   it is installed.

Rows 4-5 are timed on every ``--every``-th point (40 of 400) and extrapolated to the 400 points
by the number of points (stated in the table). The error of every row: the largest absolute
deviation of its Poincare points (x and v, all 100 samples) from ``geardyn.solvers.reference``
(DOP853, rtol 1e-12, restarted at every located edge crossing) on the same subset of ``SUBSET``
Omega values (periodic motions spread over the range; the reference is cached under the
geardyn cache dir).

    .venv/bin/python bench/peers.py [--repeat 3] [--write] [--skip diffrax,lsoda,...]
"""

from __future__ import annotations

import argparse
import datetime
import hashlib
import importlib
import math
import os
import platform
import re
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numba as nb
import numpy as np

# geardyn's kernels get geardyn's vector width (geardyn._jit_target: 512-bit vectors by default)
# on their own; the plain numba functions here get LLVM's choice for the CPU (256 bits on most
# Intel server CPUs with AVX-512, 512 on AMD Zen 4 and 5)
import geardyn  # noqa: E402, I001

OMEGA_RANGE = (0.2, 3.0)
POINTS = 400
TRANSIENT = 500.0 * math.pi  # time units; 400 forcing periods at Omega = 1.6
SAMPLES = 100
STEPS = 128
TARGET = 1e-6
#: Omega values of the error subset (the nearest grid points are used): periodic motions away
#: from the period doublings and the chaotic band 1.2 < Omega < 1.63 (where no two integrators
#: agree after hundreds of periods, whatever their accuracy)
SUBSET = (0.3, 0.55, 0.75, 0.95, 1.06, 1.7, 2.2, 2.8)
COEFFS = dict(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)
RESULTS = Path(__file__).with_name("RESULTS.md")
_JIT = {"cache": True, "error_model": "numpy", "boundscheck": False}


@dataclass(frozen=True)
class Workload:
    """The sweep: Omega per lane, transient and sampled periods per lane, the error subset."""

    omega: np.ndarray  # (L,)
    n_tr: np.ndarray  # (L,) transient forcing periods
    samples: int
    subset: np.ndarray  # indices into omega

    @property
    def periods(self) -> np.ndarray:
        """Forcing periods integrated per lane."""
        return self.n_tr + self.samples

    def sample_times(self, i: int) -> np.ndarray:
        """Times of lane ``i``'s Poincare points (ends of the sampled periods)."""
        T = 2.0 * math.pi / self.omega[i]
        return (self.n_tr[i] + np.arange(1, self.samples + 1)) * T

    def take(self, idx: np.ndarray) -> Workload:
        """The lanes ``idx`` as a workload of their own (all of them the error subset)."""
        return Workload(self.omega[idx], self.n_tr[idx], self.samples, np.arange(idx.size))


def workload(points: int = POINTS, transient: float = TRANSIENT,
             samples: int = SAMPLES) -> Workload:
    """The benchmark sweep, transients rounded up to whole periods as geardyn does."""
    omega = np.linspace(*OMEGA_RANGE, points)
    n_tr = np.ceil(transient / (2.0 * math.pi / omega) - 1e-9).astype(np.int64)
    subset = np.unique([int(np.argmin(np.abs(omega - w))) for w in SUBSET])
    return Workload(omega, n_tr, samples, subset)


def model():
    return geardyn.GearPair(**COEFFS)


def initial_state() -> np.ndarray:
    """The model's initial state (static deflection under the mean load, at rest)."""
    return np.asarray(model().initial_state(), dtype=float)


# ---------------------------------------------------------------------------------------------
# The plain peer: RK4, one lane per Omega, prange, no edge location
#   x'' + 2 zeta x' + (1 + kappa cos(Omega t)) g(x) = Fm + Fa Omega^2 cos(Omega t),
#   g(x) = x - b (x > b), x + b (x < -b), 0 otherwise


@nb.njit(inline="always", **_JIT)
def _accel(x, v, c, zeta, kappa, fm, fa_om2, b):
    """x'' of the gear pair at forcing phase cosine ``c`` (fa_om2 = Fa Omega^2)."""
    g = x - b if x > b else (x + b if x < -b else 0.0)
    return fm + fa_om2 * c - 2.0 * zeta * v - (1.0 + kappa * c) * g


@nb.njit(inline="always", **_JIT)
def _rk4_step(x, v, h, c0, ch, c1, zeta, kappa, fm, fa_om2, b):
    """One classical RK4 step of (x, v) with the forcing cosines at the step's start, middle
    and end."""
    k1x = v
    k1v = _accel(x, v, c0, zeta, kappa, fm, fa_om2, b)
    k2x = v + 0.5 * h * k1v
    k2v = _accel(x + 0.5 * h * k1x, k2x, ch, zeta, kappa, fm, fa_om2, b)
    k3x = v + 0.5 * h * k2v
    k3v = _accel(x + 0.5 * h * k2x, k3x, ch, zeta, kappa, fm, fa_om2, b)
    k4x = v + h * k3v
    k4v = _accel(x + h * k3x, k4x, c1, zeta, kappa, fm, fa_om2, b)
    x = x + h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x)
    v = v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v)
    return x, v


@nb.njit(parallel=True, **_JIT)
def rk4_lanes(omega, n_tr, samples, n_steps, coef, y0, out):
    """Integrate one lane per ``omega[i]`` from ``y0`` (x, v) at t = 0 with ``n_steps`` RK4
    steps per forcing period: ``n_tr[i]`` periods of transient, then ``samples`` periods whose
    end states go to ``out[i, k]`` (x, v). ``coef`` = (zeta, kappa, Fm, Fa, b). The forcing
    cosine is evaluated at every stage time (t = step index x h, no accumulated time)."""
    zeta, kappa, fm, fa, b = coef[0], coef[1], coef[2], coef[3], coef[4]
    for i in nb.prange(omega.size):
        om = omega[i]
        h = 2.0 * math.pi / om / n_steps
        fa_om2 = fa * om * om
        x, v = y0[0], y0[1]
        k = 0
        c0 = 1.0
        for p in range(n_tr[i] + samples):
            for _ in range(n_steps):
                t = k * h
                ch = math.cos(om * (t + 0.5 * h))
                c1 = math.cos(om * (t + h))
                x, v = _rk4_step(x, v, h, c0, ch, c1, zeta, kappa, fm, fa_om2, b)
                c0 = c1
                k += 1
            s = p - n_tr[i]
            if s >= 0:
                out[i, s, 0] = x
                out[i, s, 1] = v


@nb.njit(parallel=True, **_JIT)
def rk4_lanes_table(omega, n_tr, samples, n_steps, coef, y0, out):
    """:func:`rk4_lanes` with the forcing cosine from a table of the ``2 n_steps`` half-step
    phases of one period, shared by every lane (the phase at step k depends only on k mod n)."""
    zeta, kappa, fm, fa, b = coef[0], coef[1], coef[2], coef[3], coef[4]
    tab = np.empty(2 * n_steps + 1)
    for j in range(2 * n_steps + 1):
        tab[j] = math.cos(math.pi * j / n_steps)
    for i in nb.prange(omega.size):
        om = omega[i]
        h = 2.0 * math.pi / om / n_steps
        fa_om2 = fa * om * om
        x, v = y0[0], y0[1]
        for p in range(n_tr[i] + samples):
            for j in range(n_steps):
                x, v = _rk4_step(x, v, h, tab[2 * j], tab[2 * j + 1], tab[2 * j + 2],
                                 zeta, kappa, fm, fa_om2, b)
            s = p - n_tr[i]
            if s >= 0:
                out[i, s, 0] = x
                out[i, s, 1] = v


def coefficients() -> np.ndarray:
    """(zeta, kappa, Fm, Fa, backlash) of the benchmark model (phases are zero)."""
    m = model()
    named = m.coefficient_values()
    if named["kappa_phase"] or named["error_phase"]:
        raise ValueError("the plain kernel assumes zero forcing phases")
    return np.array([named[k] for k in ("zeta", "kappa", "Fm", "Fa", "backlash")])


def run_rk4(wl: Workload, n_steps: int, table: bool = False) -> np.ndarray:
    """Poincare points (L, samples, 2) of the plain RK4 kernel; lanes dealt dynamically to the
    threads one at a time (their lengths differ 15-fold)."""
    out = np.full((wl.omega.size, wl.samples, 2), np.nan)
    kernel = rk4_lanes_table if table else rk4_lanes
    with nb.parallel_chunksize(1):
        kernel(wl.omega, wl.n_tr, wl.samples, n_steps, coefficients(), initial_state(), out)
    return out


# ---------------------------------------------------------------------------------------------
# Reference and error


def reference(wl: Workload, cache: Path | None = None) -> np.ndarray:
    """Poincare points (len(subset), samples, 2) from geardyn's reference integrator (DOP853,
    rtol = atol = 1e-12, restarted at every located edge crossing), cached on disk."""
    from geardyn.solvers.reference import reference_solution

    key = hashlib.sha1(repr((COEFFS, wl.omega[wl.subset].tolist(), wl.n_tr[wl.subset].tolist(),
                             wl.samples)).encode()).hexdigest()[:16]
    path = (cache or _cache_dir()) / f"peers-reference-{key}.npy"
    if path.exists():
        return np.load(path)
    m = model()
    rows = []
    for i in wl.subset:
        lane = m.with_params(Omega=float(wl.omega[i]))
        rows.append(reference_solution(lane, initial_state(), wl.sample_times(int(i)),
                                       rtol=1e-12, atol=1e-12))
    ref = np.array(rows)
    path.parent.mkdir(parents=True, exist_ok=True)
    np.save(path, ref)
    return ref


def _cache_dir() -> Path:
    from geardyn._cache import cache_root

    return cache_root()


def max_error(points: np.ndarray, ref: np.ndarray) -> float:
    """Largest |point - reference| over lanes, samples and both states (inf if any NaN)."""
    d = np.abs(np.asarray(points, dtype=float) - ref)
    return float(np.max(d)) if np.all(np.isfinite(d)) else math.inf


# ---------------------------------------------------------------------------------------------
# Rows


@dataclass
class Row:
    """One line of the table."""

    method: str
    setting: str
    wall: float | None = None  # seconds for the 400-point workload (measured or extrapolated)
    times: tuple[float, ...] = ()
    lane_steps: float | None = None
    error: float | None = None
    note: str = ""
    key: str = ""  # g128, gdef, rk4, rk4tab, rk4acc, or a PEERS key

    @property
    def ns_per_lane_step(self) -> float | None:
        if self.wall is None or not self.lane_steps:
            return None
        return self.wall / self.lane_steps * 1e9


def timed(fn: Callable[[], object], repeat: int) -> tuple[float, tuple[float, ...], object]:
    """Median wall time of ``repeat`` calls of ``fn`` (after none: warm it yourself)."""
    times, result = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times), tuple(times), result


@dataclass
class Sweep:
    """A full-sweep row to be timed: ``run()`` does the work, ``finish(row, result)`` fills in
    the error and notes from the last result."""

    row: Row
    run: Callable[[], object]
    finish: Callable[[Row, object], None]


def measure(sweeps: list[Sweep], repeat: int) -> list[Row]:
    """Time every sweep ``repeat`` times, round-robin (one call of each per round, so that a
    change of the machine's load hits every row alike); the rows with medians filled in."""
    times: list[list[float]] = [[] for _ in sweeps]
    last: list[object] = [None] * len(sweeps)
    for _ in range(repeat):
        for k, sw in enumerate(sweeps):
            t = time.perf_counter()
            last[k] = sw.run()
            times[k].append(time.perf_counter() - t)
    for k, sw in enumerate(sweeps):
        sw.row.wall, sw.row.times = statistics.median(times[k]), tuple(times[k])
        sw.finish(sw.row, last[k])
    return [sw.row for sw in sweeps]


def geardyn_sweeps(wl: Workload, ref: np.ndarray) -> list[Sweep]:
    """geardyn.bifurcation at 128 steps per period and at its default step (warmed)."""
    m = model()
    out = []
    for n, label in ((STEPS, f"{STEPS} steps/period"), (None, "default step")):
        def run(n=n):
            return geardyn.bifurcation(m, "Omega", wl.omega, run=geardyn.RunSettings(
                transient=TRANSIENT, samples=wl.samples, steps_per_period=n))

        def finish(row: Row, ds, n=n) -> None:
            if not np.array_equal(ds["transient_periods"].values, wl.n_tr):
                raise RuntimeError("geardyn's transient periods differ from the workload's")
            spp = ds["steps_per_period"].values.astype(float)
            row.lane_steps = float(np.sum(wl.periods * spp))
            row.error = max_error(ds["poincare"].values[wl.subset], ref)
            if n is None:
                row.note += f"; {int(spp.min())}-{int(spp.max())} steps/period"
            bad = int(np.sum(ds["status"].values != 0))  # the status attribute: 0 means ok
            if bad:
                row.note += f"; {bad} lanes not ok"

        geardyn.bifurcation(m, "Omega", wl.omega[:4], run=geardyn.RunSettings(
            transient=10.0, samples=2, steps_per_period=n))  # compile or load the kernel
        out.append(Sweep(Row("geardyn.bifurcation", label, note="edges located",
                             key="g128" if n else "gdef"), run, finish))
    return out


def rk4_sweeps(wl: Workload, ref: np.ndarray, max_steps: int) -> tuple[list[Sweep], list[Row]]:
    """The plain kernel at 128 steps (with and without a phase table) and at the step that
    reaches TARGET (found by doubling on the subset); a row without timing when none does."""
    sub = wl.take(wl.subset)
    run_rk4(sub, 8)  # compile or load
    run_rk4(sub, 8, table=True)

    def finish_for(n: int) -> Callable[[Row, object], None]:
        def finish(row: Row, pts) -> None:
            row.lane_steps = float(np.sum(wl.periods) * n)
            row.error = max_error(pts[wl.subset], ref)
        return finish

    sweeps = [Sweep(Row(name, f"{STEPS} steps/period", note="no edge location",
                        key="rk4tab" if table else "rk4"),
                    lambda table=table: run_rk4(wl, STEPS, table), finish_for(STEPS))
              for table, name in ((False, "numba RK4, prange"),
                                  (True, "numba RK4, prange, phase table"))]
    n, errs = STEPS, {}
    while True:
        errs[n] = max_error(run_rk4(sub, n, table=True), ref)
        if errs[n] <= TARGET or 2 * n > max_steps:
            break
        n *= 2
    trail = ", ".join(f"{k}: {e:.1e}" for k, e in errs.items())
    name = "numba RK4, prange, phase table"
    if errs[n] > TARGET:
        return sweeps, [Row(name, f"{n} steps/period", error=errs[n], key="rk4acc",
                            note=f"{TARGET:g} not reached by {max_steps} steps/period "
                                 f"({trail})")]
    sweeps.append(Sweep(Row(name, f"{n} steps/period (for {TARGET:g})", key="rk4acc",
                            note=f"doubling from {STEPS} on the subset: {trail}"),
                        lambda: run_rk4(wl, n, table=True), finish_for(n)))
    return sweeps, []


def tolerance_row(name: str, solve: Callable[[Workload, float], np.ndarray], wl: Workload,
                  ref: np.ndarray, repeat: int, tolerances, note: str, every: int) -> Row:
    """The loosest rtol (= atol) of ``tolerances`` whose Poincare points on the error subset
    are within TARGET of the reference; its time on every ``every``-th point of the sweep
    (median of ``repeat``), extrapolated to the whole sweep by the number of points."""
    sub = wl.take(wl.subset)
    trail = []
    for tol in tolerances:
        err = max_error(solve(sub, tol), ref)
        trail.append(f"{tol:g}: {err:.1e}")
        if err <= TARGET:
            part = wl.take(np.arange(0, wl.omega.size, every))
            wall, times, _ = timed(lambda tol=tol, part=part: solve(part, tol), repeat)
            scale = wl.omega.size / part.omega.size
            return Row(name, f"rtol = atol = {tol:g}", wall * scale, times, None, err,
                       f"{note}; timed on every {every}th point ({part.omega.size}), x "
                       f"{scale:g}; tolerance search: {'; '.join(trail)}")
    return Row(name, f"rtol = atol = {tolerances[-1]:g}", error=err,
               note=f"{TARGET:g} not reached ({'; '.join(trail)})")


@nb.njit(**_JIT)
def gear_rhs(t, y, om, coef):
    """The gear pair's right-hand side for SciPy (a new array)."""
    dy = np.empty(2)
    dy[0] = y[1]
    dy[1] = _accel(y[0], y[1], math.cos(om * t), coef[0], coef[1], coef[2],
                   coef[3] * om * om, coef[4])
    return dy


def solve_lsoda(wl: Workload, tol: float) -> np.ndarray:
    """Poincare points of every lane from scipy's LSODA (one lane after another; the points
    from its dense output at the sample times, as ``t_eval`` gives them)."""
    from scipy.integrate import solve_ivp

    coef, y0 = coefficients(), initial_state()
    out = np.full((wl.omega.size, wl.samples, 2), np.nan)
    for i, om in enumerate(wl.omega):
        ts = wl.sample_times(i)
        sol = solve_ivp(gear_rhs, (0.0, ts[-1]), y0, method="LSODA", t_eval=ts, rtol=tol,
                        atol=tol, args=(float(om), coef))
        if sol.status == 0:
            out[i] = sol.y.T
    return out


def diffrax_solver(method: str = "Tsit5") -> Callable[[Workload, float], np.ndarray]:
    """A function (workload, tol) -> Poincare points from diffrax (``method``: a diffrax
    solver's name; PID controller, float64, one jitted solve per lane, points from the
    solver's interpolant at ``ts``)."""
    import jax

    jax.config.update("jax_enable_x64", True)
    import diffrax
    import jax.numpy as jnp

    coef = tuple(float(c) for c in coefficients())
    solver = getattr(diffrax, method)()

    def field(t, y, om):
        zeta, kappa, fm, fa, b = coef
        x, v = y[0], y[1]
        c = jnp.cos(om * t)
        g = jnp.where(x > b, x - b, jnp.where(x < -b, x + b, 0.0))
        return jnp.stack([v, fm + fa * om * om * c - 2.0 * zeta * v - (1.0 + kappa * c) * g])

    @jax.jit
    def one(om, ts, y0, tol):
        ctrl = diffrax.PIDController(rtol=tol, atol=tol)
        sol = diffrax.diffeqsolve(diffrax.ODETerm(field), solver, 0.0, ts[-1], None,
                                  y0, args=om, saveat=diffrax.SaveAt(ts=ts),
                                  stepsize_controller=ctrl, max_steps=2**22,
                                  adjoint=diffrax.ForwardMode(), throw=False)
        return sol.ys, sol.result == diffrax.RESULTS.successful

    def solve(wl: Workload, tol: float) -> np.ndarray:
        out = np.full((wl.omega.size, wl.samples, 2), np.nan)
        y0 = jnp.asarray(initial_state())
        for i, om in enumerate(wl.omega):
            ys, ok = one(float(om), jnp.asarray(wl.sample_times(i)), y0, tol)
            if bool(ok):
                out[i] = np.asarray(ys)
        return out

    return solve


def numbalsoda_solver() -> Callable[[Workload, float], np.ndarray]:
    """A function (workload, tol) -> Poincare points from numbalsoda's LSODA with a numba
    cfunc right-hand side."""
    from numbalsoda import lsoda, lsoda_sig

    coef = coefficients()
    zeta, kappa, fm, fa, b = (float(c) for c in coef)

    @nb.cfunc(lsoda_sig)
    def rhs(t, u, du, p):
        om = p[0]
        du[0] = u[1]
        du[1] = _accel(u[0], u[1], math.cos(om * t), zeta, kappa, fm, fa * om * om, b)

    ptr = rhs.address

    def solve(wl: Workload, tol: float) -> np.ndarray:
        out = np.full((wl.omega.size, wl.samples, 2), np.nan)
        y0 = initial_state()
        for i, om in enumerate(wl.omega):
            ts = np.concatenate([[0.0], wl.sample_times(i)])
            usol, ok = lsoda(ptr, y0, ts, data=np.array([om]), rtol=tol, atol=tol,
                             mxstep=10**8)
            if ok:
                out[i] = usol[1:]
        return out

    return solve


PEERS = {
    "lsoda": ("SciPy LSODA, numba rhs", lambda: solve_lsoda, "scipy"),
    "diffrax": ("diffrax Tsit5 (JAX, CPU)", diffrax_solver, "diffrax"),
    "diffrax8": ("diffrax Dopri8 (JAX, CPU)", lambda: diffrax_solver("Dopri8"), "diffrax"),
    "numbalsoda": ("numbalsoda LSODA, cfunc rhs", numbalsoda_solver, "numbalsoda"),
}


def peer_rows(wl: Workload, ref: np.ndarray, repeat: int, skip: set[str],
              every: int) -> list[Row]:
    """The adaptive peers that are installed (a row saying why for the others)."""
    rows = []
    tolerances = [10.0**-k for k in range(6, 13)]
    for key, (name, make, module) in PEERS.items():
        if key in skip:
            rows.append(Row(name, "-", note="skipped (--skip)", key=key))
            continue
        try:
            importlib.import_module(module)
        except ImportError as exc:
            print(f"{name}: not installed ({exc})")
            rows.append(Row(name, "-", note=f"not installed ({exc})", key=key))
            continue
        try:
            solve = make()
            solve(wl.take(wl.subset[:1]), 1e-3)  # compile / warm
            note = "adaptive, no event location"
            row = tolerance_row(name, solve, wl, ref, repeat, tolerances, note, every)
        except Exception as exc:  # a peer that breaks is a row that says so, not a crash
            row = Row(name, "-", note=f"failed: {type(exc).__name__}: {str(exc)[:200]}")
        row.key = key
        rows.append(row)
        print(_line(rows[-1]), flush=True)
    return rows


# ---------------------------------------------------------------------------------------------
# Report


def _fmt(x: float | None, spec: str) -> str:
    return "-" if x is None else format(x, spec)


def _line(r: Row) -> str:
    return f"{r.method} [{r.setting}]: {_fmt(r.wall, '.3f')} s, error {_fmt(r.error, '.1e')}"


def table(rows: list[Row], base: Row | None) -> str:
    """The markdown table; ``base``: the row the time ratio refers to."""
    head = ("| method | setting | wall [s] | ns per lane-step | max error | time / "
            f"{base.method if base else '-'} ({base.setting if base else '-'}) | notes |")
    lines = [head, "|---|---|---:|---:|---:|---:|---|"]
    for r in rows:
        ratio = (r.wall / base.wall) if (base and base.wall and r.wall) else None
        lines.append(f"| {r.method} | {r.setting} | {_fmt(r.wall, '.3f')} | "
                     f"{_fmt(r.ns_per_lane_step, '.1f')} | {_fmt(r.error, '.1e')} | "
                     f"{_fmt(ratio, '.2f')} | {' '.join(r.note.replace('|', '/').split())} |")
    return "\n".join(lines)


def targets(rows: list[Row]) -> list[str]:
    """The issue's two gear-pair targets, read off the rows."""
    by = {r.key: r for r in rows}
    g128, gdef = by["g128"], by["gdef"]
    out = []
    for key in ("rk4", "rk4tab"):
        r = by[key]
        out.append(f"geardyn at {STEPS} steps/period takes {g128.wall / r.wall:.2f}x the time of "
                   f"{r.method} at {STEPS} (target <= 0.33)")
    accurate = [r for r in (gdef, g128) if r.error is not None and r.error <= TARGET]
    if not accurate:
        return out + [f"geardyn reaches {TARGET:g} in neither row: no equal-accuracy ratio"]
    g = min(accurate, key=lambda r: r.wall)
    for key in ("rk4acc", *PEERS):
        r = by.get(key)
        if r is None or r.wall is None or r.error is None or r.error > TARGET:
            why = "no timing within the target error" if r is None else (r.note or "-")
            out.append(f"{r.method if r else key}: {why[:80]}")
            continue
        out.append(f"at {TARGET:g}: {r.method} ({r.setting}) takes {r.wall / g.wall:.1f}x the "
                   f"time of geardyn ({g.setting}) (target >= 5)")
    return out


def record_targets(rows: list[Row], command: str) -> None:
    """The two gear-pair targets in RESULTS.md's current-figures table."""
    import _results as results

    by = {r.key: r for r in rows}
    ratio = by["g128"].wall / by["rk4"].wall
    results.record("gear-pair-vs-rk4", f"gear pair at {STEPS} steps/period <= 1/3 of plain "
                   "numba RK4", f"{ratio:.2f}x ({by['g128'].wall:.3f} s against "
                   f"{by['rk4'].wall:.3f} s)", results.against(ratio, 1 / 3), command)
    lines = targets(rows)[2:]
    ratios = [float(m.group(1)) for m in (re.search(r"takes ([0-9.]+)x", s) for s in lines)
              if m]
    results.record("equal-accuracy", f"gear pair at equal accuracy ({TARGET:g}) >= 5x every "
                   "peer", "; ".join(lines),
                   results.against(min(ratios), 5.0, lower_is_better=False) if ratios
                   else "no peer measured",
                   command)


def machine() -> str:
    """Cores, CPU model, numba threads, versions, load average."""
    cpu = platform.processor() or platform.machine()
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, check=False).stdout
        found = re.search(r"Model name:\s*(.+)", out)
        cpu = found.group(1).strip() if found else cpu
    except OSError:
        pass
    load = os.getloadavg()
    return (f"{os.cpu_count()} cores, {cpu}, {platform.machine()}, Python "
            f"{platform.python_version()}, numpy {np.__version__}, numba {nb.__version__} with "
            f"{nb.config.NUMBA_NUM_THREADS} threads, SIMD "
            f"{geardyn._jit_target.APPLIED.split(':')[0]}; 1/5/15-min load average at the end "
            f"{load[0]:.2f}/{load[1]:.2f}/{load[2]:.2f}")


def write_section(text: str, path: Path = RESULTS) -> None:
    """Replace (or append) the ``## Peers`` section of RESULTS.md, keeping the rest."""
    old = path.read_text() if path.exists() else "# Benchmark results\n"
    pattern = re.compile(r"^## Peers\n.*?(?=^## |\Z)", re.S | re.M)
    section = text.rstrip() + "\n\n"
    new = pattern.sub(lambda _m: section, old) if pattern.search(old) else \
        old.rstrip() + "\n\n" + section
    path.write_text(new.rstrip() + "\n")


def section(rows: list[Row], base: Row | None, wl: Workload, command: str) -> str:
    """The ``## Peers`` section of RESULTS.md."""
    sub = ", ".join(f"{w:.3f}" for w in wl.omega[wl.subset])
    steps = float(np.sum(wl.periods)) * STEPS
    notes = [
        "The plain numba RK4 kernel (`bench/peers.py`: `rk4_lanes`, `rk4_lanes_table`) writes "
        "the gear pair's equations out independently of geardyn; `tests/test_bench_peers.py` "
        "checks it against the reference integrator. Its lanes go to the threads one at a time "
        "(`parallel_chunksize(1)`), as their lengths differ 15-fold. Without edge location its "
        "error falls only at about second order in the step (the kinks of the backlash "
        "function).",
        "geardyn and the plain kernel use both cores (2 numba threads). LSODA and diffrax run "
        "one lane after another in one process (a process pool would at best halve their times "
        "on 2 cores); they are timed on a uniform part of the sweep (the chaotic band included) "
        "and extrapolated to all points by the number of points. Their tolerance is the loosest "
        f"decade (rtol = atol) whose points on the error subset are within {TARGET:g}; the "
        "points come from the solver's dense output at the sample times (SciPy's `t_eval`, "
        "diffrax's `SaveAt(ts=...)`).",
    ]
    by = {r.key: r for r in rows}
    if by.get("numbalsoda") and by["numbalsoda"].note.startswith("not installed"):
        notes.append("numbalsoda: this machine's package index has only its source "
                     "distribution, which needs a Fortran compiler that is not installed, so "
                     "its row says \"not installed\" (the script runs it where it imports). "
                     "`make bench-peers` installs `.[bench]` (jax, diffrax) and tries "
                     "numbalsoda.")
    return f"""## Peers

Workload: `GearPair(zeta=0.05, kappa=0.2, Fm=0.1, Fa=0.2)`, {wl.omega.size} Omega in \
[{OMEGA_RANGE[0]:g}, {OMEGA_RANGE[1]:g}], from the initial state at t = 0; transient \
tau = {TRANSIENT:.1f} (500 pi) rounded up to whole periods in every lane \
({int(wl.n_tr.min())} to {int(wl.n_tr.max())} periods, {int(wl.n_tr.sum())} in all, \
{wl.n_tr.mean():.0f} per lane on average), then {wl.samples} sampled periods: \
{steps:.3e} lane-steps at {STEPS} steps per period.

Command: `{command}`, {datetime.date.today().isoformat()}.

Machine: {machine()}.

**Shared machine**: other jobs ran at the same time, so the absolute times are noisy (up to \
~3x between runs); every row was measured in the same run (median of the warm repeats unless \
the row says otherwise; the full-sweep rows round-robin, one run of each per round, so that a \
change of load hits them alike), and the ratios are the figures to read.

Error: the largest absolute deviation of the row's Poincare points (x and v, in backlash \
units, all {wl.samples} samples) from `geardyn.solvers.reference` (DOP853, rtol = atol = \
1e-12, restarted at every located edge crossing), on the same {wl.subset.size} Omega for every \
row ({sub}: periodic motions; the chaotic band 1.2 < Omega < 1.63 is left out, as no two \
integrators agree there after hundreds of periods). ns per lane-step: wall time / (lanes x \
periods x steps per period), all threads together (fixed-step rows only).

{table(rows, base)}

Against the issue's targets (ratios of this run):
{chr(10).join("- " + t for t in targets(rows))}

Notes:
{chr(10).join("- " + n for n in notes)}
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=3, help="warm repeats of the full-sweep rows")
    ap.add_argument("--peer-repeat", type=int, default=1,
                    help="timed runs of the adaptive peers at their tolerance")
    ap.add_argument("--points", type=int, default=POINTS)
    ap.add_argument("--max-steps", type=int, default=2**15,
                    help="largest steps per period tried for the plain kernel's TARGET")
    ap.add_argument("--every", type=int, default=10,
                    help="the adaptive peers are timed on every N-th point and extrapolated")
    ap.add_argument("--skip", default="", help="comma-separated: " + ",".join(PEERS))
    ap.add_argument("--write", action="store_true", help="replace '## Peers' in RESULTS.md")
    args = ap.parse_args()
    skip = {s.strip() for s in args.skip.split(",") if s.strip()}
    wl = workload(args.points)
    t0 = time.perf_counter()
    ref = reference(wl)
    print(f"reference on {wl.subset.size} Omega: {time.perf_counter() - t0:.1f} s", flush=True)
    sweeps = geardyn_sweeps(wl, ref)
    more, untimed = rk4_sweeps(wl, ref, args.max_steps)
    rows = measure(sweeps + more, args.repeat) + untimed
    for r in rows:
        print(_line(r), flush=True)
    rows += peer_rows(wl, ref, args.peer_repeat, skip, args.every)
    base = next(r for r in rows if r.key == "gdef")
    print()
    print(table(rows, base))
    print()
    print("\n".join(targets(rows)))
    if args.write:
        cmd = "make bench-peers" if os.environ.get("MAKELEVEL") else \
            "python bench/peers.py " + " ".join(sys.argv[1:])
        write_section(section(rows, base, wl, cmd))
        record_targets(rows, cmd)
        print(f"wrote the Peers section and the current figures of {RESULTS}")


def _as_module() -> object:
    """This file as the module ``bench_peers``, the name ``tests/test_bench_peers.py`` loads it
    under: numba's cache records a compiled function's module by name, so that run as a script
    (``__main__``) the kernels would load the tests' cache entries and fail to import it."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("bench_peers", __file__)
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_peers"] = module
    spec.loader.exec_module(module)
    return module


if __name__ == "__main__":
    _as_module().main()
