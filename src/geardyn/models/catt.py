"""The CATT planetary gear train processing device (fixed sun, N inside and N outside planets,
carrier): the dimensionless mesh-coordinate model of Eq. (10), corrected, and the dimensional
body-angle model of Eq. (1).

Mesh coordinates (Eq. 8), per planet set i::

    X_sq_i = theta_c r_c1 - theta_q_i r_bq_i - e_sq_i(t)
    X_pq_i = theta_q_i r_bq_i - theta_p_i r_bp_i - e_pq_i(t)

made dimensionless by X = X / b_c and tau = omega_n t (Eq. 9). Differentiating twice and
substituting Eq. (1) gives, with k(tau) = K(tau)/Km the relative stiffness and g the dead zone::

    X_sq_i'' = f_c(tau) - sum_j [k_sq_c_j k_sq_j(tau) g(X_sq_j, b_sq_j) + c_sq_c_j X_sq_j']
               - [k_sq_q_i k_sq_i g(X_sq_i) + c_sq_q_i X_sq_i']
               + [k_pq_q_i k_pq_i g(X_pq_i) + c_pq_q_i X_pq_i']
               + E_sq_i Omega^2 sin(Omega tau + phi)
    X_pq_i'' = [k_sq_q_i k_sq_i g(X_sq_i) + c_sq_q_i X_sq_i']
               - [(k_pq_q_i + k_pq_p_i) k_pq_i g(X_pq_i) + (c_pq_q_i + c_pq_p_i) X_pq_i']
               + f_p_i(tau) + E_pq_i Omega^2 sin(Omega tau + phi)

with the coefficients of :data:`geardyn.models.derived.COEFFICIENT_FORMULAS`. With identical
planet sets every set moves alike (from a symmetric initial state) and the model reduces to four
states; :class:`CATTDevice` picks that form automatically.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence

import numpy as np

from geardyn.core.capabilities import Capabilities
from geardyn.core.coefficients import CoefficientLayout
from geardyn.core.inputs import by_name, rederived
from geardyn.core.kernel_source import KernelSource
from geardyn.core.model import Model, unique_rows
from geardyn.core.moved import warn_once
from geardyn.errors import ParameterError
from geardyn.models import catt_kernels as ck
from geardyn.models.catt_reduced import reduced_kernel
from geardyn.models.derived import (
    CATT_BLOCK,
    CATT_HEADER,
    INTERPRETATIONS,
    THETA_BLOCK,
    THETA_HEADER,
    Derived,
    Interpretation,
    catt_harmonics,
    coefficients,
    derive,
)
from geardyn.models.params import PAPER_INPUTS, PAPER_NAMES, PlanetaryParams
from geardyn.models.stiffness import fourier_coefficients, harmonics_needed

_KERNEL = KernelSource(ck.catt_rhs, ck.catt_events, ck.catt_observe)
_THETA_KERNEL = KernelSource(ck.theta_rhs, ck.theta_events)
#: The block coefficients :meth:`CATTDevice._coefficients_of` reads back per planet set.
_READ_BACK = ("k_sq_c", "c_sq_c", "k_sq_q", "c_sq_q", "k_pq_q", "c_pq_q", "k_pq_p", "c_pq_p",
              "b_sq", "b_pq", "f_p0", "f_p1")


@functools.lru_cache(maxsize=64)
def catt_layout(n_sets: int, reduced: bool, n_harmonics: int) -> CoefficientLayout:
    """The mesh-coordinate model's coefficient vector: :data:`~geardyn.models.derived.CATT_HEADER`,
    then per planet set :data:`~geardyn.models.derived.CATT_BLOCK` and its stiffness harmonics
    (names suffixed with the set's number in the general form)."""
    harmonics = catt_harmonics(n_harmonics)
    out = CoefficientLayout.of(CATT_HEADER, model="CATTDevice")
    for i in range(n_sets):
        suffix = "" if reduced else str(i + 1)
        out.extend(CATT_BLOCK.entries, suffix)
        out.extend(harmonics.entries, suffix)
    return out


@functools.lru_cache(maxsize=64)
def theta_layout(n_sets: int, n_harmonics: int) -> CoefficientLayout:
    """The body-angle model's coefficient vector: :data:`THETA_HEADER`, then per planet set
    :data:`THETA_BLOCK` and its stiffness harmonics (names suffixed with the set's number)."""
    harmonics = catt_harmonics(n_harmonics)
    out = CoefficientLayout.of(THETA_HEADER, model="DimensionalCATT")
    for i in range(n_sets):
        out.extend(THETA_BLOCK.entries, str(i + 1))
        out.extend(harmonics.entries, str(i + 1))
    return out


class CATTDevice(Model):
    """The paper's device as a geardyn model (dimensionless, time tau = omega_n t).

    Parameters
    ----------
    params
        Validated device parameters (:meth:`PlanetaryParams.paper` for the paper's).
    interpretation
        How to read the paper's ambiguous formulas: ``"consistent"`` (default),
        ``"carrier-only"`` or ``"as-printed"`` (see :mod:`geardyn.models.derived`).
    reduced
        Use the 4-state form for identical planet sets. ``None`` (default) chooses it whenever
        the planet sets are identical; ``False`` forces the general 4N-state form.
    omega
        Dimensionless mesh frequency Omega = omega / omega_n stored in the model (solvers and
        sweeps set it).
    one_form
        Deprecated; chooses nothing (a DeprecationWarning where given). The reduced form runs
        its one form (:mod:`geardyn.models.catt_reduced`: every kernel layout generated from
        the physics written once), the general form the kernel of
        :func:`~geardyn.models.catt_kernels.catt_rhs`.
    """

    time_unit = "1"
    state_units = "1"
    observable_units = "N"
    capabilities = Capabilities(frequency_scale=True, interpretation=True,
                                natural_frequencies="rad/time",
                                physical_inputs=True, paper_device=True, mesh_forces=True)
    raw_overrides_allowed = True
    #: The paper's names of the physical parameters, declared once
    #: (:data:`~geardyn.models.params.PAPER_INPUTS`): ``with_params`` re-derives the
    #: coefficients from every one of them, a sweep takes the swept ones (not the count ``N``
    #: nor the choice ``waveform``).
    input_declarations = PAPER_INPUTS
    physical_names = rederived(PAPER_INPUTS)

    def __init__(
        self,
        params: PlanetaryParams,
        interpretation: Interpretation = "consistent",
        reduced: bool | None = None,
        omega: float = 1.0,
        one_form: bool | None = None,
    ):
        if one_form is not None:
            warn_once(("keywords", "CATTDevice", ("one_form",)),
                      "CATTDevice(one_form=...) chooses nothing and will be removed: the "
                      "reduced form always runs its one form (geardyn.models.catt_reduced)",
                      stacklevel=2)
        if interpretation not in INTERPRETATIONS:
            raise ValueError(
                f"interpretation must be one of {', '.join(INTERPRETATIONS)};"
                f" got {interpretation!r}"
            )
        identical = params.identical_planets
        if reduced and not identical:
            raise ValueError("reduced=True needs identical planet sets; these differ")
        self.params_in = params
        self.interpretation = interpretation
        self.reduced = identical if reduced is None else bool(reduced)
        self.derived: Derived = derive(params, interpretation)
        self.coefficients = coefficients(params, self.derived)
        n_sets = 1 if self.reduced else params.n_planets
        self.n_sets = n_sets
        if self.reduced:
            self.state_names = ("X_sq", "V_sq", "X_pq", "V_pq")
            self.observable_names = ("F_sq", "F_pq")
            self.event_names = ("X_sq-b_sq", "X_sq+b_sq", "X_pq-b_pq", "X_pq+b_pq")
        else:
            self.state_names = tuple(
                f"{v}_{m}{i + 1}" for i in range(n_sets) for m, v in
                (("sq", "X"), ("sq", "V"), ("pq", "X"), ("pq", "V"))
            )
            self.observable_names = tuple(
                f"F_{m}{i + 1}" for i in range(n_sets) for m in ("sq", "pq")
            )
            self.event_names = tuple(
                f"X_{m}{i + 1}{sign}b_{m}{i + 1}" for i in range(n_sets) for m in ("sq", "pq")
                for sign in ("-", "+")
            )
        if self.reduced:
            self.meshes = (("sq", 0, 1), ("pq", 2, 3))
        else:
            self.meshes = tuple(
                (f"{m}{i + 1}", 4 * i + 2 * k, 4 * i + 2 * k + 1)
                for i in range(n_sets) for k, m in enumerate(("sq", "pq"))
            )
        self.name = "CATTDevice"
        nh = self._n_harmonics()
        self.kernel = _KERNEL if n_sets > 1 else reduced_kernel(nh)
        self.omega_index = CATT_HEADER.offset("Omega")
        self.coefficient_layout = catt_layout(n_sets, self.reduced, nh)
        self.params = self._coefficient_vector(omega)
        #: Raw coefficients set by name through ``with_params`` (name -> value), applied on top
        #: of the coefficients derived from ``params_in``.
        self.raw_overrides: dict[str, float] = {}
        if not np.all(np.isfinite(self.params)):
            names = self.coefficient_layout.all_names
            bad = names[int(np.argmax(~np.isfinite(self.params)))]
            raise ParameterError("params", bad, "the parameters give a dimensionless "
                                 "coefficient that is not finite (extreme magnitudes)")

    @property
    def one_form(self) -> bool:
        """Deprecated: whether the device runs a one form (the reduced form always does, the
        general one never)."""
        warn_once(("attribute", "CATTDevice.one_form"), "CATTDevice.one_form is deprecated: "
                  "the reduced form always runs its one form", stacklevel=2)
        return self.kernel.one_form is not None

    # ------------------------------------------------------------------ coefficient vector
    def _n_harmonics(self) -> int:
        sets = [self.params_in.planet_set(i) for i in range(self.params_in.n_planets)]
        return max(max(harmonics_needed(s[0]), harmonics_needed(s[1])) for s in sets)

    def _coefficient_vector(self, omega: float) -> np.ndarray:
        """The vector of :func:`catt_layout`, from the derived coefficients."""
        prm = self.params_in
        co = self.coefficients
        d = self.derived
        nh = self._n_harmonics()
        values: dict[str, float] = {
            "Omega": omega, "Lambda": prm.loads.Lambda, "n_blocks": self.n_sets,
            "n_harmonics": nh, "f_c0": co["f_c0"], "f_c1": co["f_c1"],
            "psi1": prm.loads.psi1, "psi2": prm.loads.psi2,
        }
        mult = prm.n_planets if self.reduced else 1
        for i in range(self.n_sets):
            sfx = "" if self.reduced else str(i + 1)
            sq, pq, _, _ = prm.planet_set(i)
            values[f"k_sq_c{sfx}"] = mult * co["k_sq_c"][i]
            values[f"c_sq_c{sfx}"] = mult * co["c_sq_c"][i]
            for name in ("k_sq_q", "c_sq_q", "k_pq_q", "c_pq_q", "k_pq_p", "c_pq_p", "b_sq",
                         "b_pq", "f_p0", "f_p1"):
                values[f"{name}{sfx}"] = co[name][i]
            values[f"E_sq_s{sfx}"] = co["E_sq"][i] * math.cos(sq.error_phase)
            values[f"E_sq_c{sfx}"] = co["E_sq"][i] * math.sin(sq.error_phase)
            values[f"E_pq_s{sfx}"] = co["E_pq"][i] * math.cos(pq.error_phase)
            values[f"E_pq_c{sfx}"] = co["E_pq"][i] * math.sin(pq.error_phase)
            values[f"force_scale{sfx}"] = prm.b_c * d.omega_n**2 * d.M_q[i]
            values[f"spare{sfx}"] = 0.0
            for mesh, m in ((sq, "ksq"), (pq, "kpq")):
                a, b = fourier_coefficients(mesh, nh)
                for h in range(nh):
                    values[f"{m}_a{h + 1}{sfx}"] = a[h]
                    values[f"{m}_b{h + 1}{sfx}"] = b[h]
        return self.coefficient_layout.build(values)

    # ------------------------------------------------------------------ parameters by name
    @property
    def omega_n(self) -> float:
        """omega_n [rad/s]: the unit of dimensionless time (interpretation-dependent)."""
        return float(self.derived.omega_n)

    def dataset_attrs(self) -> dict[str, object]:
        """``interpretation`` and ``omega_n`` [rad/s], recorded in every dataset."""
        return {"interpretation": self.interpretation, "omega_n": self.omega_n}

    def replace(self, **changes) -> CATTDevice:
        """A new device with physical parameters changed by the paper's names (``xi1``,
        ``backlash``, ``B1``, ...) and/or ``Omega``. Raw coefficients set before
        (:attr:`raw_overrides`) are kept when the change leaves them alone, and refused
        (:class:`~geardyn.errors.ParameterError`) when it would re-derive them."""
        omega = float(changes.pop("Omega", self.omega))
        params = self.params_in.replace(**changes) if changes else self.params_in
        reduced = None if params.identical_planets else False
        if not self.reduced:
            reduced = False
        out = CATTDevice(params, self.interpretation, reduced=reduced, omega=omega)
        if self.raw_overrides:
            plain = CATTDevice(self.params_in, self.interpretation, reduced=self.reduced,
                               omega=omega).params
            moved = [n for n in self.raw_overrides if out.params.size != plain.size
                     or out.params[out._param_index(n)] != plain[self._param_index(n)]]
            if moved:
                name = moved[0]
                raise ParameterError(
                    name, self.raw_overrides[name],
                    f"set as a raw coefficient, but changing {', '.join(sorted(changes))} "
                    "re-derives it from the physical parameters, which would undo the "
                    "override; change the physical parameters first, then the raw coefficient"
                    " (in a map: swap the axes)")
            out = out._override(self.raw_overrides)
        return out

    def with_params(self, **values: float) -> CATTDevice:
        """A copy with parameters changed by name (:meth:`Model.with_params`): physical ones
        (the paper's names, see :data:`~geardyn.models.params.PAPER_NAMES`, and ``Omega``)
        re-derive every coefficient; any other name sets that raw coefficient of the vector
        (e.g. ``k_pq_q``, ``f_c0``; dimensionless, in units of this device's omega_n, which
        stays; the reduced form's ``k_sq_c`` and ``c_sq_c`` are the N planet sets' together).
        Everything derived (natural frequencies, static forces, initial state, default step)
        then follows the coefficients. Raises :class:`~geardyn.errors.ParameterError` for an
        entry that fixes the vector's layout (``n_blocks``, ``n_harmonics``, ``spare``: not
        parameters) and for a physical change that would undo an earlier raw one."""
        return Model.with_params(self, **values)  # type: ignore[return-value]

    def _is_physical(self, name: str) -> bool:
        return name in PAPER_NAMES or name == "Omega"

    def _with_physical(self, values: dict[str, float]) -> CATTDevice:
        return self.replace(**values)

    def _with_raw(self, values: dict[str, float]) -> CATTDevice:
        return self._override(values)

    def _kind(self, name: str) -> str:
        """The coefficient ``name`` without its planet-set suffix (the reduced form's name)."""
        return self.coefficient_layout.slot(name).coefficient.name

    def _override(self, raw: dict[str, float]) -> CATTDevice:
        """A copy with raw coefficients set (checked: known parameters, finite)."""
        out = Model._with_raw(self, raw)
        out.raw_overrides = {**self.raw_overrides, **{k: float(v) for k, v in raw.items()}}
        out.coefficients = out._coefficients_of(out.params)
        return out

    def _coefficients_of(self, p: np.ndarray) -> dict[str, np.ndarray | float]:
        """:attr:`coefficients` with the raw-overridden ones read back from the vector ``p``
        (the reduced form's carrier coupling is N sets' together: divided by N)."""
        co = dict(self.coefficients)
        touched = {self._kind(k) for k in self.raw_overrides}
        values = self.coefficient_layout.read(p)
        n = self.params_in.n_planets
        sfx = [""] if self.reduced else [str(i + 1) for i in range(self.n_sets)]

        def per_set(name: str) -> np.ndarray:
            return np.array([values[name + s] for s in sfx])

        def put(name: str, v: np.ndarray) -> None:
            co[name] = np.broadcast_to(v, (n,)).copy() if v.size == 1 else v.copy()

        for name in _READ_BACK:
            if name in touched:
                put(name, per_set(name) / (n if self.reduced and name[2:] == "_sq_c" else 1))
        for name in ("E_sq", "E_pq"):
            if touched & {f"{name}_s", f"{name}_c"}:
                put(name, np.hypot(per_set(f"{name}_s"), per_set(f"{name}_c")))
        for name in ("f_c0", "f_c1"):
            if name in touched:
                co[name] = values[name]
        return co

    def lane_params(self, name: str, values: Sequence[float] | np.ndarray) -> np.ndarray:
        """Coefficient vectors (lanes x n_params) with ``name`` set to ``values``: a swept
        paper name re-derives every coefficient (as :meth:`with_params`), another name sets
        that raw coefficient; ``waveform`` (not swept) is a
        :class:`~geardyn.errors.ParameterError` naming it. ``N``, a count, is not swept either:
        a sweep of it (the reduced form's lanes, whose size N does not change) is deprecated
        (a DeprecationWarning) and still computed."""
        if name == "N":
            warn_once(("sweep", "CATTDevice", "N"), "sweeping N (a count, not a swept input of "
                      "CATTDevice) is deprecated: build one model per number of planet sets",
                      stacklevel=2)
        else:
            self._refuse_unswept(name, values)
        values = np.asarray(values, dtype=float).ravel()
        if name in PAPER_NAMES:
            rows = [self.replace(**{name: float(v)}).params for v in values]
            if len({r.size for r in rows}) != 1:
                raise ValueError(f"sweeping {name!r} changes the model's size")
            return np.array(rows)
        return Model.lane_params(self, name, values)

    def param_attrs(self, name: str) -> dict[str, str]:
        """Attributes of a sweep's axis: a swept paper name's (the name a sweep and
        ``with_params`` take first: ``units`` the SI unit of its declared kind, ``long_name``
        its meaning), else a coefficient's (:meth:`Model.param_attrs`); empty for a paper name
        that is not swept."""
        declared = by_name(PAPER_INPUTS).get(name)
        if declared is None:
            return super().param_attrs(name)
        if not declared.swept:
            return {}
        return {"units": str(declared.axis_unit), "long_name": declared.meaning}

    # ------------------------------------------------------------------ linear analysis
    def other_frequencies(self, P: np.ndarray) -> np.ndarray:
        """The load fluctuation's Lambda in every lane where B1 or B2 is nonzero (else NaN)."""
        P = np.atleast_2d(P)
        acts = (P[:, ck.F_C1] != 0.0) | np.any(
            P[:, ck.HEADER + ck.F_P1 :: ck.block_size(self._n_harmonics())][:, : self.n_sets]
            != 0.0, axis=1)
        return np.where(acts & (P[:, ck.LAMBDA] != 0.0), P[:, ck.LAMBDA], np.nan)[:, None]

    def _blocks(self, P: np.ndarray) -> np.ndarray:
        """The planet-set blocks of coefficient vectors ``P`` (lanes x n_params), shape
        (lanes, n_sets, block size)."""
        P = np.atleast_2d(P)
        bs = ck.block_size(int(P[0, ck.N_HARM]))
        return P[:, ck.HEADER : ck.HEADER + self.n_sets * bs].reshape(P.shape[0], self.n_sets, bs)

    def _mean_stiffness(self, P: np.ndarray, carrier: bool = True) -> np.ndarray:
        """Dimensionless mean stiffness matrices (lanes, 2 n_sets, 2 n_sets) of the modelled
        coordinates (X_sq1, X_pq1, ...): linearised undamped motion X'' = -A X + forcing. The
        reduced form's carrier coupling is N times a set's (its in-phase modes); with
        ``carrier=False`` the carrier coupling is left out (the reduced form's out-of-phase
        modes, which the carrier does not feel)."""
        blk = self._blocks(P)
        L, n = blk.shape[0], self.n_sets
        A = np.zeros((L, 2 * n, 2 * n))
        s, q = np.arange(0, 2 * n, 2), np.arange(1, 2 * n, 2)
        if carrier:
            A[:, s[:, None], s[None, :]] += blk[:, None, :, ck.K_SQ_C]
        A[:, s, s] += blk[:, :, ck.K_SQ_Q]
        A[:, s, q] -= blk[:, :, ck.K_PQ_Q]
        A[:, q, s] -= blk[:, :, ck.K_SQ_Q]
        A[:, q, q] += blk[:, :, ck.K_PQ_Q] + blk[:, :, ck.K_PQ_P]
        return A

    def _mode_eigenvalues(self, P: np.ndarray) -> np.ndarray:
        """Eigenvalues (lanes, 2N) of the linearised general model's stiffness matrix for every
        lane of ``P``; the reduced form adds its N - 1 out-of-phase pairs."""
        lam = np.linalg.eigvals(self._mean_stiffness(P))
        if self.reduced and self.params_in.n_planets > 1:
            out = np.linalg.eigvals(self._mean_stiffness(P, carrier=False))
            lam = np.concatenate([lam] + [out] * (self.params_in.n_planets - 1), axis=1)
        return lam

    def stiffness_matrix(self) -> np.ndarray:
        """Dimensionless mean stiffness matrix A of the general 2N-coordinate model, such that the
        linearised undamped motion (b = 0, Ka = 0) is X'' = -A X + forcing (from the coefficient
        vector, so raw overrides count)."""
        g = self.general() if self.reduced else self
        return g._mean_stiffness(g.params)[0]

    def natural_frequencies(self) -> np.ndarray:
        """Natural frequencies of the linearised device (mean stiffness, no backlash), ascending,
        in units of omega_n: all 2N modes of the general model, from the coefficient vector."""
        lam = self._mode_eigenvalues(self.params)[0]
        if np.max(np.abs(lam.imag)) > 1e-9 * np.max(np.abs(lam.real)):
            raise ValueError("the linearised stiffness matrix has complex eigenvalues")
        return np.sort(np.sqrt(lam.real))

    def fastest_natural_frequency(self, P: np.ndarray | None = None) -> np.ndarray:
        """Fastest natural frequency [omega_n] of the linearised device in every lane of ``P``
        (default: this device's coefficients), from the lane's own mean stiffness coefficients:
        sqrt of the largest eigenvalue magnitude of the stiffness matrix (vectorised)."""
        P = np.atleast_2d(self.params if P is None else np.asarray(P, dtype=float))
        cols = [ck.HEADER + i * ck.block_size(int(P[0, ck.N_HARM])) + k
                for i in range(self.n_sets) for k in (ck.K_SQ_C, ck.K_SQ_Q, ck.K_PQ_Q, ck.K_PQ_P)]
        # only the stiffness coefficients matter: one eigenproblem per distinct set of them
        keys, inverse = unique_rows(P[:, cols])
        Q = np.zeros((keys.shape[0], P.shape[1]))
        Q[:, ck.N_HARM] = P[0, ck.N_HARM]
        Q[:, cols] = keys
        w = np.sqrt(np.max(np.abs(self._mode_eigenvalues(Q)), axis=1))
        return w[inverse]

    def static_forces(self) -> np.ndarray:
        """Dimensionless static mesh deflections g(X) = X - b of the quasi-static state under the
        mean torques (mean stiffness, no error), one (sq, pq) pair per modelled planet set
        (from the coefficient vector, so raw overrides count)."""
        blk = self._blocks(self.params)[0]
        rhs = np.zeros(2 * self.n_sets)
        rhs[0::2] = self.params[ck.F_C0]
        rhs[1::2] = blk[:, ck.F_P0]
        return np.linalg.solve(self._mean_stiffness(self.params)[0], rhs)

    def initial_state(self) -> np.ndarray:
        """The quasi-static state under the mean loads (mean stiffness, no error), at rest: the
        deflection g = F/K added to the backlash on the loaded flank."""
        g = self.static_forces()
        blk = self._blocks(self.params)[0]
        y = np.zeros(self.n_states)
        for i in range(self.n_sets):
            for k, b in ((0, blk[i, ck.B_SQ]), (1, blk[i, ck.B_PQ])):
                gi = g[2 * i + k]
                y[4 * i + 2 * k] = gi + math.copysign(b, gi) if gi != 0.0 else 0.0
        return y

    def static_mesh_forces(self) -> np.ndarray:
        """Static mesh forces [N] under the mean loads, in the order of ``observable_names``:
        the deflection times the mean stiffness coefficient times the force scale, as the
        dynamic forces are observed."""
        g = self.static_forces()
        blk = self._blocks(self.params)[0]
        scale = blk[:, ck.FORCE_SCALE]
        out = np.empty(2 * self.n_sets)
        out[0::2] = g[0::2] * blk[:, ck.K_SQ_Q] * scale
        out[1::2] = g[1::2] * blk[:, ck.K_PQ_Q] * scale
        return out

    def carrier_acceleration(self) -> float:
        """Angular acceleration [rad/s^2] of the carrier (of the whole device: the mesh
        coordinates are constant) in the quasi-static state under the mean torques: the
        Eq. (1) body-angle equations evaluated at the state :meth:`initial_state` gives (mean
        stiffness, no error, no load fluctuation). Zero iff T_D, T_L1 and T_L2 balance; the
        paper's Table 2 does not (``docs/model.md``)."""
        quiet = self.replace(Ka=0.0, error=0.0, B1=0.0, B2=0.0)
        theta = quiet.dimensional()
        d, prm = quiet.derived, quiet.params_in
        x = quiet.general().initial_state() * prm.b_c  # X_sq1, V, X_pq1, V, ... [m]
        y = np.zeros(theta.n_states)  # theta_c = 0; every planet angle from its deflections
        for i in range(prm.n_planets):
            y[2 + 4 * i] = -x[4 * i] / d.r_bq[i]
            y[4 + 4 * i] = (y[2 + 4 * i] * d.r_bq[i] - x[4 * i + 2]) / d.r_bp[i]
        dy = np.empty(theta.n_states)
        theta.kernel.rhs(0.0, y, dy, np.ascontiguousarray(theta.params), 0.0, 1.0)
        return float(dy[1])

    def general(self) -> CATTDevice:
        """The same device in the general 4N-state form."""
        out = CATTDevice(self.params_in, self.interpretation, reduced=False, omega=self.omega)
        if not self.raw_overrides:
            return out
        n = self.params_in.n_planets
        raw: dict[str, float] = {}
        for name, value in self.raw_overrides.items():
            if name in CATT_HEADER.names or not self.reduced:
                raw[name] = value
            else:  # a reduced block coefficient: the same in every set (carrier coupling / N)
                per = value / n if name in ("k_sq_c", "c_sq_c") else value
                raw.update({f"{name}{i + 1}": per for i in range(n)})
        return out._override(raw)

    def expand_state(self, y: np.ndarray) -> np.ndarray:
        """A reduced state repeated for every planet set (the general model's symmetric state)."""
        if not self.reduced:
            return np.asarray(y, dtype=float).copy()
        return np.tile(np.asarray(y, dtype=float), self.params_in.n_planets)

    def dimensional(self) -> DimensionalCATT:
        """The dimensional body-angle model of Eq. (1) with the same parameters. Raises
        :class:`~geardyn.errors.ParameterError` when raw coefficients were set: the body-angle
        model is built from the physical parameters and has no place for them."""
        if self.raw_overrides:
            name = next(iter(self.raw_overrides))
            raise ParameterError(name, self.raw_overrides[name],
                                 "a raw coefficient has no counterpart in the dimensional "
                                 "body-angle model; set the physical parameters instead")
        return DimensionalCATT(self)

    def __repr__(self) -> str:
        form = "reduced" if self.reduced else "general"
        return (f"CATTDevice(N={self.params_in.n_planets}, {form}, "
                f"interpretation={self.interpretation!r}, Omega={self.omega:g})")


class DimensionalCATT(Model):
    """Eq. (1) in the body angles (2N + 1 rotational degrees of freedom), SI units.

    State: theta_c, theta_c', then theta_q_i, theta_q_i', theta_p_i, theta_p_i' per planet set
    [rad, rad/s]; time in seconds; ``params[0]`` is the mesh frequency omega = Omega omega_n.
    Written independently of the mesh-coordinate form, to verify it. Switching functions: the
    dead-zone edges x - b and x + b of every mesh deflection [m] (``event_names``), located by
    the solvers as in the mesh-coordinate form.
    """

    time_unit = "s"
    state_units = "rad, rad/s"
    capabilities = Capabilities(paper_device=True)

    def __init__(self, device: CATTDevice):
        prm = device.params_in
        d = device.derived
        n = prm.n_planets
        nh = int(device.params[ck.N_HARM])
        loads = prm.loads
        values: dict[str, float] = {
            "omega": device.omega * d.omega_n, "omega_L": loads.Lambda * d.omega_n,
            "n_sets": n, "n_harmonics": nh, "T_D": loads.T_D, "A1": loads.A1, "B1": loads.B1,
            "psi1": loads.psi1, "A2": loads.A2, "B2": loads.B2, "psi2": loads.psi2,
            "J_c": d.J_c_eff, "r_c1": prm.carrier.r_c1, "arm": d.arm,
        }
        for i in range(n):
            k = str(i + 1)
            sq, pq, _, _ = prm.planet_set(i)
            values.update({
                f"J_q{k}": d.J_q[i], f"J_p{k}": d.J_p[i], f"r_bq{k}": d.r_bq[i],
                f"r_bp{k}": d.r_bp[i], f"Km_sq{k}": sq.mean_stiffness,
                f"Km_pq{k}": pq.mean_stiffness, f"C_sq{k}": d.C_sq[i], f"C_pq{k}": d.C_pq[i],
                f"b_sq{k}": sq.backlash, f"b_pq{k}": pq.backlash,
                f"E_sq_s{k}": sq.error * math.cos(sq.error_phase),
                f"E_sq_c{k}": sq.error * math.sin(sq.error_phase),
                f"E_pq_s{k}": pq.error * math.cos(pq.error_phase),
                f"E_pq_c{k}": pq.error * math.sin(pq.error_phase),
            })
            for mesh, m in ((sq, "ksq"), (pq, "kpq")):
                a, b = fourier_coefficients(mesh, nh)
                for h in range(nh):
                    values[f"{m}_a{h + 1}{k}"] = a[h]
                    values[f"{m}_b{h + 1}{k}"] = b[h]
        self.device = device
        self.name = "DimensionalCATT"
        self.coefficient_layout = theta_layout(n, nh)
        self.params = self.coefficient_layout.build(values)
        self.kernel = _THETA_KERNEL
        self.omega_index = THETA_HEADER.offset("omega")
        self.state_names = ("theta_c", "dtheta_c") + tuple(
            f"{v}{i + 1}" for i in range(n)
            for v in ("theta_q", "dtheta_q", "theta_p", "dtheta_p")
        )
        # the dead-zone edges of every mesh deflection (switching functions, metres), as in
        # the mesh-coordinate form, so that steps are split there
        self.event_names = tuple(
            f"x_{m}{i + 1}{sign}b_{m}{i + 1}" for i in range(n) for m in ("sq", "pq")
            for sign in ("-", "+")
        )
        self.meshes = tuple(
            (f"{m}{i + 1}", 4 * i + 2 * k, 4 * i + 2 * k + 1)
            for i in range(n) for k, m in enumerate(("sq", "pq"))
        )

    @property
    def params_in(self) -> PlanetaryParams:
        """The device's parameters (the body-angle model is built from them)."""
        return self.device.params_in

    def fastest_natural_frequency(self, P: np.ndarray | None = None) -> np.ndarray:
        """Fastest natural frequency [rad/s] of Eq. (1) linearised (mean stiffness, no backlash)
        in every lane of ``P`` (default: this model's coefficients): sqrt of the largest
        eigenvalue magnitude of J^-1 K in the body angles, from each lane's inertias, radii and
        stiffnesses (vectorised; the rigid-body rotation gives a zero eigenvalue)."""
        P = np.atleast_2d(self.params if P is None else np.asarray(P, dtype=float))
        L, n = P.shape[0], int(P[0, ck.T_N])
        bs = ck.T_BLOCK_FIXED + 4 * int(P[0, ck.T_NH])
        blk = P[:, ck.T_HEADER : ck.T_HEADER + n * bs].reshape(L, n, bs)
        jq, jp = blk[:, :, ck.T_JQ], blk[:, :, ck.T_JP]
        rq, rp = blk[:, :, ck.T_RBQ], blk[:, :, ck.T_RBP]
        ks, kp = blk[:, :, ck.T_KM_SQ], blk[:, :, ck.T_KM_PQ]
        rc1, arm, jc = P[:, ck.T_RC1, None], P[:, ck.T_ARM, None], P[:, ck.T_JC]
        A = np.zeros((L, 2 * n + 1, 2 * n + 1))  # J^-1 K, angles (theta_c, theta_q1, theta_p1..)
        q, pp = np.arange(1, 2 * n + 1, 2), np.arange(2, 2 * n + 2, 2)
        A[:, 0, 0] = np.sum(arm * ks * rc1, axis=1) / jc
        A[:, 0, q] = -arm * ks * rq / jc[:, None]
        A[:, q, 0] = -rq * ks * rc1 / jq
        A[:, q, q] = rq * rq * (ks + kp) / jq
        A[:, q, pp] = -rq * kp * rp / jq
        A[:, pp, q] = -rp * kp * rq / jp
        A[:, pp, pp] = rp * kp * rp / jp
        return np.sqrt(np.max(np.abs(np.linalg.eigvals(A)), axis=1))

    @property
    def state_scale(self) -> np.ndarray:
        """Characteristic scale of each body-angle state [rad, rad/s]: the angle that moves its
        mesh by the nominal displacement b_c (b_c / r_c1 for the carrier, b_c / r_bq_i and
        b_c / r_bp_i for the planets), and for a rate that angle times omega_n, so that y / scale
        is of the size of the dimensionless mesh coordinates X = x / b_c and X' = dX/dtau."""
        prm = self.device.params_in
        d = self.device.derived
        radii = [prm.carrier.r_c1]
        for i in range(prm.n_planets):
            radii += [d.r_bq[i], d.r_bp[i]]
        angle = prm.b_c / np.asarray(radii, dtype=float)
        return np.stack([angle, angle * d.omega_n], axis=1).ravel()

    def mesh_coordinates(self, t: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Dimensionless mesh coordinates and their tau-derivatives (Eq. 8, 9) of body-angle states
        y[..., state] at times t [s] from forcing phase 0 (the mesh phase is omega t), in the
        general CATTDevice state order."""
        prm = self.device.params_in
        d = self.device.derived
        w = self.omega
        t = np.asarray(t, dtype=float)[..., None]
        out = []
        for i in range(prm.n_planets):
            sq, pq, _, _ = prm.planet_set(i)
            j = 2 + 4 * i
            e_sq = sq.error * np.sin(w * t[..., 0] + sq.error_phase)
            de_sq = sq.error * w * np.cos(w * t[..., 0] + sq.error_phase)
            e_pq = pq.error * np.sin(w * t[..., 0] + pq.error_phase)
            de_pq = pq.error * w * np.cos(w * t[..., 0] + pq.error_phase)
            x_sq = y[..., 0] * prm.carrier.r_c1 - y[..., j] * d.r_bq[i] - e_sq
            v_sq = y[..., 1] * prm.carrier.r_c1 - y[..., j + 1] * d.r_bq[i] - de_sq
            x_pq = y[..., j] * d.r_bq[i] - y[..., j + 2] * d.r_bp[i] - e_pq
            v_pq = y[..., j + 1] * d.r_bq[i] - y[..., j + 3] * d.r_bp[i] - de_pq
            out += [x_sq / prm.b_c, v_sq / (prm.b_c * d.omega_n), x_pq / prm.b_c,
                    v_pq / (prm.b_c * d.omega_n)]
        return np.stack(out, axis=-1)
