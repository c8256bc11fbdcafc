"""The classic single-mesh spur gear pair with backlash (Kahraman & Singh form), dimensionless.

    x'' + 2 zeta x' + (1 + kappa cos(Omega tau + phi_k)) g(x, b)
        = Fm + Fa Omega^2 cos(Omega tau + phi_e)

x is the dynamic transmission error scaled by the backlash half-width (so b = 1 by default), tau
the time scaled by the linear natural frequency, Fm the mean load, Fa Omega^2 the excitation by the
static transmission error of amplitude Fa, kappa the relative stiffness variation.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from geardyn.core.kernel_source import FORM_GENERAL, FORM_QUIET, KernelSource
from geardyn.core.model import Model
from geardyn.models.catt_kernels import dead_zone

_JIT = {"cache": True, "error_model": "numpy", "boundscheck": False}
OMEGA, ZETA, KAPPA, FM, FA, PHI_K, PHI_E, BACKLASH = range(8)


@nb.njit(**_JIT)
def gear_pair_rhs(t, y, dy, p, s, c):
    x = y[0]
    b = p[BACKLASH]
    g = x - b if x > b else (x + b if x < -b else 0.0)
    ck = c * math.cos(p[PHI_K]) - s * math.sin(p[PHI_K])
    ce = c * math.cos(p[PHI_E]) - s * math.sin(p[PHI_E])
    dy[0] = y[1]
    dy[1] = (p[FM] + p[FA] * p[OMEGA] * p[OMEGA] * ce - 2.0 * p[ZETA] * y[1]
             - (1.0 + p[KAPPA] * ck) * g)


@nb.njit(**_JIT)
def gear_pair_events(t, y, g, p, s, c):
    g[0] = y[0] - p[BACKLASH]
    g[1] = y[0] + p[BACKLASH]


@nb.njit(**_JIT)
def gear_pair_observe(t, y, out, p, s, c):
    x = y[0]
    b = p[BACKLASH]
    g = x - b if x > b else (x + b if x < -b else 0.0)
    ck = c * math.cos(p[PHI_K]) - s * math.sin(p[PHI_K])
    out[0] = (1.0 + p[KAPPA] * ck) * g + 2.0 * p[ZETA] * y[1]


# Lane-block forms for the sweep kernel (picked up by name, ``<function>_lanes``): the same
# arithmetic as the functions above, operation for operation, on lanes 0..nl-1 of a block in
# structure-of-arrays layout (state Y[q, k], coefficients PT[j, k], forcing phase S[k], C[k]
# per lane); the lane loops vectorise. SC: scratch rows (>= 4) of the block's width.


@nb.njit(inline="always", **_JIT)
def _phase_factors(PT, nl, SC):
    """cos and sin of the stiffness and error phases of every lane into SC rows 0-3 (no libm
    call when a phase is 0: cos 0 = 1 and sin 0 = 0 exactly)."""
    phased = False
    for k in range(nl):
        SC[0, k] = 1.0
        SC[1, k] = 0.0
        SC[2, k] = 1.0
        SC[3, k] = 0.0
        phased |= (PT[PHI_K, k] != 0.0) | (PT[PHI_E, k] != 0.0)
    if not phased:  # no libm call in the common case (a guarded call may be speculated)
        return
    for k in range(nl):
        if PT[PHI_K, k] != 0.0:
            SC[0, k] = math.cos(PT[PHI_K, k])
            SC[1, k] = math.sin(PT[PHI_K, k])
        if PT[PHI_E, k] != 0.0:
            SC[2, k] = math.cos(PT[PHI_E, k])
            SC[3, k] = math.sin(PT[PHI_E, k])


@nb.njit(**_JIT)
def gear_pair_rhs_lanes(T, Y, DY, PT, nl, S, C, SC):
    """:func:`gear_pair_rhs` for lanes 0..nl-1 of a block."""
    _phase_factors(PT, nl, SC)
    for k in range(nl):
        x = Y[0, k]
        b = PT[BACKLASH, k]
        g = x - b if x > b else (x + b if x < -b else 0.0)
        ck = C[k] * SC[0, k] - S[k] * SC[1, k]
        ce = C[k] * SC[2, k] - S[k] * SC[3, k]
        om = PT[OMEGA, k]
        DY[0, k] = Y[1, k]
        DY[1, k] = (PT[FM, k] + PT[FA, k] * om * om * ce - 2.0 * PT[ZETA, k] * Y[1, k]
                    - (1.0 + PT[KAPPA, k] * ck) * g)


@nb.njit(**_JIT)
def gear_pair_events_lanes(T, Y, G, PT, nl, S, C):
    """:func:`gear_pair_events` for lanes 0..nl-1 of a block."""
    for k in range(nl):
        G[0, k] = Y[0, k] - PT[BACKLASH, k]
        G[1, k] = Y[0, k] + PT[BACKLASH, k]


@nb.njit(**_JIT)
def gear_pair_observe_lanes(T, Y, O, PT, nl, S, C, SC):
    """:func:`gear_pair_observe` for lanes 0..nl-1 of a block."""
    _phase_factors(PT, nl, SC)
    for k in range(nl):
        x = Y[0, k]
        b = PT[BACKLASH, k]
        g = x - b if x > b else (x + b if x < -b else 0.0)
        ck = C[k] * SC[0, k] - S[k] * SC[1, k]
        O[0, k] = (1.0 + PT[KAPPA, k] * ck) * g + 2.0 * PT[ZETA, k] * Y[1, k]


# Lane-scalar forms for the sweep kernel's fused step loop (picked up by name, ``<function>_lane``):
# lane k of a block (coefficients PT[j, k]), the state and the results as tuples, the same
# arithmetic as the functions above operation for operation (bitwise equal). FORM_QUIET: both
# phases 0, where cos 0 = 1 and sin 0 = 0 exactly (no libm call: the loop vectorises);
# FORM_GENERAL: any lane (libm for the phases; scalar). The model has no FORM_LOAD.

#: State size of the lane-scalar forms (the tuples' length).
gear_pair_rhs_lane_states = 2


@nb.njit(inline="always", **_JIT)
def _unphased(PT, k):
    """True where lane k's stiffness and error phases are both 0."""
    return (PT[PHI_K, k] == 0.0) & (PT[PHI_E, k] == 0.0)


@nb.njit(**_JIT)
def gear_pair_rhs_lane_form(PT, k):
    """The lane form lane k may take: FORM_QUIET where both phases are 0, else FORM_GENERAL."""
    return FORM_QUIET if _unphased(PT, k) else FORM_GENERAL


@nb.njit(inline="always", **_JIT)
def _phase_lane(PT, k, s, c, form):
    """(ck, ce) of lane k: the stiffness and error phases' cosines as the other forms compute
    them (``c cos(phi) - s sin(phi)``; cos 0 = 1 and sin 0 = 0 exactly, in libm too). The
    general form (the split path's, for every lane) calls libm only where a phase is not 0."""
    if form == FORM_QUIET or _unphased(PT, k):
        return c * 1.0 - s * 0.0, c * 1.0 - s * 0.0
    pk = PT[PHI_K, k]
    pe = PT[PHI_E, k]
    return c * math.cos(pk) - s * math.sin(pk), c * math.cos(pe) - s * math.sin(pe)


@nb.njit(inline="always", **_JIT)
def gear_pair_rhs_lane(t, y, PT, k, s, c, form):
    """:func:`gear_pair_rhs` of lane k: dy/dt as a tuple."""
    x, v = y
    g = dead_zone(x, PT[BACKLASH, k])  # the other forms' g, branch-free: the same values
    ck, ce = _phase_lane(PT, k, s, c, form)
    om = PT[OMEGA, k]
    return (v, PT[FM, k] + PT[FA, k] * om * om * ce - 2.0 * PT[ZETA, k] * v
            - (1.0 + PT[KAPPA, k] * ck) * g)


@nb.njit(inline="always", **_JIT)
def gear_pair_events_lane(t, y, PT, k, s, c):
    """:func:`gear_pair_events` of lane k, as a tuple."""
    return (y[0] - PT[BACKLASH, k], y[0] + PT[BACKLASH, k])


@nb.njit(inline="always", **_JIT)
def gear_pair_observe_lane(t, y, PT, k, s, c, form):
    """:func:`gear_pair_observe` of lane k, as a tuple."""
    g = dead_zone(y[0], PT[BACKLASH, k])
    ck, _ = _phase_lane(PT, k, s, c, form)
    return ((1.0 + PT[KAPPA, k] * ck) * g + 2.0 * PT[ZETA, k] * y[1],)


class GearPair(Model):
    """Single spur gear pair with backlash, time-varying stiffness and transmission error.

    Parameters (all dimensionless): ``zeta`` damping ratio, ``kappa`` relative stiffness
    variation (``abs(kappa) < 1``), ``Fm`` mean load, ``Fa`` transmission-error amplitude, ``Omega``
    mesh frequency, ``kappa_phase`` and ``error_phase`` [rad], ``backlash`` half-width (1 when x
    is scaled by it).
    """

    name = "GearPair"
    state_names = ("x", "v")
    event_names = ("x-b", "x+b")
    observable_names = ("F",)
    meshes = (("mesh", 0, 1),)
    param_names = ("Omega", "zeta", "kappa", "Fm", "Fa", "kappa_phase", "error_phase", "backlash")

    def __init__(self, zeta: float = 0.05, kappa: float = 0.0, Fm: float = 0.1, Fa: float = 0.05,
                 Omega: float = 1.0, kappa_phase: float = 0.0, error_phase: float = 0.0,
                 backlash: float = 1.0):
        values = dict(Omega=Omega, zeta=zeta, kappa=kappa, Fm=Fm, Fa=Fa,
                      kappa_phase=kappa_phase, error_phase=error_phase, backlash=backlash)
        for key, v in values.items():
            if not isinstance(v, int | float) or isinstance(v, bool) or not math.isfinite(v):
                raise ValueError(f"{key}: must be a finite number (got {v!r})")
        if zeta < 0:
            raise ValueError(f"zeta: damping ratio must be >= 0 (got {zeta!r})")
        if not abs(kappa) < 1:
            raise ValueError(f"kappa: |kappa| must be < 1 to keep the stiffness positive "
                             f"(got {kappa!r})")
        if backlash < 0:
            raise ValueError(f"backlash: must be >= 0 (got {backlash!r})")
        if Omega < 0:
            raise ValueError(f"Omega: must be >= 0 (got {Omega!r})")
        self.params = np.array([float(values[k]) for k in self.param_names])
        self.omega_index = OMEGA
        self.kernel = KernelSource(gear_pair_rhs, gear_pair_events, gear_pair_observe)

    def with_params(self, **values: float) -> GearPair:
        """A copy with parameters changed by name, validated as in the constructor (every
        derived quantity reads the coefficient vector, so it follows)."""
        current = dict(zip(self.param_names, (float(v) for v in self.params), strict=True))
        for name in values:
            self._param_index(name)  # unknown names: KeyError naming the known ones
        return type(self)(**{**current, **{k: float(v) for k, v in values.items()}})

    def fastest_natural_frequency(self, P: np.ndarray | None = None) -> np.ndarray:
        """The linear natural frequency in contact, 1 in every lane (time is scaled by it)."""
        return np.ones(np.atleast_2d(self.params if P is None else P).shape[0])

    def initial_state(self) -> np.ndarray:
        """Static deflection under the mean load, at rest."""
        fm, b = self.params[FM], self.params[BACKLASH]
        return np.array([fm + math.copysign(b, fm) if fm else 0.0, 0.0])

    def static_mesh_forces(self) -> np.ndarray:
        """Static mesh force: the mean load Fm."""
        return np.array([self.params[FM]])

    def natural_frequencies(self) -> np.ndarray:
        """Linear natural frequency in contact (1 in units of the time scale)."""
        return np.array([1.0])

    def separation_onset(self, omegas: np.ndarray) -> np.ndarray:
        """Linear prediction (kappa = 0): the teeth separate where
        ``Fa Omega^2 / abs(1 - Omega^2 + 2 i zeta Omega) > Fm``. Returns that amplitude ratio
        minus 1."""
        om = np.asarray(omegas, dtype=float)
        zeta, fm, fa = self.params[ZETA], self.params[FM], self.params[FA]
        amp = fa * om**2 / np.abs(1.0 - om**2 + 2j * zeta * om)
        return amp / fm - 1.0
