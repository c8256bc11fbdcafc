"""The reduced CATT device (one planet-set block, four states) in the one form.

The physics of :func:`geardyn.models.catt_kernels.catt_rhs` for one (equivalent) planet set,
written once as per-lane scalar functions (:mod:`geardyn.core.one_form`): ``y = (X_sq, X_sq',
X_pq, X_pq')``, ``p`` the lane's coefficients by name (the vector of
:func:`geardyn.models.catt.catt_layout` for one set: :data:`~geardyn.models.derived.CATT_HEADER`,
:data:`~geardyn.models.derived.CATT_BLOCK`, then the stiffness harmonics), ``s, c`` sin and cos
of the mesh phase. The engine generates every layout from them (trajectory, lane blocks, the
sweep's fused loop).

* The stiffness harmonics: their number fixes the coefficient tuple's length, so each number of
  harmonics is its own one form (:func:`reduced_kernel`), whose series
  :func:`~geardyn.models.elements.harmonic_factors` writes out term by term (no loop, no libm
  call: every lane vectorises, one harmonic or many).
* The load fluctuation at Lambda: its sines by :func:`~geardyn.models.catt_kernels.load_sin`
  (arithmetic), taken where either amplitude (``f_c1``, ``f_p1``) is non-zero, as the general
  model takes them: under ``if loud(p):`` (:func:`geardyn.core.one_form.loud`), the amplitudes
  being the one form's ``quiet`` coefficients. A lane without the fluctuation (the paper's
  workload) runs a copy of the sweep's loop where the test is the constant False (the sines
  dead code), a lane with it a copy where it is True (no test, no select: the loop vectorises
  as the general model's arithmetic).
"""

from __future__ import annotations

import functools

import numba as nb

from geardyn.core.kernel_source import KernelSource
from geardyn.core.one_form import OneForm, loud
from geardyn.models.catt_kernels import load_sin
from geardyn.models.derived import CATT_BLOCK, CATT_HEADER, catt_harmonics
from geardyn.models.elements import dead_zone, harmonic_factors

_JIT = {"cache": True, "error_model": "numpy", "boundscheck": False}
#: The index of the first stiffness harmonic in the coefficient vector (after the header and
#: the planet set's block): the harmonics are the tuple's tail, ``p[HARMONICS:]``.
HARMONICS = CATT_HEADER.size + CATT_BLOCK.size
#: The coefficients that switch the load fluctuation on (the one form's ``quiet``).
LOAD_AMPLITUDES = ("f_c1", "f_p1")


@nb.njit(**_JIT)
def catt_reduced_rhs(t, y, p, s, c):
    """dy/dt of the reduced device: Eq. (10) (corrected) for one planet set whose carrier
    coupling ``k_sq_c``, ``c_sq_c`` is the N sets' together."""
    xs, vs, xp, vp = y
    ks, kp = harmonic_factors(p[HARMONICS:], 2, s, c)
    om2 = p.Omega * p.Omega
    load_c = p.f_c0
    sin_l1 = 0.0
    if loud(p):  # the load fluctuates (f_c1 or f_p1 non-zero; a constant in the lane forms)
        load_c += p.f_c1 * load_sin(p.Lambda * t + p.psi2)
        sin_l1 = load_sin(p.Lambda * t + p.psi1)
    load_p = p.f_p0 + p.f_p1 * sin_l1
    gs = ks * dead_zone(xs, p.b_sq)
    gp = kp * dead_zone(xp, p.b_pq)
    carrier = 0.0 + (p.k_sq_c * gs + p.c_sq_c * vs)  # as the general model sums its sets
    f_sq = p.k_sq_q * gs + p.c_sq_q * vs
    f_pq = p.k_pq_q * gp + p.c_pq_q * vp
    f_pp = p.k_pq_p * gp + p.c_pq_p * vp
    d1 = -f_sq + f_pq + om2 * (p.E_sq_s * s + p.E_sq_c * c)
    d3 = f_sq - f_pq - f_pp + load_p + om2 * (p.E_pq_s * s + p.E_pq_c * c)
    return (vs, d1 + (load_c - carrier), vp, d3)


@nb.njit(**_JIT)
def catt_reduced_events(t, y, p, s, c):
    """Dead-zone edges: X - b and X + b of the sun-inside and the inside-outside mesh."""
    return (y[0] - p.b_sq, y[0] + p.b_sq, y[2] - p.b_pq, y[2] + p.b_pq)


@nb.njit(**_JIT)
def catt_reduced_observe(t, y, p, s, c):
    """Dynamic mesh forces [N]: sun-inside, inside-outside (of one planet set)."""
    ks, kp = harmonic_factors(p[HARMONICS:], 2, s, c)
    gs = ks * dead_zone(y[0], p.b_sq)
    gp = kp * dead_zone(y[2], p.b_pq)
    return (p.force_scale * (p.k_sq_q * gs + p.c_sq_q * y[1]),
            p.force_scale * (p.k_pq_q * gp + p.c_pq_q * y[3]))


def coefficient_names(n_harmonics: int) -> tuple[str, ...]:
    """Every entry of the reduced device's coefficient vector, in order (structure included)."""
    return CATT_HEADER.names + CATT_BLOCK.names + catt_harmonics(n_harmonics).names


@functools.cache
def reduced_kernel(n_harmonics: int) -> KernelSource:
    """The reduced device's kernel source for ``n_harmonics`` stiffness harmonics (one form per
    number: the coefficient tuple's length)."""
    return KernelSource(catt_reduced_rhs, catt_reduced_events, catt_reduced_observe,
                        one_form=OneForm(coefficient_names(n_harmonics), 4, 4, 2,
                                         quiet=LOAD_AMPLITUDES))
