"""The seed paper's claims (``shared/model-notes.md``) as checks computed from case results.

Every check reads the motion labels (period classifier plus Lyapunov exponent, see
:mod:`geardyn.reproduction.motion`) and the stroboscopic samples of the cases it names, and
returns a :class:`Verdict`: ``holds``, ``partly holds`` or ``fails``, with the measured Omega
ranges and numbers; ``not assessed`` when a case it needs was not run. Nothing is typed by hand:
change the model or the numerics and the verdicts follow.

Rules shared by the checks (module constants, stated in the report):

* "at Omega ~ a-b" is read on the grid points in [a, b]; the claimed motion must cover at least
  :data:`SHARE_HOLDS` of them to hold, at least :data:`SHARE_PARTLY` (or appear within
  :data:`APPROX` of the range) to partly hold;
* a window (of chaos, of non-periodic motion) needs :data:`MIN_RUN` consecutive points;
* "chaos" is a positive Lyapunov exponent; the paper, like most bifurcation studies, calls every
  cloud of points chaos, so a check whose chaos turns out quasi-periodic partly holds;
* "obvious" influence of the load noise: the spread of the stroboscopic points grows, in the
  median over Omega, by at least :data:`OBVIOUS` of the static mesh deflection.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
import xarray as xr

from geardyn.reproduction.evidence import Branch, Evidence, MissingCase, format_intervals

__all__ = ["CLAIMS", "STATUSES", "Claim", "Verdict", "evaluate", "evaluate_claim"]

HOLDS, PARTLY, FAILS, NOT_ASSESSED = "holds", "partly holds", "fails", "not assessed"
STATUSES: tuple[str, ...] = (HOLDS, PARTLY, FAILS, NOT_ASSESSED)

#: Tolerance of the paper's "Omega ~ a" (absolute, in Omega).
APPROX = 0.1
#: Share of a claimed Omega range that must show the claimed motion to hold / partly hold.
SHARE_HOLDS = 0.8
SHARE_PARTLY = 0.2
#: Consecutive grid points that make a window.
MIN_RUN = 2
#: Share of Omega whose motion must agree for "the same shape" to hold / partly hold.
SHAPE_HOLDS = 0.9
SHAPE_PARTLY = 0.7
#: "Obvious" influence: median growth of the point spread, as a share of the static deflection.
OBVIOUS = 0.1
#: Relative tolerance of "unchanged" amplitudes (holds within it, partly within 3 times it).
SAME_AMPLITUDE = 0.1


@dataclass(frozen=True)
class Verdict:
    status: str
    measured: str
    details: tuple[str, ...] = ()


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
        near = b.runs(mask & b.within(lo - APPROX, hi + APPROX))
        status = _grade(share >= SHARE_HOLDS,
                        share >= SHARE_PARTLY or wide >= SHARE_PARTLY or bool(near))
        return Verdict(status,
                       f"period-{k} on {_pct(share)} of the {n} points in [{lo:g}, {hi:g}]; "
                       f"period-{k} at Omega = {b.describe(mask)}")

    return check


def _window(case: str, lo: float, hi: float) -> Callable[[Evidence], Verdict]:
    """A chaotic window in Omega ~ (lo, hi)."""

    def check(ev: Evidence) -> Verdict:
        b = ev[case]
        inside = b.within(lo, hi)
        chaos = b.runs(b.chaotic & inside, MIN_RUN)
        cloud = b.runs(b.nonperiodic & inside, MIN_RUN)
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
        chaos, cloud = b.runs(b.chaotic, MIN_RUN), b.runs(b.nonperiodic, MIN_RUN)
        return Verdict(_grade(bool(chaos), bool(cloud)),
                       f"chaotic at {_fmt(chaos)}; without period at {_fmt(cloud)}")

    return check


def _summary_line(b: Branch) -> str:
    return (f"{b.case}: chaotic over {b.length(b.chaotic):.3g}, without period over "
            f"{b.length(b.nonperiodic):.3g} (Omega-length)")


# --------------------------------------------------------------------------- Fig. 3
def _fig3_periodic_below(ev: Evidence) -> Verdict:
    b = ev["fig3"]
    share, n = b.share(b.period(1), b.omega[0], 0.7)
    onset = b.first(b.bifurcated)
    loss = b.first(np.any(b.contact != "none", axis=1))
    near = onset is not None and abs(onset - 0.7) <= APPROX
    status = _grade(share >= 0.95 and near, share >= 0.95 or share >= SHARE_HOLDS)
    return Verdict(status,
                   f"period-1 on {_pct(share)} of the {n} points below 0.7; first other motion "
                   f"at Omega = {_num(onset)}",
                   (f"teeth first separate (contact loss) at Omega = {_num(loss)}",))


def _num(x: float | None) -> str:
    return "none" if x is None else f"{x:.3g}"


def _fig3_nonperiodic_high(ev: Evidence) -> Verdict:
    b = ev["fig3"]
    share, n = b.share(b.nonperiodic, 1.5, 3.2)
    chaos = b.runs(b.chaotic & b.within(1.5, 3.2), MIN_RUN)
    cloud = b.runs(b.nonperiodic & b.within(1.5, 3.2), MIN_RUN)
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
    chaos = b.runs(b.chaotic, MIN_RUN)
    cloud = b.runs(b.nonperiodic, MIN_RUN)
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
        chaos, cloud = b.runs(b.chaotic, MIN_RUN), b.runs(b.nonperiodic, MIN_RUN)
        onset = b.first(b.bifurcated)
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
        return Verdict(_grade(share >= 0.95, share >= 0.5),
                       f"the largest {b.state} of the diagram is lower than in {ref} at "
                       f"{_pct(share)} of the points (median drop {drop:.3g})",
                       (f"extent of the whole diagram (peak-to-peak) {b.extent:.3g} against "
                        f"{a.extent:.3g} in {ref} (ratio {amp:.3g})",))

    return check


def _shift_left(case: str, ref: str) -> Callable[[Evidence], Verdict]:
    def check(ev: Evidence) -> Verdict:
        a, b = ev[ref], ev[case]
        onset_a, onset_b = a.first(a.bifurcated), b.first(b.bifurcated)
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


def _chaos_changes(ev: Evidence) -> Verdict:
    ref = ev["fig4"]
    lines, changed = [], {}
    for case in NOISE_CASES:
        if not ev.has(case):
            continue
        b = ev[case]
        diff = b.chaotic != ref.chaotic
        changed[case] = bool(b.runs(diff, MIN_RUN))
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
        return Verdict(_grade(all(hits), any(hits)),
                       "growth of the point spread over fig4 (median, in static deflections): "
                       + ", ".join(f"{c} {v:.3g}" for c, v in values.items()))

    return check


def _smaller_lambda_more(ev: Evidence) -> Verdict:
    ref = ev["fig4"]
    values = [_influence(ev[c], ref) for c in ("fig13", "fig14", "fig15a")]
    decreasing = values[0] > values[1] > values[2]
    return Verdict(_grade(decreasing, values[0] == max(values)),
                   "B = 100 N m, Lambda = 0.1, 2, 40: growth of the point spread "
                   + ", ".join(f"{v:.3g}" for v in values) + " static deflections")


# --------------------------------------------------------------------------- the list
_SHARE_RULE = (f"holds if the claimed motion covers >= {SHARE_HOLDS:.0%} of the grid points in "
               f"the range; partly if >= {SHARE_PARTLY:.0%}, or if it appears within "
               f"{APPROX:g} of the range")
_WINDOW_RULE = (f"holds if >= {MIN_RUN} consecutive chaotic points lie in the range; partly if "
                "only points without period (quasi-periodic) do")

CLAIMS: tuple[Claim, ...] = (
    Claim("C1", "Sec. 3, on Fig. 3", "periodic (period-1) motion below the critical speed "
          "Omega ~ 0.7", ("fig3",),
          "holds if >= 95% of the points below 0.7 are period-1 and the first other motion is "
          f"within {APPROX:g} of 0.7; partly if >= 80% are period-1",
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
          f"partly if a window of >= {MIN_RUN} points without period exists there",
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
          f">= {SHAPE_PARTLY:.0%}", _same_shape("fig9", "fig4")),
    Claim("C15", "Sec. 3, on Fig. 9; Conclusion (3)", "b = 30 um: smaller dimensionless "
          "displacement X_sq whatever the speed", ("fig4", "fig9"),
          "holds if the largest point of the diagram is lower at >= 95% of the Omega values; "
          "partly if at >= 50%", _smaller_displacement("fig9", "fig4")),
    Claim("C16", "Sec. 3, on Fig. 10", "b = 30 um, X_pq: same shape as Fig. 7",
          ("fig7", "fig10"), f"as C14 (>= {SHAPE_HOLDS:.0%} / {SHAPE_PARTLY:.0%})",
          _same_shape("fig10", "fig7")),
    Claim("C17", "Sec. 3, on Fig. 10; Conclusion (3)", "b = 30 um: smaller dimensionless "
          "displacement X_pq", ("fig7", "fig10"), "as C15",
          _smaller_displacement("fig10", "fig7")),
    Claim("C18", "Sec. 3, on Figs. 9, 10", "reducing the backlash does not avoid chaos",
          ("fig9",), f"holds if Fig. 9 has a chaotic window of >= {MIN_RUN} points; partly if "
          "only a window without period", _chaos_persists("fig9")),
    Claim("C19", "Sec. 3, on Fig. 11; Conclusion (4)", "E = 20 um shifts the diagram to lower "
          "Omega (against Fig. 4)", ("fig4", "fig11"),
          "holds if both the first bifurcation and the best-matching shift of the pattern move "
          "down by at least one grid step; partly if one does", _shift_left("fig11", "fig4")),
    Claim("C20", "Sec. 3, on Fig. 11; Conclusion (4)", "E = 20 um does not change the "
          "displacement amplitude (X_sq)", ("fig4", "fig11"),
          f"holds if the extent of the diagram changes by <= {SAME_AMPLITUDE:.0%}; partly if by "
          f"<= {3 * SAME_AMPLITUDE:.0%}", _same_amplitude("fig11", "fig4")),
    Claim("C21", "Sec. 3, on Fig. 12", "E = 20 um, X_pq: the diagram translates to lower Omega "
          "(against Fig. 7)", ("fig7", "fig12"), "as C19", _shift_left("fig12", "fig7")),
    Claim("C22", "Sec. 3, on Fig. 12", "E = 20 um, X_pq: the displacement does not change",
          ("fig7", "fig12"), "as C20", _same_amplitude("fig12", "fig7")),
    Claim("C23", "Sec. 3, on Figs. 11, 12; Conclusion (4)", "increasing the meshing error does "
          "not avoid chaos", ("fig11",), "as C18, on Fig. 11", _chaos_persists("fig11")),
    Claim("C24", "Sec. 3, on Figs. 13-15; Conclusion (5)", "the load noise changes the chaotic "
          "regions (against Fig. 4)", ("fig4", "fig13"),
          f"holds if every B = 100 N m case has >= {MIN_RUN} consecutive points whose chaos "
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
