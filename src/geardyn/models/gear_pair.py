"""The classic single-mesh spur gear pair with backlash (Kahraman & Singh form), dimensionless.

    x'' + 2 zeta x' + (1 + kappa cos(Omega tau + phi_k)) g(x, b)
        = Fm + Fa Omega^2 cos(Omega tau + phi_e)

x is the dynamic transmission error scaled by the backlash half-width (so b = 1 by default), tau
the time scaled by the linear natural frequency, Fm the mean load, Fa Omega^2 the excitation by the
static transmission error of amplitude Fa, kappa the relative stiffness variation.
"""

from __future__ import annotations

import math
from types import MappingProxyType

import numba as nb
import numpy as np

from geardyn._jit_target import WidthCompiler
from geardyn.core.capabilities import Capabilities
from geardyn.core.coefficients import CoefficientLayout
from geardyn.core.kernel_source import KernelSource
from geardyn.core.model import Model
from geardyn.core.one_form import OneForm
from geardyn.errors import ParameterError
from geardyn.models.elements import dead_zone
from geardyn.models.gear_pair_coefficients import GEAR_PAIR

_JIT = {"cache": True, "error_model": "numpy", "boundscheck": False,
        "pipeline_class": WidthCompiler}
#: Index constants of the declared coefficients (models/gear_pair_coefficients.py).
OMEGA, ZETA, KAPPA, FM, FA, PHI_K, PHI_E, BACKLASH, COS_K, SIN_K, COS_E, SIN_E = (
    GEAR_PAIR.offset(n) for n in GEAR_PAIR.names)
_LAYOUT = CoefficientLayout.of(GEAR_PAIR, model="GearPair")

# The model in the one form (geardyn.core.one_form): y = (x, v), p the lane's coefficients by
# name, s and c sin and cos of the forcing phase; the phases enter through their cos and sin,
# derived coefficients (no libm call per step: the sweep's lane loop vectorises).


@nb.njit(**_JIT)
def gear_pair_rhs(t, y, p, s, c):
    x, v = y
    g = dead_zone(x, p.backlash)
    ck = c * p.cos_kappa_phase - s * p.sin_kappa_phase
    ce = c * p.cos_error_phase - s * p.sin_error_phase
    return (v, p.Fm + p.Fa * p.Omega * p.Omega * ce - 2.0 * p.zeta * v
            - (1.0 + p.kappa * ck) * g)


@nb.njit(**_JIT)
def gear_pair_events(t, y, p, s, c):
    return (y[0] - p.backlash, y[0] + p.backlash)


@nb.njit(**_JIT)
def gear_pair_observe(t, y, p, s, c):
    g = dead_zone(y[0], p.backlash)
    ck = c * p.cos_kappa_phase - s * p.sin_kappa_phase
    return ((1.0 + p.kappa * ck) * g + 2.0 * p.zeta * y[1],)


#: Derived coefficients: name -> (the parameter it follows, the function of it), read from their
#: declarations in :data:`~geardyn.models.gear_pair_coefficients.GEAR_PAIR` (computed with
#: Python's ``math``, the libm of the compiled code: cos 0 = 1 and sin 0 = 0 exactly).
DERIVED = MappingProxyType(_LAYOUT.derivations())

_KERNEL = KernelSource(gear_pair_rhs, gear_pair_events, gear_pair_observe,
                       one_form=OneForm(GEAR_PAIR.names, 2, 2, 1))


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
    capabilities = Capabilities(mesh_forces=True, natural_frequencies="rad/time")
    derived = DERIVED
    #: The declared coefficients (:data:`~geardyn.models.gear_pair_coefficients.GEAR_PAIR`):
    #: the parameters, then the derived coefficients (:data:`DERIVED`), in the kernel's order.
    #: ``with_params`` and ``lane_params`` are :class:`~geardyn.Model`'s: they validate by the
    #: declarations and refill the derived coefficients from them.
    param_names = GEAR_PAIR.names

    def __init__(self, zeta: float = 0.05, kappa: float = 0.0, Fm: float = 0.1, Fa: float = 0.05,
                 Omega: float = 1.0, kappa_phase: float = 0.0, error_phase: float = 0.0,
                 backlash: float = 1.0):
        values = dict(Omega=Omega, zeta=zeta, kappa=kappa, Fm=Fm, Fa=Fa,
                      kappa_phase=kappa_phase, error_phase=error_phase, backlash=backlash)
        for key, v in values.items():  # finite and in the declared range (|kappa| < 1: k > 0)
            if isinstance(v, str):
                raise ParameterError(key, v, "must be a number")
            values[key] = GEAR_PAIR[key].check(key, v)
        self.params = _LAYOUT.fill_derived(np.array(
            [values[k] for k in self.param_names[:COS_K]] + [0.0] * len(DERIVED)))
        self.coefficient_layout = _LAYOUT
        self.omega_index = OMEGA
        self.kernel = _KERNEL

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
