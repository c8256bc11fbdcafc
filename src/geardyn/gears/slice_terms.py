"""The energy terms of healthy tooth pairs from Chebyshev interpolants along the path of contact
(the slices of a helical pair).

Each slice of a helical pair meets the transverse spur pair at its own contact positions, so a
grid of A angles and S slices holds about 2 A S eps_alpha distinct positions (both flanks),
each integrated by Gauss-Legendre quadrature (:func:`~geardyn.gears.tooth_compliances`). For
healthy teeth every compliance is an analytic function of the contact position s on the path
of contact [-g_f, g_a]: the integrands, the integration limits and the fillet-foundation
terms depend analytically on the load angle alpha_1, which is linear in s, and so does the
fixed-node quadrature of them. :class:`ChebyshevTerms` interpolates each term's compliance by
a Chebyshev series of degree :data:`DEGREE` through its quadrature values at the Chebyshev
points of the path (the axial compliance divided by its factor sin^2 alpha_1, which vanishes
where the load angle does), and evaluates the series at the contacts; the Hertz term is
constant and a ring's fillet term (rigid body) stays inf.

The interpolant is checked against quadrature at the DEGREE + 2 points between and beyond the
nodes (the midpoints in the Chebyshev angle and both ends of the path): its ``error`` is the
largest of each term's compliance error relative to the pair's compliance and the pair
stiffness's relative error. A caller uses it only where ``error`` <= :data:`TOLERANCE` and
records which evaluation it used. Faulty teeth are not interpolated (:meth:`terms` passes
them to quadrature).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.polynomial import chebyshev

from geardyn.gears.potential_energy import PotentialEnergyPair

#: Degree of the Chebyshev series of each compliance along the path of contact.
DEGREE = 48
#: Largest error of the interpolant at the check points (relative to the pair's compliance
#: and stiffness) for it to stand in for quadrature.
TOLERANCE = 1e-12


def _compliances(pair: PotentialEnergyPair, position: np.ndarray
                 ) -> tuple[tuple[str, ...], np.ndarray, np.ndarray]:
    """(the tooth terms' names in :meth:`PotentialEnergyPair.terms`' order, their compliances
    [m/N] over (term, position) by quadrature, the pair's stiffness [N/m])."""
    terms = pair.terms(position)
    names = tuple(n for n in terms if n not in ("hertz", "pair"))
    return names, np.stack([1.0 / terms[n] for n in names]), terms["pair"]


def _factors(pair: PotentialEnergyPair, names: tuple[str, ...],
             position: np.ndarray) -> np.ndarray:
    """Over (term, position): sin^2 alpha_1 of the axial terms (their tooth's load angle), 1
    for the others."""
    a_p, a_w = pair.load_angles(position)
    out = np.ones((len(names), position.size))
    for i, name in enumerate(names):
        if name.startswith("axial_"):
            out[i] = np.sin(a_p if name.endswith("_pinion") else a_w) ** 2
    return out


@dataclass(frozen=True)
class ChebyshevTerms:
    """The healthy terms of ``pair`` as Chebyshev series on the path of contact [``lo``,
    ``hi``] [m] (module docstring): ``coef`` over (degree + 1, term) of ``names``, the axial
    ones divided by sin^2 alpha_1; ``rigid`` marks the terms that are inf (a ring's fillet);
    ``error`` the check's largest error. :meth:`terms` stands in for
    :meth:`PotentialEnergyPair.terms`."""

    pair: PotentialEnergyPair
    lo: float
    hi: float
    names: tuple[str, ...]
    coef: np.ndarray
    rigid: np.ndarray
    error: float

    @property
    def faults(self) -> tuple[object, ...]:
        """The pair's faults."""
        return self.pair.faults

    @classmethod
    def build(cls, pair: PotentialEnergyPair, degree: int = DEGREE) -> ChebyshevTerms:
        """The interpolants of ``pair``'s healthy terms over its path of contact, checked."""
        mesh = pair.mesh
        lo, hi = -mesh.approach_length, mesh.recess_length
        nodes = np.cos(np.pi * (np.arange(degree + 1) + 0.5) / (degree + 1))
        at = 0.5 * (hi + lo) + 0.5 * (hi - lo) * nodes
        names, comp, _ = _compliances(pair, at)
        rigid = np.all(comp == 0.0, axis=1)
        values = comp / _factors(pair, names, at)
        coef = chebyshev.chebvander(nodes, degree).T @ values.T
        coef[0] /= degree + 1
        coef[1:] /= 0.5 * (degree + 1)
        table = cls(pair, lo, hi, names, coef, rigid, np.inf)
        check = 0.5 * (hi + lo) + 0.5 * (hi - lo) * np.cos(np.pi * np.arange(degree + 2)
                                                           / (degree + 1))
        _, want, k_want = _compliances(pair, check)
        got = table.compliances(check)
        k_got = 1.0 / (1.0 / pair.hertz + got.sum(axis=0))
        total = 1.0 / k_want
        with np.errstate(invalid="ignore"):
            error = max(float(np.max(np.abs(got - want) / total)),
                        float(np.max(np.abs(k_got - k_want) / k_want)))
        return cls(pair, lo, hi, names, coef, rigid, error if np.isfinite(error) else np.inf)

    def compliances(self, position: np.ndarray) -> np.ndarray:
        """Each term's compliance [m/N] over (term, position) from the series (0 where
        rigid)."""
        x = (2.0 * position - (self.hi + self.lo)) / (self.hi - self.lo)
        out = chebyshev.chebval(x, self.coef) * _factors(self.pair, self.names, position)
        out[self.rigid] = 0.0
        return out

    def terms(self, position: np.ndarray, pinion: object = None, wheel: object = None, *,
              coast: bool = False) -> dict[str, np.ndarray]:
        """:meth:`PotentialEnergyPair.terms` at ``position`` [m] on the path of contact: the
        healthy pair's from the series (the same names and order; a term's stiffness 1 /
        compliance, the pair's 1 / (1/k_h + sum of the compliances)), a pair with a faulty
        tooth by quadrature."""
        if pinion is not None or wheel is not None:
            return self.pair.terms(position, pinion, wheel, coast=coast)  # type: ignore[arg-type]
        pos = np.asarray(position, dtype=float).reshape(-1)
        comp = self.compliances(pos)
        hertz = self.pair.hertz
        out = {"hertz": np.full(pos.shape, hertz)}
        compliance = 1.0 / out["hertz"]
        for name, c, rigid in zip(self.names, comp, self.rigid, strict=True):
            out[name] = np.full(c.shape, np.inf) if rigid else 1.0 / c
            compliance = compliance + c
        out["pair"] = 1.0 / compliance
        return {k: v.reshape(np.shape(position)) for k, v in out.items()}
