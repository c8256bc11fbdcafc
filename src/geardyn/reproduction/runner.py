"""Run the paper's figure cases: each a bifurcation sweep in Omega, continued up and down, with
the largest Lyapunov exponent wherever the period classifier finds no period.

The result of one case under one interpretation is an :class:`xarray.Dataset` with a ``sweep``
dimension (``"up"``, ``"down"``) in front of the variables of :func:`geardyn.bifurcation`, plus
``lyapunov`` (NaN where not computed), its standard error ``lyapunov_err`` and ``motion`` (the
labels of :mod:`geardyn.reproduction.motion`).
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import Executor
from dataclasses import asdict, dataclass

import numpy as np
import xarray as xr

from geardyn.analysis.bifurcation import ContinuedSweep, continued_sweeps, shared_settings
from geardyn.analysis.lyapunov import lyapunov_err_attrs, lyapunov_lanes
from geardyn.analysis.motion import LYAPUNOV_FLOOR, LYAPUNOV_Z, exponent_sign, rule_text
from geardyn.core.model import Model
from geardyn.core.plan import default_steps_at, lane_section
from geardyn.core.results import finish
from geardyn.core.settings import SWEEP_DIRECTIONS, LyapunovSettings, RunSettings
from geardyn.reproduction.cases import Case
from geardyn.reproduction.motion import motion_labels
from geardyn.study import build_model

__all__ = ["DIRECTIONS", "ReproductionSettings", "branch_lyapunov", "run_case", "run_cases",
           "sweep_values", "worker_pool"]

DIRECTIONS: tuple[str, ...] = SWEEP_DIRECTIONS

#: progress(stage, done, total): ``stage`` names the case, interpretation and sweep direction.
Progress = Callable[[str, int, int], None]

#: Points of each sweep per kernel call where progress is reported or several threads share the
#: calls (in a worker process, one thread and no progress: the whole sweep in one call). Any
#: segment gives bitwise the same points
#: (:func:`~geardyn.analysis.continuation.continue_branches`); a longer one leaves fewer slots
#: idle at the calls' ends, a shorter one rebalances the threads at every call (measured in
#: bench/RESULTS.md).
SEGMENT = 250


@dataclass(frozen=True)
class ReproductionSettings:
    """How finely to reproduce. ``None`` takes the study's value: ``num`` Omega points ([sweep]
    num), ``transient`` (tau, [run] transient), ``samples`` (mesh periods recorded per point,
    [sweep] samples else [run] periods). With ``converge`` (a tolerance; None: a fixed
    transient) ``transient`` is the longest transient and each point stops as soon as its
    Poincare point is estimated within ``converge`` of its orbit after at least
    ``min_transient`` (tau): a continued point starts next to its attractor and needs far less.
    The Lyapunov exponent is measured over ``lyapunov_duration`` (tau) after
    ``lyapunov_transient`` (tau), starting from the sweep's last stroboscopic sample at that
    point; it is positive or negative only beyond its uncertainty max(``lyapunov_z`` x standard
    error, ``lyapunov_floor`` / duration) (see :mod:`geardyn.analysis.motion`). A first estimate
    over ``lyapunov_screen`` (tau) settles the points whose exponent is clearly negative by that
    rule at the screening duration; only the others, among them every chaotic one, are measured
    over the full duration. Under load noise a Poincare section is taken where Lambda/Omega =
    p/q with q <= ``max_section_periods`` (sampling every q mesh periods); at every other Omega
    the exponent decides (a section every 9-32 periods, which the grid hits by accident at a few
    points, would cost 64 x q periods per point)."""

    num: int | None = None
    transient: float | None = None
    samples: int | None = None
    converge: float | None = 1.0e-8
    min_transient: float = 200.0
    lyapunov_transient: float = 100.0
    lyapunov_duration: float = 1500.0
    lyapunov_z: float = LYAPUNOV_Z
    lyapunov_floor: float = LYAPUNOV_FLOOR
    lyapunov_screen: float = 200.0
    max_section_periods: int = 8

    def __post_init__(self) -> None:
        checks = (("num", self.num, 2), ("samples", self.samples, 2))
        for name, value, least in checks:
            if value is not None and value < least:
                raise ValueError(f"{name} must be >= {least} (got {value!r})")
        if self.converge is not None and not (np.isfinite(self.converge) and self.converge > 0):
            raise ValueError(f"converge must be a tolerance > 0 or None (got {self.converge!r})")
        for name in ("transient", "min_transient", "lyapunov_transient"):
            value = getattr(self, name)
            if value is not None and not (np.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be a finite time >= 0 (got {value!r})")
        for name in ("lyapunov_z", "lyapunov_floor"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be finite and >= 0 (got {value!r})")
        for name in ("lyapunov_duration", "lyapunov_screen"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a finite time > 0 (got {value!r})")

    def run_settings(self, case: Case) -> RunSettings:
        """The :class:`~geardyn.RunSettings` of ``case``'s sweeps (by continuation:
        ``transient`` is the longest transient, ``continued_transient`` the shortest)."""
        r = self.resolve(case)
        return case.study.run_settings(
            transient=r["transient"], samples=r["samples"], converge=self.converge,
            continued_transient=min(r["min_transient"], r["transient"]),
            transient_max=r["transient"], max_section_periods=self.max_section_periods)

    def resolve(self, case: Case) -> dict[str, float | int]:
        """The settings for ``case`` with the study's defaults filled in."""
        s = case.study
        if s.sweep is None or s.sweep.param != "Omega":
            raise ValueError(f"{case.study_name}: needs a [sweep] over Omega")
        samples = self.samples or s.sweep.samples or s.run.periods
        return {
            "start": float(s.sweep.start),
            "stop": float(s.sweep.stop),
            "num": int(self.num or s.sweep.num),
            "transient": float(s.run.transient if self.transient is None else self.transient),
            "samples": int(samples),
            "converge": float(self.converge or 0.0),
            "min_transient": float(self.min_transient),
            "lyapunov_transient": float(self.lyapunov_transient),
            "lyapunov_duration": float(self.lyapunov_duration),
            "lyapunov_z": float(self.lyapunov_z),
            "lyapunov_floor": float(self.lyapunov_floor),
            "lyapunov_screen": float(self.lyapunov_screen),
            "max_section_periods": int(self.max_section_periods),
        }


def sweep_values(case: Case, settings: ReproductionSettings) -> np.ndarray:
    r = settings.resolve(case)
    return np.linspace(r["start"], r["stop"], int(r["num"]))


def branch_lyapunov(model: Model, values: np.ndarray, y0: np.ndarray, need: np.ndarray,
                    transient: float, duration: float,
                    steps_per_period: int | None = None,
                    t0: np.ndarray | float = 0.0,
                    run: RunSettings | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Largest Lyapunov exponent [1/tau] and its standard error at the Omega ``values`` where
    ``need`` is true, each started from its own state ``y0[i]`` at its own time ``t0[i]`` (the
    sweep's final time, so both forcing phases continue); NaN elsewhere, and where the
    integration diverged. ``run``: the sweep's settings, whose ``locate_edges`` and ``bound``
    apply (None: RunSettings' defaults); ``transient`` and the step are the arguments'.

    Lanes are grouped by their default step count (within a factor 1.25) so that a low Omega
    does not impose its fine step on the whole sweep; each group runs in parallel."""
    values = np.asarray(values, dtype=float)
    t0 = np.broadcast_to(np.asarray(t0, dtype=float), values.shape)
    out = np.full(values.size, np.nan)
    err = np.full(values.size, np.nan)
    idx = np.flatnonzero(need)
    if idx.size == 0:
        return out, err
    idx = idx[np.argsort(values[idx], kind="stable")]
    steps = (np.full(idx.size, int(steps_per_period)) if steps_per_period
             else default_steps_at(model, values[idx]))
    groups: list[list[int]] = []
    for j in range(idx.size):
        if not groups or steps[groups[-1][0]] > 1.25 * steps[j] or len(groups[-1]) >= 64:
            groups.append([])
        groups[-1].append(j)
    base = RunSettings() if run is None else run
    for g in groups:
        lanes = idx[g]
        out[lanes], err[lanes] = lyapunov_lanes(
            model, model.lane_params("Omega", values[lanes]), np.asarray(y0)[lanes],
            base.replace(transient=transient, steps_per_period=int(max(steps[g]))),
            settings=LyapunovSettings(duration=duration), t0=t0[lanes], with_error=True)
    return out, np.where(np.isfinite(out), err, np.nan)


def _sweeps(tasks: list[tuple[Case, str, str]], settings: ReproductionSettings,
            progress: Progress | None = None) -> list[xr.Dataset]:
    """The sweeps ``(case, interpretation, direction)``, continued together (their points
    advance as lanes of one kernel call; see :func:`geardyn.analysis.bifurcation.continued_sweeps`),
    then each classified, with Lyapunov exponents where no period is found. A unit of work:
    the arguments pickle, for worker processes. Each kernel call runs every sweep whole on one
    thread without ``progress``, else :data:`SEGMENT` points of each."""
    import numba

    start = time.perf_counter()
    plans = []
    for case, interp, direction in tasks:
        r = settings.resolve(case)
        run = settings.run_settings(case)
        model = build_model(case.study, interpretation=interp)
        sweep = ContinuedSweep(model, "Omega", sweep_values(case, settings), direction, run=run)
        plans.append((sweep, r, run))
    case0, interp0, _ = tasks[0]
    label = (f"{case0.name} {interp0} up and down" if len(tasks) == 2
             else f"{len(tasks)} sweeps together")

    def tick(done: int, total: int) -> None:
        if progress is not None:
            progress(label, done, total)

    swept: list[xr.Dataset] = [xr.Dataset()] * len(tasks)
    # one continuation per set of shared settings (all but each sweep's transients and step)
    groups: dict[tuple, list[int]] = {}
    for i, (_, _r, run) in enumerate(plans):
        groups.setdefault(shared_settings(run), []).append(i)
    for members in groups.values():
        whole = progress is None and numba.get_num_threads() == 1
        segment = max(np.size(plans[i][0].values) for i in members) if whole else SEGMENT
        done = continued_sweeps([plans[i][0] for i in members], plans[members[0]][2],
                                progress=tick, segment=segment)
        for i, ds in zip(members, done, strict=True):
            swept[i] = ds
    joint = time.perf_counter() - start
    out = []
    for ds, (sweep, r, _run) in zip(swept, plans, strict=True):
        ds = _classify(ds, sweep, r)
        ds.attrs.update(continuation_wall_time_s=joint, continued_with=len(tasks))
        out.append(ds)
    return out


def _classify(ds: xr.Dataset, sweep: ContinuedSweep, r: dict) -> xr.Dataset:
    """``ds`` with the Lyapunov exponent where no period is found, and the motion class."""
    start = time.perf_counter()
    model, values = sweep.model, np.asarray(sweep.values, dtype=float)
    period = ds["period"].values
    final = ds["poincare"].values[:, -1, :]
    t_final = ds["final_time"].values
    need = period == 0
    screen = min(r["lyapunov_screen"], r["lyapunov_duration"])
    lam, err = branch_lyapunov(model, values, final, need, r["lyapunov_transient"], screen,
                               sweep.steps_per_period, t_final, run=sweep.run)
    duration = np.full(lam.shape, screen)
    rule = {"z": r["lyapunov_z"], "floor": r["lyapunov_floor"]}
    again = need & ~(exponent_sign(lam, err, duration, **rule) < 0)
    if r["lyapunov_screen"] < r["lyapunov_duration"] and again.any():
        lam2, err2 = branch_lyapunov(model, values, final, again, r["lyapunov_transient"],
                                     r["lyapunov_duration"], sweep.steps_per_period, t_final,
                                     run=sweep.run)
        lam[again], err[again] = lam2[again], err2[again]
        duration[again] = r["lyapunov_duration"]
    ds["lyapunov"] = ("Omega", lam, {
        "long_name": "largest Lyapunov exponent", "units": "1/tau",
        "computed_where": "no period found (period == 0); clearly negative ones over the "
        "screening duration only",
        "start": "last stroboscopic sample of this sweep at this Omega, at its time "
                 "(final_time: both forcing phases continue)"})
    ds["lyapunov_err"] = ("Omega", err, lyapunov_err_attrs("tau"))
    ds["lyapunov_duration"] = ("Omega", np.where(need, duration, np.nan), {
        "long_name": "time the Lyapunov exponent was averaged over", "units": "tau"})
    section = lane_section(model, model.lane_params("Omega", values), values,
                           r["max_section_periods"])[1]
    ds["motion"] = ("Omega", motion_labels(period, lam, lyapunov_err=err, duration=duration,
                                           section=section, **rule), {
        "long_name": "motion class", "meaning": "period-k, chaotic, quasi-periodic, "
        "unresolved (no period <= max_period, exponent clearly negative), non-periodic (no "
        "exponent), unbounded; see geardyn.analysis.motion", "rule": rule_text(**rule)})
    ds.attrs["lyapunov_wall_time_s"] = time.perf_counter() - start
    steps = ds["steps_per_period"].values * (ds["transient_periods"].values
                                             + r["samples"] * ds["section_periods"].values)
    ds.attrs["lane_steps"] = int(np.sum(steps))
    return ds


def _assemble(case: Case, interpretation: str, settings: ReproductionSettings,
              parts: dict[str, xr.Dataset]) -> xr.Dataset:
    """The up and down sweeps of ``case`` as one case result (see the module docs)."""
    per_direction: dict[str, dict] = {}
    ordered = []
    for direction in DIRECTIONS:
        ds = parts[direction].copy()
        per_direction[direction] = {k: ds.attrs.pop(k) for k in (
            "lyapunov_wall_time_s", "lane_steps", "continuation_wall_time_s",
            "continued_with")}
        ds.attrs.pop("continuation", None)
        ordered.append(ds)
    out = xr.concat(ordered, dim="sweep", combine_attrs="drop_conflicts")
    out = out.assign_coords(sweep=("sweep", list(DIRECTIONS)))
    model = build_model(case.study, interpretation=interpretation)
    loads = case.params.loads
    up, down = per_direction["up"], per_direction["down"]
    out.attrs.update(
        {f"setting_{k}": v for k, v in settings.resolve(case).items()},
        interpretation=interpretation,
        lane_steps_up=up["lane_steps"], lane_steps_down=down["lane_steps"],
        lyapunov_time_up_s=float(up["lyapunov_wall_time_s"]),
        lyapunov_time_down_s=float(down["lyapunov_wall_time_s"]),
        continuation_time_up_s=float(up["continuation_wall_time_s"]),
        continuation_time_down_s=float(down["continuation_wall_time_s"]),
        continued_with_up=int(up["continued_with"]),
        continued_with_down=int(down["continued_with"]),
        B1=float(loads.B1), B2=float(loads.B2), Lambda=float(loads.Lambda),
        section="load fluctuation at Lambda: every common period where Lambda/Omega = p/q with "
        f"q <= {settings.max_section_periods} (section_periods), elsewhere no section: the "
        "Lyapunov exponent decides"
        if case.load_noise else "stroboscopic, once per mesh period",
        params_json=case.params.model_dump_json(),
        static_deflection=[float(g) for g in model.static_forces()[:2]],
        unresolved_steps=int(out["unresolved_steps"].sum()),
    )
    return finish(label_case(out, case), "reproduction-case")


def run_case(case: Case, interpretation: str = "consistent",
             settings: ReproductionSettings | None = None,
             progress: Progress | None = None) -> xr.Dataset:
    """Sweep ``case`` in Omega, continued up and down (both together), and classify every
    point.

    Returns the dataset described in the module docs; its attributes name the case, the
    interpretation, the settings used, how the Poincare section is taken (``section``), the
    integration work of each direction and the wall times."""
    settings = settings or ReproductionSettings()
    parts = _sweeps([(case, interpretation, d) for d in DIRECTIONS], settings, progress)
    return _assemble(case, interpretation, settings, dict(zip(DIRECTIONS, parts, strict=True)))


def label_case(ds: xr.Dataset, case: Case) -> xr.Dataset:
    """``ds`` (a case result) relabelled as ``case``: name, figure and plotted coordinate."""
    out = ds.copy()
    out.attrs.update(case=case.name, figure=case.figure, study=case.name,
                     description=case.study.study.description, plot_state=case.plot_state)
    return out


def _one_thread() -> None:
    """Worker-process set-up: one numba thread each (the processes share the cores)."""
    import numba

    numba.set_num_threads(1)


@contextlib.contextmanager
def worker_pool(workers: int) -> Iterator[Executor | None]:
    """``workers`` spawned worker processes with one numba thread each, for :func:`run_cases`
    and then :func:`~geardyn.reproduction.report.write_report` (one start-up for both); None
    when ``workers`` <= 1."""
    if workers <= 1:
        yield None
        return
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    ctx = multiprocessing.get_context("spawn")  # no fork of numba's thread pool
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx,
                             initializer=_one_thread) as pool:
        yield pool


def run_cases(cases: Iterable[Case], interpretations: Iterable[str],
              settings: ReproductionSettings | None = None,
              progress: Progress | None = None, workers: int = 1,
              pool: Executor | None = None) -> dict[tuple[str, str], xr.Dataset]:
    """:func:`run_case` for every case and interpretation, keyed ``(case name,
    interpretation)``; cases with the same dynamics (Figs. 3 and 6, ...) run once.

    All sweeps (two per distinct case) are continued together, their points advancing as the
    lanes of one kernel call on all numba threads. ``workers`` > 1 splits them into that many
    groups, each continued in its own worker process with one thread (a group waits at each
    point for its slowest lane, so a few independent groups keep the cores busier); ``pool``:
    the processes to use (from :func:`worker_pool`; None: started here). Lanes do not
    interact, so the results are bitwise those of a serial run, whatever the grouping."""
    settings = settings or ReproductionSettings()
    cases = list(cases)
    first: dict[str, tuple[Case, str]] = {}
    owner: dict[tuple[str, str], str] = {}
    for interp in interpretations:
        for case in cases:
            key = case.dynamics_key(interp) + repr(asdict(settings))
            first.setdefault(key, (case, interp))
            owner[(case.name, interp)] = key
    tasks = [(key, d) for key in first for d in DIRECTIONS]
    groups = _split(tasks, first, workers)
    parts: dict[tuple[str, str], xr.Dataset] = {}
    if len(groups) <= 1:
        for ds, task in zip(_sweeps([(*first[k], d) for k, d in tasks], settings, progress),
                            tasks, strict=True):
            parts[task] = ds
    else:
        from concurrent.futures import as_completed

        with contextlib.ExitStack() as stack:
            if pool is None:
                pool = stack.enter_context(worker_pool(len(groups)))
            futures = {pool.submit(_sweeps, [(*first[k], d) for k, d in g], settings): g
                       for g in groups}
            finished = 0
            for fut in as_completed(futures):
                for task, ds in zip(futures[fut], fut.result(), strict=True):
                    parts[task] = ds
                finished += len(futures[fut])
                if progress is not None:
                    progress(f"sweeps in {len(groups)} processes", finished, len(tasks))
    done = {key: _assemble(*first[key], settings, {d: parts[(key, d)] for d in DIRECTIONS})
            for key in first}
    out: dict[tuple[str, str], xr.Dataset] = {}
    for (name, interp), key in owner.items():
        ds = done[key]
        if ds.attrs["case"] != name:
            ds = label_case(ds, Case(name))
            ds.attrs["shared_with"] = done[key].attrs["case"]
        out[(name, interp)] = ds
    return out


def _split(tasks: list[tuple[str, str]], first: dict[str, tuple[Case, str]], workers: int
           ) -> list[list[tuple[str, str]]]:
    """``tasks`` in at most ``workers`` groups of about equal estimated cost (a load-noise case
    needs Lyapunov exponents almost everywhere: counted three times), longest first."""
    n = max(1, min(workers, len(tasks)))
    cost = [3.0 if first[k][0].load_noise else 1.0 for k, _ in tasks]
    load = [0.0] * n
    groups: list[list[tuple[str, str]]] = [[] for _ in range(n)]
    for i in sorted(range(len(tasks)), key=lambda i: -cost[i]):
        g = load.index(min(load))
        groups[g].append(tasks[i])
        load[g] += cost[i]
    return [g for g in groups if g]
