"""The seed paper's claims (``shared/model-notes.md``) as checks computed from case results.

Every check reads the motion labels (period classifier plus Lyapunov exponent, see
:mod:`geardyn.reproduction.motion`) and the stroboscopic samples of the cases it names, and
returns a :class:`Verdict`: ``holds``, ``partly holds`` or ``fails``, with the measured Omega
ranges and numbers; ``not assessed`` when a case it needs was not run. Nothing is typed by hand:
change the model or the numerics and the verdicts follow.

Rules shared by the checks (module constants, stated in the report):

* "at Omega ~ a-b" is read on the grid points in [a, b]; the claimed motion must cover at least
  :data:`SHARE_HOLDS` of them to hold; to partly hold it must cover at least
  :data:`SHARE_PARTLY` of them (or of the range widened by :data:`APPROX`), or form a region
  within :data:`APPROX` of the range, and in every case appear at more than one grid point
  within :data:`APPROX` of the range;
* a region (a window of chaos, of non-periodic motion, the onset of other motion) is a run of
  consecutive grid points spanning at least :data:`MIN_WIDTH` in Omega, whatever the grid;
* "chaos" is a positive Lyapunov exponent; the paper, like most bifurcation studies, calls every
  cloud of points chaos, so a check whose chaos turns out quasi-periodic partly holds;
* "obvious" influence of the load noise: the spread of the stroboscopic points grows, in the
  median over Omega, by at least :data:`OBVIOUS` of the static mesh deflection.

A verdict also says what decided it (:attr:`Verdict.basis`) when that is not the nonlinear
dynamics: while the back flanks never touch, the equations depend on X - b only, so the backlash
claims (C14-C18) compare a diagram with a copy of itself shifted by the change of backlash
(:data:`BY_CONSTRUCTION`, checked on the data: no back-flank contact at any point of either
case); at a load frequency Lambda far below the natural frequencies (Lambda = 0.1) the growth of
the point spread is the quasi-static response to B1, B2, which linear statics give
(:data:`LINEAR_STATICS`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace

import numpy as np
import xarray as xr

from geardyn.reproduction.evidence import (
    QUASI_STATIC,
    Branch,
    Evidence,
    MissingCase,
    format_intervals,
)

__all__ = ["BACK_CONTACT", "BY_CONSTRUCTION", "CLAIMS", "LINEAR_STATICS", "STATUSES", "Claim",
           "Verdict", "evaluate", "evaluate_claim"]

HOLDS, PARTLY, FAILS, NOT_ASSESSED = "holds", "partly holds", "fails", "not assessed"
STATUSES: tuple[str, ...] = (HOLDS, PARTLY, FAILS, NOT_ASSESSED)

#: Tolerance of the paper's "Omega ~ a" (absolute, in Omega).
APPROX = 0.1
#: Share of a claimed Omega range that must show the claimed motion to hold / partly hold.
SHARE_HOLDS = 0.8
SHARE_PARTLY = 0.2
#: Smallest width in Omega (last minus first grid point of a run) that makes a region: a
#: window of chaos or of motion without period, the onset of other motion.
MIN_WIDTH = 0.05
#: "Partly holds" needs the claimed motion at more than this many grid points within APPROX of
#: the claimed range.
MIN_POINTS_NEAR = 1
#: Share of Omega whose motion must agree for "the same shape" to hold / partly hold.
SHAPE_HOLDS = 0.9
SHAPE_PARTLY = 0.7
#: "Obvious" influence: median growth of the point spread, as a share of the static deflection.
OBVIOUS = 0.1
#: Relative tolerance to which the section points of two cases must agree after the backlash
#: shift to count as the same motion (the transients converge to 1e-8).
SHIFT_TOL = 1.0e-6
#: Largest relative difference between the measured growth of the point spread and the linear
#: quasi-static estimate for linear statics to count as deciding a load-noise verdict.
STATICS_AGREE = 0.3
#: Relative tolerance of "unchanged" amplitudes (holds within it, partly within 3 times it).
SAME_AMPLITUDE = 0.1


#: Basis of a verdict that a coordinate shift decides (see the module docs).
BY_CONSTRUCTION = "by construction (coordinate shift while no back-flank contact)"
#: Basis when the back flanks touch in a backlash claim's cases: the claim tests the model.
BACK_CONTACT = "model (back-flank contact: not a pure coordinate shift)"
#: Basis of a load-noise verdict that the quasi-static response to B decides.
LINEAR_STATICS = "linear statics (quasi-static response to B at low Lambda)"


@dataclass(frozen=True)
class Verdict:
    """``status`` (one of :data:`STATUSES`), what was ``measured``, further ``details``, and
    the ``basis`` of the verdict when it is not the nonlinear dynamics ("" otherwise:
    :data:`BY_CONSTRUCTION`, :data:`BACK_CONTACT`, :data:`LINEAR_STATICS`; the evidence for it
    is the last entry of ``details``)."""

    status: str
    measured: str
    details: tuple[str, ...] = ()
    basis: str = ""


@dataclass(frozen=True)
class Claim:
    """One claim: where the paper makes it, what it says, which cases the check reads, and the
    rule that turns the measurements into a verdict."""

    id: str
    source: str
    statement: str
    cases: tuple[str, ...]
    rule: str
    check: Callable[[Evidence], Verdict]


def _grade(good: bool, partial: bool) -> str:
    return HOLDS if good else PARTLY if partial else FAILS


def _pct(x: float) -> str:
    return "n/a" if not np.isfinite(x) else f"{100 * x:.0f}%"


# --------------------------------------------------------------------------- generic checks
def _motion_in_range(case: str, k: int, lo: float, hi: float) -> Callable[[Evidence], Verdict]:
    """Period-k motion over Omega ~ [lo, hi]."""

    def check(ev: Evidence) -> Verdict:
        b = ev[case]
        mask = b.period(k)
        share, n = b.share(mask, lo, hi)
        wide, _ = b.share(mask, lo - APPROX, hi + APPROX)
        near = mask & b.within(lo - APPROX, hi + APPROX)
        count = int(np.count_nonzero(near))
        region = bool(b.regions(near, MIN_WIDTH))
        partial = count > MIN_POINTS_NEAR and (
            share >= SHARE_PARTLY or wide >= SHARE_PARTLY or region)
        status = _grade(share >= SHARE_HOLDS and count > MIN_POINTS_NEAR, partial)
        return Verdict(status,
                       f"period-{k} on {_pct(share)} of the {n} points in [{lo:g}, {hi:g}] "
                       f"({count} within {APPROX:g} of it); period-{k} at Omega = "
                       f"{b.describe(mask)}")

    return check


def _window(case: str, lo: float, hi: float) -> Callable[[Evidence], Verdict]:
    """A chaotic window in Omega ~ (lo, hi)."""

    def check(ev: Evidence) -> Verdict:
        b = ev[case]
        inside = b.within(lo, hi)
        chaos = b.regions(b.chaotic & inside, MIN_WIDTH)
        cloud = b.regions(b.nonperiodic & inside, MIN_WIDTH)
        status = _grade(bool(chaos), bool(cloud))
        return Verdict(status,
                       f"in [{lo:g}, {hi:g}]: chaotic at {_fmt(chaos)}; without period at "
                       f"{_fmt(cloud)}",
                       (f"whole diagram: chaotic at {b.describe(b.chaotic)}; quasi-periodic or "
                        f"unresolved at {b.describe(b.nonperiodic & ~b.chaotic)}",))

    return check


def _fmt(runs: list[tuple[float, float, int]]) -> str:
    return format_intervals(runs)


def _chaos_persists(case: str) -> Callable[[Evidence], Verdict]:
    def check(ev: Evidence) -> Verdict:
        b = ev[case]
        chaos, cloud = b.regions(b.chaotic, MIN_WIDTH), b.regions(b.nonperiodic, MIN_WIDTH)
        return Verdict(_grade(bool(chaos), bool(cloud)),
                       f"chaotic at {_fmt(chaos)}; without period at {_fmt(cloud)}")

    return check


# --------------------------------------------------------------------------- Fig. 3
def _fig3_periodic_below(ev: Evidence) -> Verdict:
    b = ev["fig3"]
    share, n = b.share(b.period(1), b.omega[0], 0.7)
    onset = b.first_region(b.bifurcated, MIN_WIDTH)
    single = b.first(b.bifurcated)
    loss = b.first(np.any(b.contact != "none", axis=1))
    near = onset is not None and abs(onset - 0.7) <= APPROX
    status = _grade(share >= 0.95 and near, share >= 0.95 or share >= SHARE_HOLDS)
    return Verdict(status,
                   f"period-1 on {_pct(share)} of the {n} points below 0.7; first region of "
                   f"other motion from Omega = {_num(onset)}",
                   (f"first point of other motion at Omega = {_num(single)}",
                    f"teeth first separate (contact loss) at Omega = {_num(loss)}"))


def _num(x: float | None) -> str:
    return "none" if x is None else f"{x:.3g}"


def _fig3_nonperiodic_high(ev: Evidence) -> Verdict:
    b = ev["fig3"]
    share, n = b.share(b.nonperiodic, 1.5, 3.2)
    chaos = b.regions(b.chaotic & b.within(1.5, 3.2), MIN_WIDTH)
    cloud = b.regions(b.nonperiodic & b.within(1.5, 3.2), MIN_WIDTH)
    status = _grade(share >= 0.5 and bool(chaos), bool(cloud))
    return Verdict(status,
                   f"without period on {_pct(share)} of the {n} points in [1.5, 3.2]: "
                   f"{_fmt(cloud)}; chaotic at {_fmt(chaos)}")


def _fig3_period1_above(ev: Evidence) -> Verdict:
    b = ev["fig3"]
    share, n = b.share(b.period(1), 3.2, b.omega[-1])
    last = b.runs(b.period(1))
    start = last[-1][0] if last and last[-1][1] == b.omega[-1] else None
    near = start is not None and abs(start - 3.2) <= 2 * APPROX
    status = _grade(share >= 0.95 and near, share >= 0.5)
    return Verdict(status,
                   f"period-1 on {_pct(share)} of the {n} points above 3.2; the last period-1 "
                   f"branch starts at Omega = {_num(start)}")


def _route_to_chaos(ev: Evidence) -> Verdict:
    b = ev["fig3"]
    k = max(1, b.omega.size // 20)
    low = bool(np.all(b.period(1)[:k]))
    high = bool(np.all(b.period(1)[-k:]))
    chaos = b.regions(b.chaotic, MIN_WIDTH)
    cloud = b.regions(b.nonperiodic, MIN_WIDTH)
    ends = low and high
    return Verdict(_grade(ends and bool(chaos), ends and bool(cloud)),
                   f"period-1 at the lowest 5% of Omega: {low}, at the highest 5%: {high}; "
                   f"chaotic at {_fmt(chaos)}; without period at {_fmt(cloud)}")


# --------------------------------------------------------------------------- damping
def _damping_shrinks(low: str, high: str) -> Callable[[Evidence], Verdict]:
    def check(ev: Evidence) -> Verdict:
        a, b = ev[low], ev[high]
        chaos_a, chaos_b = a.length(a.chaotic), b.length(b.chaotic)
        cloud_a, cloud_b = a.length(a.nonperiodic), b.length(b.nonperiodic)
        status = _grade(chaos_a > 0 and chaos_b < chaos_a, cloud_a > 0 and cloud_b < cloud_a)
        return Verdict(status,
                       f"chaotic Omega-length {chaos_a:.3g} -> {chaos_b:.3g}; without period "
                       f"{cloud_a:.3g} -> {cloud_b:.3g} ({low} -> {high})")

    return check


def _only_period1(case: str) -> Callable[[Evidence], Verdict]:
    def check(ev: Evidence) -> Verdict:
        b = ev[case]
        share = float(np.mean(b.period(1)))
        other = b.describe(b.bifurcated)
        return Verdict(_grade(share == 1.0, share >= 0.9),
                       f"period-1 at {_pct(share)} of {b.omega.size} points; other motion at "
                       f"{other}")

    return check


def _damping_avoids_chaos(ev: Evidence) -> Verdict:
    bs = [ev[c] for c in ("fig3", "fig4", "fig5")]
    chaos = [b.length(b.chaotic) for b in bs]
    cloud = [b.length(b.nonperiodic) for b in bs]
    mono_chaos = chaos[0] > 0 and chaos[0] >= chaos[1] >= chaos[2] and chaos[2] == 0
    mono_cloud = cloud[0] > 0 and cloud[0] >= cloud[1] >= cloud[2] and cloud[2] == 0
    return Verdict(_grade(mono_chaos, mono_cloud),
                   "xi = 0.05, 0.1, 0.2: chaotic Omega-length "
                   + ", ".join(f"{c:.3g}" for c in chaos) + "; without period "
                   + ", ".join(f"{c:.3g}" for c in cloud))


def _pq_route(ev: Evidence) -> Verdict:
    lines, grades = [], []
    for case in ("fig6", "fig7"):
        b = ev[case]
        chaos, cloud = b.regions(b.chaotic, MIN_WIDTH), b.regions(b.nonperiodic, MIN_WIDTH)
        onset = b.first_region(b.bifurcated, MIN_WIDTH)
        after = b.period(1) & (b.omega > (onset if onset is not None else np.inf))
        low = bool(b.period(1)[0])
        grades.append((low and bool(chaos) and bool(after.any()),
                       low and bool(cloud) and bool(after.any())))
        lines.append(f"{case}: period-1 at the lowest Omega: {low}; chaotic at {_fmt(chaos)}; "
                     f"without period at {_fmt(cloud)}; period-1 after the first bifurcation: "
                     f"{bool(after.any())}")
    good = all(g for g, _ in grades)
    partial = any(g or p for g, p in grades)
    return Verdict(_grade(good, partial), "; ".join(lines),
                   ("Figs. 6 and 7 have the parameters of Figs. 3 and 4: the same motion, another "
                    "coordinate",))


def _pq_harmonic(ev: Evidence) -> Verdict:
    b = ev["fig8"]
    share = float(np.mean(b.period(1)))
    j = b.mesh.index("pq") if "pq" in b.mesh else -1
    regimes = sorted(set(b.contact[:, j])) if j >= 0 else []
    one_form = len(regimes) == 1
    return Verdict(_grade(share == 1.0 and one_form, share >= 0.9),
                   f"period-1 at {_pct(share)} of the points; pq contact regimes over Omega: "
                   f"{', '.join(regimes)}",
                   ("'the vibration form does not change' is read as one contact-loss regime of "
                    "the pq mesh over the whole sweep",))


# --------------------------------------------------------------------------- backlash, error
def _same_shape(case: str, ref: str) -> Callable[[Evidence], Verdict]:
    def check(ev: Evidence) -> Verdict:
        a, b = ev[ref], ev[case]
        if a.omega.size != b.omega.size or not np.allclose(a.omega, b.omega):
            return Verdict(NOT_ASSESSED, "the two cases were run on different Omega grids")
        agree = float(np.mean(a.motion == b.motion))
        return Verdict(_grade(agree >= SHAPE_HOLDS, agree >= SHAPE_PARTLY),
                       f"the motion class agrees with {ref} at {_pct(agree)} of the points",
                       (f"differs at Omega = {a.describe(a.motion != b.motion)}",))

    return check


def _smaller_displacement(case: str, ref: str) -> Callable[[Evidence], Verdict]:
    def check(ev: Evidence) -> Verdict:
        a, b = ev[ref], ev[case]
        lower = b.top < a.top
        share = float(np.mean(lower))
        drop = float(np.median(a.top - b.top))
        amp = b.extent / a.extent if a.extent > 0 else float("nan")
        shift = a.backlash - b.backlash
        return Verdict(_grade(share >= 0.95, share >= 0.5),
                       f"the largest {b.state} of the diagram is lower than in {ref} at "
                       f"{_pct(share)} of the points (median drop {drop:.3g}"
                       + (f"; the backlash is {shift:.3g} b_c smaller)" if np.isfinite(shift)
                          else ")"),
                       (f"extent of the whole diagram (peak-to-peak) {b.extent:.3g} against "
                        f"{a.extent:.3g} in {ref} (ratio {amp:.3g})",))

    return check


def _shift_basis(ev: Evidence, case: str, ref: str) -> tuple[str, str]:
    """The basis of a backlash claim comparing ``case`` with ``ref`` (the same parameters but
    the backlash), and the evidence for it: :data:`BY_CONSTRUCTION` when the back flanks touch
    at no point of either case (read on the sampled motion of every point), else
    :data:`BACK_CONTACT` with where they touch."""
    if not ev.has(ref):
        return "", (f"whether {case} is {ref} shifted was not checked ({ref} was not run)")
    a, b = ev[ref], ev[case]
    touch = [f"{x.case} at Omega = {x.describe(x.back_contact)}"
             for x in (a, b) if x.back_contact.any()]
    if touch:
        return BACK_CONTACT, ("the back flanks touch in " + "; ".join(touch) + ": there the "
                              "backlash changes the dynamics, not only the coordinate")
    lost = [f"{x.case} at Omega = {x.describe(x.diverged)}" for x in (a, b) if x.diverged.any()]
    if lost:
        return "", ("back-flank contact not established: the integration diverged in "
                    + "; ".join(lost))
    shift = a.backlash - b.backlash
    by = f" by {shift:.3g} b_c" if np.isfinite(shift) else ""
    return BY_CONSTRUCTION, (
        f"no back-flank contact in {ref} or {case} at any Omega of this sweep (contact regimes "
        "and section points of the sampled motion): the equations depend on X - b only, so "
        f"{case} is {ref} with the coordinate shifted{by}; the claim tests this shift, not the "
        "model (tests/test_backlash_shift.py checks the identity)" + _shift_seen(a, b, shift))


def _shift_seen(a: Branch, b: Branch, shift: float) -> str:
    """How far the data show the shift: the share of points whose section points agree after
    it (to :data:`SHIFT_TOL` relative); "" when it cannot be measured."""
    if not np.isfinite(shift) or a.x.shape != b.x.shape or not np.array_equal(a.omega, b.omega):
        return ""
    scale = SHIFT_TOL * max(1.0, float(np.nanmax(np.abs(a.x))))
    with np.errstate(invalid="ignore"):
        same = np.max(np.abs(a.x - shift - b.x), axis=1) <= scale
    return (f"; after the shift the section points agree to {SHIFT_TOL:g} (relative) at "
            f"{_pct(float(np.mean(same)))} of the points (where not: chaotic motion, which "
            "amplifies round-off, a transient that touched the back flank, or coexisting "
            "attractors reached by different transients)")


def _backlash(check: Callable[[Evidence], Verdict], case: str, ref: str
              ) -> Callable[[Evidence], Verdict]:
    """``check`` with the basis of :func:`_shift_basis` added to its verdict."""

    def wrapped(ev: Evidence) -> Verdict:
        verdict = check(ev)
        if verdict.status == NOT_ASSESSED:
            return verdict
        basis, why = _shift_basis(ev, case, ref)
        return replace(verdict, basis=basis, details=verdict.details + (why,))

    return wrapped


def _shift_left(case: str, ref: str) -> Callable[[Evidence], Verdict]:
    def check(ev: Evidence) -> Verdict:
        a, b = ev[ref], ev[case]
        onset_a = a.first_region(a.bifurcated, MIN_WIDTH)
        onset_b = b.first_region(b.bifurcated, MIN_WIDTH)
        if onset_a is None or onset_b is None:
            return Verdict(FAILS, f"first bifurcation: {ref} at {_num(onset_a)}, {case} at "
                           f"{_num(onset_b)}: no shift to measure")
        best = _best_shift(a.bifurcated, b.bifurcated, a.step)
        step = a.step
        moved = [onset_b - onset_a <= -step, best <= -step]
        return Verdict(_grade(all(moved), any(moved)),
                       f"first bifurcation at Omega = {onset_b:.3g} against {onset_a:.3g} in "
                       f"{ref} (shift {onset_b - onset_a:+.3g}); best-matching shift of the "
                       f"whole pattern {best:+.3g}",
                       ("the pattern is 'not period-1' against Omega; the best shift minimises "
                        "the disagreement over shifts up to 0.5",))

    return check


def _best_shift(ref: np.ndarray, moved: np.ndarray, step: float, max_shift: float = 0.5
                ) -> float:
    """The shift d (a multiple of the grid step, |d| <= max_shift) that best maps ``ref`` onto
    ``moved``: moved(Omega) ~ ref(Omega - d); ties go to the smallest |d|."""
    n = ref.size
    kmax = int(round(max_shift / step)) if step > 0 else 0
    best, best_err = 0, np.inf
    for k in sorted(range(-kmax, kmax + 1), key=abs):
        lo, hi = max(0, k), min(n, n + k)
        if hi - lo < n // 2:
            continue
        err = float(np.mean(moved[lo:hi] != ref[lo - k:hi - k]))
        if err < best_err - 1e-12:
            best, best_err = k, err
    return best * step


def _same_amplitude(case: str, ref: str) -> Callable[[Evidence], Verdict]:
    def check(ev: Evidence) -> Verdict:
        a, b = ev[ref], ev[case]
        ratio = b.extent / a.extent if a.extent > 0 else float("nan")
        dev = abs(ratio - 1.0)
        return Verdict(_grade(dev <= SAME_AMPLITUDE, dev <= 3 * SAME_AMPLITUDE),
                       f"extent of the diagram (peak-to-peak of every {b.state} point) "
                       f"{b.extent:.3g} against {a.extent:.3g} in {ref} (ratio {ratio:.3g})")

    return check


# --------------------------------------------------------------------------- load noise
NOISE_CASES = ("fig13", "fig14", "fig15a", "fig15b", "fig15c", "fig15d")


def _influence(b: Branch, ref: Branch) -> float:
    """Median growth of the point spread over Omega, in units of the static deflection."""
    return float(np.median(b.spread - ref.spread)) / b.static_deflection


def _statics(b: Branch, ref: Branch) -> tuple[bool, str] | None:
    """Whether linear statics alone give the "obvious" reading of ``b`` (the quasi-static
    response to B is on the same side of :data:`OBVIOUS` as the measured growth, and agrees
    with it to :data:`STATICS_AGREE`), and the
    numbers; None unless the load frequency is quasi-static (Lambda <= QUASI_STATIC x the
    lowest natural frequency) and the parameters are known."""
    spread, lam, lowest = b.quasi_static
    if not (np.isfinite(spread) and 0.0 < lam <= QUASI_STATIC * lowest):
        return None
    static = spread / b.static_deflection
    measured = _influence(b, ref)
    same = ((static >= OBVIOUS) == (measured >= OBVIOUS)
            and abs(measured - static) <= STATICS_AGREE * static)
    return same, (f"{b.case}: Lambda = {lam:g} is below {QUASI_STATIC:g} x the lowest natural "
                  f"frequency ({lowest:.3g}): the loads A +- B through the static stiffness "
                  f"alone move {b.state} by {spread:.3g} peak-to-peak, {static:.3g} static "
                  f"deflections, against a measured growth of {measured:.3g}"
                  + (f" (within {STATICS_AGREE:.0%}: linear statics decide)" if same else
                     " (they disagree: the dynamics matter)"))


def _with_statics(verdict: Verdict, cases: list[Branch], ref: Branch) -> Verdict:
    """``verdict`` with the quasi-static cases among ``cases`` noted (see :func:`_statics`)."""
    found = [(c.case, _statics(c, ref)) for c in cases]
    found = [(name, r) for name, r in found if r is not None]
    if not found:
        return verdict
    decided = [name for name, (same, _) in found if same]
    basis = f"{LINEAR_STATICS}: {', '.join(decided)}" if decided else ""
    return replace(verdict, basis=basis,
                   details=verdict.details + tuple(text for _, (_, text) in found))


def _chaos_changes(ev: Evidence) -> Verdict:
    ref = ev["fig4"]
    lines, changed = [], {}
    for case in NOISE_CASES:
        if not ev.has(case):
            continue
        b = ev[case]
        diff = b.chaotic != ref.chaotic
        changed[case] = bool(b.regions(diff, MIN_WIDTH))
        lines.append(f"{case}: chaotic at {b.describe(b.chaotic)}; differs from fig4 at "
                     f"{_pct(float(np.mean(diff)))} of the points")
    if not changed:
        raise MissingCase("fig13")
    strong = [changed[c] for c in ("fig13", "fig14", "fig15a") if c in changed]
    status = _grade(bool(strong) and all(strong), any(changed.values()))
    return Verdict(status, f"fig4: chaotic at {ref.describe(ref.chaotic)}; " + "; ".join(lines),
                   ("the stroboscopic section cannot show the period of these cases (a second "
                    "frequency Lambda): chaos is a Lyapunov exponent above the threshold",))


def _obvious(cases: tuple[str, ...], expect: bool) -> Callable[[Evidence], Verdict]:
    def check(ev: Evidence) -> Verdict:
        ref = ev["fig4"]
        values = {c: _influence(ev[c], ref) for c in cases}
        hits = [(v >= OBVIOUS) == expect for v in values.values()]
        verdict = Verdict(_grade(all(hits), any(hits)),
                          "growth of the point spread over fig4 (median, in static "
                          "deflections): " + ", ".join(f"{c} {v:.3g}" for c, v in values.items()))
        return _with_statics(verdict, [ev[c] for c in cases], ref)

    return check


def _smaller_lambda_more(ev: Evidence) -> Verdict:
    ref = ev["fig4"]
    cases = [ev[c] for c in ("fig13", "fig14", "fig15a")]
    values = [_influence(c, ref) for c in cases]
    decreasing = values[0] > values[1] > values[2]
    verdict = Verdict(_grade(decreasing, values[0] == max(values)),
                      "B = 100 N m, Lambda = 0.1, 2, 40: growth of the point spread "
                      + ", ".join(f"{v:.3g}" for v in values) + " static deflections")
    return _with_statics(verdict, cases, ref)


# --------------------------------------------------------------------------- the list
_SHARE_RULE = (f"holds if the claimed motion covers >= {SHARE_HOLDS:.0%} of the grid points in "
               f"the range; partly if >= {SHARE_PARTLY:.0%} (of the range or of the range "
               f"widened by {APPROX:g}), or if it forms a region of width >= {MIN_WIDTH:g} within "
               f"{APPROX:g} of the range; either needs more than {MIN_POINTS_NEAR} point of it "
               f"within {APPROX:g} of the range")
_WINDOW_RULE = (f"holds if a chaotic region (consecutive points spanning >= {MIN_WIDTH:g} in "
                "Omega) lies in the range; partly if only a region without period "
                "(quasi-periodic) does")
_SHIFT_NOTE = ("; while the back flanks never touch this holds or fails by construction (a "
               "coordinate shift), which the verdict's basis says")

CLAIMS: tuple[Claim, ...] = (
    Claim("C1", "Sec. 3, on Fig. 3", "periodic (period-1) motion below the critical speed "
          "Omega ~ 0.7", ("fig3",),
          "holds if >= 95% of the points below 0.7 are period-1 and the first region of other "
          f"motion (width >= {MIN_WIDTH:g}) begins within {APPROX:g} of 0.7; partly if >= 80% "
          "are period-1",
          _fig3_periodic_below),
    Claim("C2", "Sec. 3, on Fig. 3", "then a chaotic region (before the 2T window, Omega ~ "
          "0.7-1)", ("fig3",), _WINDOW_RULE, _window("fig3", 0.7, 1.0)),
    Claim("C3", "Sec. 3, on Fig. 3", "2T-periodic motion at Omega ~ 1-1.2", ("fig3",),
          _SHARE_RULE, _motion_in_range("fig3", 2, 1.0, 1.2)),
    Claim("C4", "Sec. 3, on Fig. 3", "a second chaotic region (Omega ~ 1.2-1.4)", ("fig3",),
          _WINDOW_RULE, _window("fig3", 1.2, 1.4)),
    Claim("C5", "Sec. 3, on Fig. 3", "4T-periodic motion at Omega ~ 1.4-1.5", ("fig3",),
          _SHARE_RULE, _motion_in_range("fig3", 4, 1.4, 1.5)),
    Claim("C6", "Sec. 3, on Fig. 3", "non-periodic motion of unpredictable magnitude at higher "
          "Omega (1.5-3.2)", ("fig3",),
          "holds if >= 50% of the points in [1.5, 3.2] have no period and some are chaotic; "
          f"partly if a region (width >= {MIN_WIDTH:g}) without period exists there",
          _fig3_nonperiodic_high),
    Claim("C7", "Sec. 3, on Fig. 3", "single-periodic motion again for Omega > 3.2", ("fig3",),
          "holds if >= 95% of the points above 3.2 are period-1 and the last period-1 branch "
          f"starts within {2 * APPROX:g} of 3.2; partly if >= 50% are period-1",
          _fig3_period1_above),
    Claim("C8", "Conclusion (1); Fig. 3", "periodic -> chaos -> periodic as Omega increases",
          ("fig3",), "holds if period-1 at the lowest and the highest 5% of Omega and a chaotic "
          "window between; partly if the window is without period but not chaotic",
          _route_to_chaos),
    Claim("C9", "Sec. 3, on Fig. 4", "xi = 0.1 makes the chaotic region smaller than xi = 0.05",
          ("fig3", "fig4"), "holds if the chaotic Omega-length shrinks (from a non-zero one); "
          "partly if only the Omega-length without period shrinks",
          _damping_shrinks("fig3", "fig4")),
    Claim("C10", "Sec. 3, on Fig. 5", "xi = 0.2 leaves only single-periodic motion", ("fig5",),
          "holds if every point is period-1; partly if >= 90%", _only_period1("fig5")),
    Claim("C11", "Sec. 3 and Conclusion (2); Figs. 3-5", "increasing damping avoids chaos",
          ("fig3", "fig4", "fig5"), "holds if the chaotic Omega-length is non-zero at xi = 0.05, "
          "does not grow with xi and vanishes at 0.2; partly if that holds for the Omega-length "
          "without period", _damping_avoids_chaos),
    Claim("C12", "Sec. 3, on Figs. 6, 7", "X_pq at xi = 0.05 and 0.1: periodic, then chaotic "
          "and single-periodic regions", ("fig6", "fig7"),
          "holds if both start period-1, have a chaotic window and period-1 after the first "
          "bifurcation; partly if one does, or the windows have no period but no chaos",
          _pq_route),
    Claim("C13", "Sec. 3, on Fig. 8", "X_pq at xi = 0.2: single-periodic harmonic response, the "
          "vibration form does not change with speed", ("fig8",),
          "holds if every point is period-1 with one pq contact regime throughout; partly if "
          ">= 90% are period-1", _pq_harmonic),
    Claim("C14", "Sec. 3, on Fig. 9", "b = 30 um: the shape of the diagram does not change "
          "(against Fig. 4)", ("fig4", "fig9"),
          f"holds if the motion class agrees at >= {SHAPE_HOLDS:.0%} of the points; partly if "
          f">= {SHAPE_PARTLY:.0%}{_SHIFT_NOTE}",
          _backlash(_same_shape("fig9", "fig4"), "fig9", "fig4")),
    Claim("C15", "Sec. 3, on Fig. 9; Conclusion (3)", "b = 30 um: smaller dimensionless "
          "displacement X_sq whatever the speed", ("fig4", "fig9"),
          "holds if the largest point of the diagram is lower at >= 95% of the Omega values; "
          f"partly if at >= 50%{_SHIFT_NOTE}",
          _backlash(_smaller_displacement("fig9", "fig4"), "fig9", "fig4")),
    Claim("C16", "Sec. 3, on Fig. 10", "b = 30 um, X_pq: same shape as Fig. 7",
          ("fig7", "fig10"), f"as C14 (>= {SHAPE_HOLDS:.0%} / {SHAPE_PARTLY:.0%})",
          _backlash(_same_shape("fig10", "fig7"), "fig10", "fig7")),
    Claim("C17", "Sec. 3, on Fig. 10; Conclusion (3)", "b = 30 um: smaller dimensionless "
          "displacement X_pq", ("fig7", "fig10"), "as C15",
          _backlash(_smaller_displacement("fig10", "fig7"), "fig10", "fig7")),
    Claim("C18", "Sec. 3, on Figs. 9, 10", "reducing the backlash does not avoid chaos",
          ("fig9",), f"holds if Fig. 9 has a chaotic region (width >= {MIN_WIDTH:g}); partly "
          f"if only a region without period{_SHIFT_NOTE} (Fig. 9's chaos is then Fig. 4's)",
          _backlash(_chaos_persists("fig9"), "fig9", "fig4")),
    Claim("C19", "Sec. 3, on Fig. 11; Conclusion (4)", "E = 20 um shifts the diagram to lower "
          "Omega (against Fig. 4)", ("fig4", "fig11"),
          "holds if both the first bifurcation (the first region of other motion than period-1, "
          f"width >= {MIN_WIDTH:g}) and the best-matching shift of the pattern move down by at "
          "least one grid step; partly if one does", _shift_left("fig11", "fig4")),
    Claim("C20", "Sec. 3, on Fig. 11; Conclusion (4)", "E = 20 um does not change the "
          "displacement amplitude (X_sq)", ("fig4", "fig11"),
          f"holds if the extent of the diagram changes by <= {SAME_AMPLITUDE:.0%}; partly if by "
          f"<= {3 * SAME_AMPLITUDE:.0%}", _same_amplitude("fig11", "fig4")),
    Claim("C21", "Sec. 3, on Fig. 12", "E = 20 um, X_pq: the diagram translates to lower Omega "
          "(against Fig. 7)", ("fig7", "fig12"), "as C19", _shift_left("fig12", "fig7")),
    Claim("C22", "Sec. 3, on Fig. 12", "E = 20 um, X_pq: the displacement does not change",
          ("fig7", "fig12"), "as C20", _same_amplitude("fig12", "fig7")),
    Claim("C23", "Sec. 3, on Figs. 11, 12; Conclusion (4)", "increasing the meshing error does "
          "not avoid chaos", ("fig11",), f"holds if Fig. 11 has a chaotic region (width >= "
          f"{MIN_WIDTH:g}); partly if only a region without period", _chaos_persists("fig11")),
    Claim("C24", "Sec. 3, on Figs. 13-15; Conclusion (5)", "the load noise changes the chaotic "
          "regions (against Fig. 4)", ("fig4", "fig13"),
          f"holds if every B = 100 N m case has a region (width >= {MIN_WIDTH:g}) whose chaos "
          "(Lyapunov exponent) differs from Fig. 4; partly if any noise case has", _chaos_changes),
    Claim("C25", "Sec. 3, on Figs. 13, 14, 15a", "B1 = B2 = 100 N m influences the vibration "
          "obviously", ("fig4", "fig13", "fig14", "fig15a"),
          f"holds if in every case the point spread grows (median over Omega) by >= {OBVIOUS:g} "
          "static deflections; partly if in some", _obvious(("fig13", "fig14", "fig15a"), True)),
    Claim("C26", "Sec. 3, on Figs. 13, 14, 15a", "with B = 100 N m a smaller Lambda gives more "
          "obvious local vibration superposition", ("fig4", "fig13", "fig14", "fig15a"),
          "holds if the growth of the point spread decreases from Lambda = 0.1 to 2 to 40; "
          "partly if Lambda = 0.1 gives the largest", _smaller_lambda_more),
    Claim("C27", "Sec. 3, on Figs. 15b-d", "B1 = B2 = 10 N m does not influence the vibration "
          "obviously", ("fig4", "fig15b", "fig15c", "fig15d"),
          f"holds if in every case the point spread grows by < {OBVIOUS:g} static deflections; "
          "partly if in some", _obvious(("fig15b", "fig15c", "fig15d"), False)),
)


def evaluate_claim(claim: Claim, evidence: Evidence) -> Verdict:
    """The verdict of one claim; ``not assessed`` when a case it needs is missing."""
    missing = [c for c in claim.cases if not evidence.has(c)]
    if missing:
        return Verdict(NOT_ASSESSED, f"needs {', '.join(missing)} (not run)")
    try:
        return claim.check(evidence)
    except MissingCase as exc:
        return Verdict(NOT_ASSESSED, f"needs {exc.args[0]} (not run)")


def evaluate(results: Mapping[str, xr.Dataset], direction: str = "up"
             ) -> dict[str, Verdict]:
    """Every claim's verdict from the case results of one interpretation (keyed by case name),
    read on the sweep ``direction``."""
    ev = Evidence(results, direction)
    return {c.id: evaluate_claim(c, ev) for c in CLAIMS}
