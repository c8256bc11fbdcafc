"""Motion classes of a bifurcation sweep, from the period classifier and Lyapunov exponents.

Every swept point gets one label:

``period-k``        the motion repeats after k mesh periods: ``ds["period"]`` of
                    :func:`geardyn.bifurcation` (its Poincare section is once per mesh period, or
                    once per common period when a load fluctuation at Lambda is commensurate);
``chaotic``         no period found and the largest Lyapunov exponent exceeds
                    :data:`LYAPUNOV_CHAOS` (per unit tau);
``quasi-periodic``  no period found and the exponent does not exceed it: motion on a torus, the
                    two-frequency response to a load fluctuation at Lambda (Eq. 14), or a period
                    longer than the classifier's ``max_period``;
``unbounded``       the integration diverged;
``non-periodic``    no period found and no Lyapunov exponent available.

The Lyapunov exponent is only needed (and only computed) where the period classifier finds no
period. With a load fluctuation at a Lambda incommensurate with Omega no stroboscopic section
shows the motion's period (``period`` is 0 there), so the exponent alone separates chaos from
quasi-periodic motion.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "CHAOTIC",
    "LYAPUNOV_CHAOS",
    "NONPERIODIC",
    "QUASI_PERIODIC",
    "UNBOUNDED",
    "intervals",
    "is_nonperiodic",
    "motion_labels",
    "period_label",
]

#: Largest Lyapunov exponent [1/tau] above which motion without a period counts as chaotic.
#: Measured with the default Lyapunov settings on the paper's device (xi = 0.05, consistent):
#: quasi-periodic points give |lambda| <= 6e-4, the periodic ones <= -1.5e-3.
LYAPUNOV_CHAOS = 2.0e-3

CHAOTIC = "chaotic"
QUASI_PERIODIC = "quasi-periodic"
UNBOUNDED = "unbounded"
#: No period found and no exponent available (not computed, or its integration diverged).
NONPERIODIC = "non-periodic"


def period_label(k: int) -> str:
    return f"period-{int(k)}"


def motion_labels(period: np.ndarray, lyapunov: np.ndarray,
                  threshold: float = LYAPUNOV_CHAOS) -> np.ndarray:
    """Label per point (see the module docs) from ``period`` (k >= 1, 0 none found,
    -1 unbounded) and the largest Lyapunov exponent (NaN where not computed)."""
    period = np.asarray(period)
    lam = np.asarray(lyapunov, dtype=float)
    out = np.empty(period.shape, dtype=object)
    for i, k in np.ndenumerate(period):
        if k < 0:
            out[i] = UNBOUNDED
        elif k >= 1:
            out[i] = period_label(k)
        elif np.isnan(lam[i]):
            out[i] = NONPERIODIC
        else:
            out[i] = CHAOTIC if lam[i] > threshold else QUASI_PERIODIC
    return out.astype(str)


def is_nonperiodic(labels: np.ndarray) -> np.ndarray:
    """No period found: chaotic, quasi-periodic or unresolved (the paper's diagrams show these
    as clouds of points)."""
    labels = np.asarray(labels)
    return np.isin(labels, (CHAOTIC, QUASI_PERIODIC, NONPERIODIC))


def intervals(x: np.ndarray, mask: np.ndarray) -> list[tuple[float, float, int]]:
    """Maximal runs of consecutive points (in ascending ``x``) where ``mask`` holds:
    (first x, last x, number of points)."""
    x = np.asarray(x, dtype=float)
    mask = np.asarray(mask, dtype=bool)
    order = np.argsort(x, kind="stable")
    xs, ms = x[order], mask[order]
    out: list[tuple[float, float, int]] = []
    start = None
    for i, m in enumerate(ms):
        if m and start is None:
            start = i
        if start is not None and (not m or i == ms.size - 1):
            end = i if m else i - 1
            out.append((float(xs[start]), float(xs[end]), end - start + 1))
            start = None
    return out
