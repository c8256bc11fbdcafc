"""Contact-loss regime of a mesh (the classic gear-rattle classification).

From the extremes of the dead-zone switching functions X - b (drive flank) and X + b (back flank)
over the sampled motion, and the located edge crossings:

``none``    the teeth never separate (always on the drive flank, or always on the back flank);
``single``  they separate but the back flanks never touch (single-sided impacts);
``double``  both flanks are hit (double-sided impacts, back-flank contact);
``unbounded`` the lane diverged.
"""

from __future__ import annotations

import numpy as np

from geardyn.core.status import Status

REGIMES = ("none", "single", "double")
UNBOUNDED_LABEL = "unbounded"


def contact_regime(event_min: np.ndarray, event_max: np.ndarray, crossings: np.ndarray,
                   drive: int, back: int, status: np.ndarray) -> np.ndarray:
    """Regime label per lane for one mesh whose drive/back switching functions are the events
    ``drive`` (X - b) and ``back`` (X + b)."""
    d_min, d_max = event_min[:, drive], event_max[:, drive]
    b_min, b_max = event_min[:, back], event_max[:, back]
    d_cross, b_cross = crossings[:, drive] > 0, crossings[:, back] > 0
    on_drive = d_max > 0.0
    leaves_drive = (d_min <= 0.0) | d_cross
    on_back = (b_min < 0.0) | b_cross
    leaves_back = (b_max >= 0.0) | b_cross
    out = np.where(on_drive & on_back, "double", "single").astype(object)
    out[on_drive & ~leaves_drive] = "none"
    out[on_back & ~leaves_back & ~on_drive] = "none"
    out[np.asarray(status) != Status.OK] = UNBOUNDED_LABEL
    return out.astype(str)
