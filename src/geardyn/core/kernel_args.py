"""Structured arguments of the sweep kernel (numba accepts NamedTuples of arrays and scalars).

The generated kernel modules import these classes by name, so they live in an importable module
of the core (numba's on-disk cache pickles a NamedTuple's type by reference). Arrays are indexed
by lane (the caller's lane order; nothing is reordered).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class LaneInputs(NamedTuple):
    """Per-lane inputs: coefficient rows P[L, n_p], start states Y0[L, ns], step H[L] and forcing
    frequency OMEGA[L] (time units of the model), start time T0[L] (whole periods), transient and
    its limit in grid steps, grid steps between section samples."""

    P: np.ndarray
    Y0: np.ndarray
    H: np.ndarray
    OMEGA: np.ndarray
    T0: np.ndarray
    n_transient: np.ndarray
    n_transient_max: np.ndarray
    sample_every: np.ndarray


class SweepConfig(NamedTuple):
    """Settings shared by every lane: convergence tolerance (0: off) and depth (section periods),
    section samples per lane, edge location on/off, divergence bound, number of events and
    observables, slots per worker (the lane block's width)."""

    conv_tol: float
    conv_depth: int
    n_samples: int
    locate: bool
    bound: float
    n_ev: int
    n_obs: int
    width: int


class Schedule(NamedTuple):
    """Which worker runs which lanes: worker w takes the lanes queue[start[w]:start[w + 1]] in
    that order; lane l has n_per[l] steps per period and its phase table at S_TAB/C_TAB[tab[l]:]
    (2 n_per + 1 half-step points of sin and cos of the forcing phase). ``chain`` (empty: none)
    chains lanes, a sweep by continuation: chain[l] is the lane that starts, in the slot where
    lane l ended and only if it ended well, from l's final state at l's end time (-1: none);
    the queue then holds the chains' first lanes only."""

    start: np.ndarray
    queue: np.ndarray
    n_per: np.ndarray
    tab: np.ndarray
    S_TAB: np.ndarray
    C_TAB: np.ndarray
    chain: np.ndarray


class LaneOutputs(NamedTuple):
    """Per-lane results, preallocated by the caller and filled by the kernel: section samples
    [L, n_samples, ns] (NaN where diverged), final state [L, ns], status [L], extremes of the
    events [L, n_ev], located crossings while sampling [L, n_ev], extremes and RMS of the
    observables [L, n_obs], steps that reached the split limit [L], transient used in grid
    steps [L], convergence flag [L] (1 settled, 0 limit reached, -1 test off), grid steps
    integrated [L] (zeros in, added to by the kernel)."""

    samples: np.ndarray
    final: np.ndarray
    status: np.ndarray
    gmin: np.ndarray
    gmax: np.ndarray
    ncross: np.ndarray
    omax: np.ndarray
    omin: np.ndarray
    orms: np.ndarray
    unresolved: np.ndarray
    transient_steps: np.ndarray
    converged: np.ndarray
    steps: np.ndarray
