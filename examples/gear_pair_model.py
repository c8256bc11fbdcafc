"""The single gear pair with backlash written as a user's model in the one form (the equations of
geardyn.GearPair, written here independently), used by bench/user_model.py and the tests.
Defined in an importable module, so that geardyn caches the kernels built from it on disk.

    x'' + 2 zeta x' + (1 + kappa cos(Omega t + phi_k)) g(x, b)
        = Fm + Fa Omega^2 cos(Omega t + phi_e)

g(x, b) is the backlash dead zone; the phases enter through their cos and sin, derived
coefficients (no libm call per step, so the sweep vectorises).
"""

import math

import numba

import geardyn


@numba.njit(cache=True)
def _dead_zone(x, b):
    return x - min(max(x, -b), b)


@numba.njit(cache=True)
def pair_rhs(t, y, p, s, c):
    """dy/dt of y = (x, v); s, c: sin and cos of the forcing phase Omega t."""
    x, v = y
    g = _dead_zone(x, p.b)
    stiffness = 1.0 + p.kappa * (c * p.cos_phi_k - s * p.sin_phi_k)
    error = p.Fa * p.Omega * p.Omega * (c * p.cos_phi_e - s * p.sin_phi_e)
    return (v, p.Fm + error - 2.0 * p.zeta * v - stiffness * g)


@numba.njit(cache=True)
def pair_events(t, y, p, s, c):
    """The dead zone's edges: x - b (drive side) and x + b (back side)."""
    return (y[0] - p.b, y[0] + p.b)


@numba.njit(cache=True)
def pair_force(t, y, p, s, c):
    """The mesh force: elastic plus damping."""
    stiffness = 1.0 + p.kappa * (c * p.cos_phi_k - s * p.sin_phi_k)
    return (stiffness * _dead_zone(y[0], p.b) + 2.0 * p.zeta * y[1],)


def gear_pair(zeta=0.05, kappa=0.0, Fm=0.1, Fa=0.05, Omega=1.0, phi_k=0.0, phi_e=0.0, b=1.0,
              kernel_path="pointer"):
    """The gear pair as a geardyn.UserModel in the one form, with its mesh declared
    (kernel_path: "pointer", the default, for the kernels compiled once for every model;
    "lane-form" for every kernel compiled with the model's functions inlined)."""
    return geardyn.UserModel.from_one_form(
        pair_rhs,
        params=dict(Omega=Omega, zeta=zeta, kappa=kappa, Fm=Fm, Fa=Fa, phi_k=phi_k,
                    phi_e=phi_e, b=b),
        derived={"cos_phi_k": ("phi_k", math.cos), "sin_phi_k": ("phi_k", math.sin),
                 "cos_phi_e": ("phi_e", math.cos), "sin_phi_e": ("phi_e", math.sin)},
        states=("x", "v"),
        events=pair_events, event_names=("x-b", "x+b"),
        observe=pair_force, observable_names=("F",),
        meshes=[("mesh", "x-b", "x+b", "F")],
        static_forces=lambda p: (p.Fm,),
        initial_state=lambda p: (p.Fm + math.copysign(p.b, p.Fm) if p.Fm else 0.0, 0.0),
        natural_frequency=1.0,
        name="gear pair (user)",
        kernel_path=kernel_path,
    )
