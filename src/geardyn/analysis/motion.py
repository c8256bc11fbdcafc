"""Motion classes from the period classifier and a finite-time Lyapunov exponent with its error.

Every point gets one label, decided from what was measured:

``period-k``        the Poincare samples repeat after k forcing periods (``period`` k >= 1 of
                    :func:`geardyn.analysis.lanes.lane_periods`);
``chaotic``         no period found and the largest exponent is positive beyond its
                    uncertainty: lambda > u;
``quasi-periodic``  no period found and the exponent is zero within its uncertainty,
                    |lambda| <= u (a torus: the neutral direction along it gives lambda = 0);
                    where the point has no true Poincare section (a second excitation at a
                    frequency incommensurate with Omega, ``section`` False) also lambda < -u:
                    the response locked to two incommensurate forcings is a torus whose
                    phases are not states, so its largest exponent is negative;
``unresolved``      no period found, a true section, and a clearly negative exponent,
                    lambda < -u: a periodic attractor of period longer than the classifier's
                    ``max_period``, or a transient that had not settled;
``unbounded``       the integration diverged (``period`` -1);
``non-periodic``    no period found and no exponent available (NaN: not computed, diverged).

The uncertainty of a finite-time exponent measured over a duration T is

    u = max(z * lyapunov_err, c / T)

with ``lyapunov_err`` the 1-sigma statistical standard error (spread of block means over the
run, per unit time), z = :data:`LYAPUNOV_Z` = 3 and c = :data:`LYAPUNOV_FLOOR` = 5. The floor is
the finite-time bias of a zero exponent: on a torus the measured exponent is
(ln|v(T)| - ln|v(0)|) / T for a tangent vector v that stays bounded but whose length varies
around the torus (and with what is left of its alignment), so |lambda_T| <= (range of ln|v|) / T,
an O(1/T) bias that the block spread need not show (a nearly uniform torus has a tiny
statistical error). c = 5 allows a length ratio e^5 ~ 150; measured ranges of ln|v| on forced
van der Pol tori are 0.6-1.7 (docs/lyapunov.md, classification).
A statistical error alone can therefore not make a torus chaotic, and a weakly attracting long
period orbit (lambda > -c/T) reads quasi-periodic: at a finite T the two cannot be told apart.
"""

from __future__ import annotations

import numpy as np

from geardyn.core.plan import forcing_period, periods_covering

__all__ = [
    "CHAOTIC",
    "LYAPUNOV_FLOOR",
    "LYAPUNOV_Z",
    "MOTION_CLASSES",
    "NONPERIODIC",
    "QUASI_PERIODIC",
    "UNBOUNDED",
    "UNRESOLVED",
    "exponent_sign",
    "lyapunov_uncertainty",
    "motion_classes",
    "period_label",
    "averaging_time",
    "motion_variable",
    "rule_text",
]

#: Standard errors by which an exponent must clear zero to count as positive or negative.
LYAPUNOV_Z = 3.0
#: Finite-time floor c of the uncertainty, c / T [dimensionless: a log of a stretch ratio].
LYAPUNOV_FLOOR = 5.0

CHAOTIC = "chaotic"
QUASI_PERIODIC = "quasi-periodic"
UNRESOLVED = "unresolved"
UNBOUNDED = "unbounded"
#: No period found and no exponent available (not computed, or its integration diverged).
NONPERIODIC = "non-periodic"
#: Every label other than ``period-k``.
MOTION_CLASSES: tuple[str, ...] = (CHAOTIC, QUASI_PERIODIC, UNRESOLVED, UNBOUNDED, NONPERIODIC)


def period_label(k: int) -> str:
    """The label of a period-k point: ``period-k``."""
    return f"period-{int(k)}"


def lyapunov_uncertainty(lyapunov_err: np.ndarray | float | None, duration: np.ndarray | float,
                         z: float = LYAPUNOV_Z, floor: float = LYAPUNOV_FLOOR) -> np.ndarray:
    """u = max(z * lyapunov_err, floor / duration) [1/time] per point (see the module).

    ``lyapunov_err`` NaN or None (no error measured): the floor alone. ``duration``: the time the
    exponent was averaged over, scalar or per point (> 0)."""
    duration = np.asarray(duration, dtype=float)
    if np.any(~(duration > 0)):
        raise ValueError("duration must be > 0 (the time the exponent was averaged over)")
    if z < 0 or floor < 0:
        raise ValueError("z and floor must be >= 0")
    base = floor / duration
    if lyapunov_err is None:
        return base
    err = np.asarray(lyapunov_err, dtype=float)
    stat = np.where(np.isfinite(err), z * np.abs(np.where(np.isfinite(err), err, 0.0)), 0.0)
    return np.maximum(stat, base)


def exponent_sign(lyapunov: np.ndarray, lyapunov_err: np.ndarray | None,
                  duration: np.ndarray | float, z: float = LYAPUNOV_Z,
                  floor: float = LYAPUNOV_FLOOR) -> np.ndarray:
    """+1 where lambda > u, -1 where lambda < -u, 0 where |lambda| <= u, and 0 where lambda is
    NaN (check with ``np.isnan``); u from :func:`lyapunov_uncertainty`."""
    lam = np.asarray(lyapunov, dtype=float)
    u = lyapunov_uncertainty(lyapunov_err, duration, z, floor)
    with np.errstate(invalid="ignore"):
        return np.where(lam > u, 1, np.where(lam < -u, -1, 0)).astype(np.int64)


def motion_classes(period: np.ndarray, lyapunov: np.ndarray,
                   lyapunov_err: np.ndarray | None, duration: np.ndarray | float,
                   section: np.ndarray | bool = True, z: float = LYAPUNOV_Z,
                   floor: float = LYAPUNOV_FLOOR) -> np.ndarray:
    """Label per point (see the module docs).

    period
        k >= 1 period-k, 0 no period <= max_period found, -1 unbounded.
    lyapunov, lyapunov_err
        Largest finite-time exponent and its 1-sigma statistical error [1/time]; NaN where not
        computed (``lyapunov_err`` None or NaN: the finite-time floor alone).
    duration
        Time each exponent was averaged over (scalar or per point).
    section
        True where the samples form a true Poincare section (every excitation commensurate);
        False where a second excitation is incommensurate (no period exists).
    """
    period = np.asarray(period)
    lam = np.broadcast_to(np.asarray(lyapunov, dtype=float), period.shape)
    duration = np.broadcast_to(np.asarray(duration, dtype=float), period.shape)
    err = None if lyapunov_err is None else np.broadcast_to(
        np.asarray(lyapunov_err, dtype=float), period.shape)
    true_section = np.broadcast_to(np.asarray(section, dtype=bool), period.shape)
    need = (period == 0) & np.isfinite(lam)
    sign = np.zeros(period.shape, np.int64)
    if np.any(need):
        sign[need] = exponent_sign(lam[need], None if err is None else err[need],
                                   duration[need], z, floor)
    out = np.empty(period.shape, dtype=object)
    for i, k in np.ndenumerate(period):
        if k < 0:
            out[i] = UNBOUNDED
        elif k >= 1:
            out[i] = period_label(k)
        elif not need[i]:
            out[i] = NONPERIODIC
        elif sign[i] > 0:
            out[i] = CHAOTIC
        elif sign[i] < 0 and true_section[i]:
            out[i] = UNRESOLVED
        else:
            out[i] = QUASI_PERIODIC
    return out.astype(str)


def rule_text(z: float = LYAPUNOV_Z, floor: float = LYAPUNOV_FLOOR) -> str:
    """The classification rule in one line, for reports and dataset attributes."""
    return (f"no period found: chaotic if lambda > u, quasi-periodic if |lambda| <= u (or "
            f"lambda < -u without a true section), unresolved if lambda < -u, with "
            f"u = max({z:g} x standard error, {floor:g} / T) and T the averaging time")


def averaging_time(duration: float, omega: np.ndarray) -> np.ndarray:
    """Time each lane's exponent is averaged over when ``duration`` is asked for: whole forcing
    periods 2 pi / omega, rounded up, at least one (as :func:`geardyn.lyapunov` does) [time]."""
    period = forcing_period(np.asarray(omega, dtype=float))
    return np.maximum(1.0, periods_covering(duration, period)) * period


def motion_variable(period: np.ndarray, lyapunov: np.ndarray, lyapunov_err: np.ndarray,
                    duration: np.ndarray, section: np.ndarray, z: float = LYAPUNOV_Z,
                    floor: float = LYAPUNOV_FLOOR) -> tuple[np.ndarray, dict[str, str]]:
    """Labels of :func:`motion_classes` with the attributes a dataset's ``motion`` carries."""
    labels = motion_classes(period, lyapunov, lyapunov_err, duration, section, z, floor)
    return labels, {
        "long_name": "motion class",
        "meaning": "period-k; chaotic (exponent positive beyond its uncertainty); "
                   "quasi-periodic (exponent zero within it, or a response locked to "
                   "incommensurate forcings); unresolved (no period <= max_period found and the "
                   "exponent clearly negative: a longer period or not settled); non-periodic "
                   "(no exponent); unbounded. See geardyn.analysis.motion",
        "rule": rule_text(z, floor)}
