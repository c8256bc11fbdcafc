"""Coefficients declared once: what each entry of a model's coefficient vector is.

A model's compiled functions read one float64 vector ``p`` (``Model.params``). Each entry is
declared once, by a :class:`Coefficient` (name, unit, meaning, kind, what it derives from),
grouped into :class:`CoefficientBlock` s (a header, a block repeated per planet set or mesh).
From the declarations come:

* the kernel's index constants: ``block.offset(name)`` (an ``int``, so a module-level constant
  numba freezes at compile time), checked against the kernel module's constants by the tests;
* a model's :class:`CoefficientLayout` (its blocks placed in one vector, with name suffixes):
  the parameter names (``Model.param_names``), the index of a name, the vector built from values
  (:meth:`CoefficientLayout.build`), read back into a dict (:meth:`CoefficientLayout.read`),
  validation naming the field (:meth:`CoefficientLayout.validate`);
* the vocabulary (names, units, meanings) of study files, CLI help and the explorer
  (:meth:`CoefficientBlock.vocabulary`, :meth:`CoefficientLayout.vocabulary`).

Four kinds of entry (:data:`KINDS`), and only the first two are parameters:

``input``
    set directly by the user (a value of the model's own inputs, e.g. Omega);
``derived``
    computed from physical inputs (``derived_from`` names them); ``Model.with_params`` refuses
    it, naming those inputs, unless the model accepts raw overrides
    (``Model.raw_overrides_allowed``, the CATT device). One that is a function of one input's
    value carries that function (``derive=math.cos``): the layout then fills it
    (:meth:`CoefficientLayout.fill_derived`) wherever that input is set (``with_params``,
    ``lane_params``), so no model writes the derivation a second time; others are computed by
    the model's own code from its physical inputs;
``structure``
    constant for the model and the same in every lane (counts, sparse indices): it fixes the
    vector's layout or the kernel's loops; never a parameter;
``workspace``
    scratch the kernel writes (caches, flags); never a parameter.

Declaring a model (e.g. a gear pair with eight per-lane coefficients)::

    from geardyn.core.coefficients import Coefficient, CoefficientBlock, CoefficientLayout

    GEAR_PAIR = CoefficientBlock((
        Coefficient("Omega", "1", "mesh frequency / natural frequency", minimum=0.0),
        Coefficient("zeta", "1", "damping ratio", minimum=0.0),
        Coefficient("kappa", "1", "relative stiffness variation",
                    exclusive_minimum=-1.0, exclusive_maximum=1.0),
        Coefficient("Fm", "1", "mean load"), Coefficient("Fa", "1", "error amplitude"),
        Coefficient("kappa_phase", "rad", "stiffness phase"),
        Coefficient("error_phase", "rad", "error phase"),
        Coefficient("backlash", "1", "backlash half-width", minimum=0.0),
    ))
    OMEGA, ZETA = GEAR_PAIR.offset("Omega"), GEAR_PAIR.offset("zeta")   # kernel constants

and in the model's ``__init__``: ``self.coefficient_layout = CoefficientLayout.of(GEAR_PAIR,
model="GearPair")``, ``self.params = self.coefficient_layout.build(values, validate=True)``;
``param_names`` then follows the layout, and ``Model.with_params`` validates by the declaration.
A cos/sin pair derived from a phase is declared with its function::

    Coefficient("cos_kappa_phase", "1", "cos of the stiffness phase", kind="derived",
                derived_from=("kappa_phase",), derive=math.cos)

and ``layout.fill_derived(p)`` computes it from ``kappa_phase`` (``Model.with_params`` and
``Model.lane_params`` call it). (The gear pair's actual declaration is
:data:`geardyn.models.gear_pair_coefficients.GEAR_PAIR`.)
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from geardyn.errors import ParameterError, UnknownParameterError

#: The kinds of coefficient-vector entry (see the module doc); the first two are parameters.
KINDS: tuple[str, ...] = ("input", "derived", "structure", "workspace")
#: The kinds that are parameters (``param_names``, ``with_params``, ``lane_params``).
PARAMETER_KINDS: frozenset[str] = frozenset({"input", "derived"})
#: How many parameter names an error message lists.
_LISTED = 40


@dataclass(frozen=True)
class Coefficient:
    """One declared entry of a coefficient vector.

    ``unit`` is the unit of the value in the vector ("1" dimensionless); ``per_lane`` whether
    lanes of one sweep may hold different values (parameters by default; structure never);
    ``derived_from`` the physical inputs a derived coefficient is computed from; ``constant``
    the kernel's index constant (default the upper-cased name); ``default`` the value
    :meth:`CoefficientLayout.build` writes when none is given (workspace: its initial value);
    ``minimum``/``maximum`` (inclusive) and ``exclusive_*`` the admissible range; ``derive``,
    for a derived coefficient of one input, the function of that input's value that gives it
    (computed once per distinct value, in Python: ``math.cos`` is the libm the compiled code
    calls, so the same bits); ``explore`` whether the explorer offers an input coefficient as
    a control (a model whose inputs are its coefficients, no declared physical inputs)."""

    name: str
    unit: str = "1"
    meaning: str = ""
    kind: str = "input"
    derived_from: tuple[str, ...] = ()
    per_lane: bool | None = None
    constant: str | None = None
    default: float | None = None
    minimum: float | None = None
    maximum: float | None = None
    exclusive_minimum: float | None = None
    exclusive_maximum: float | None = None
    derive: Callable[[float], float] | None = None
    explore: bool = False

    def __post_init__(self) -> None:
        for label in ("name", "unit", "meaning"):
            if not isinstance(getattr(self, label), str):
                raise ValueError(f"{self.name}: {label} must be a string "
                                 f"(got {getattr(self, label)!r})")
        if self.kind not in KINDS:
            raise ValueError(f"{self.name}: kind must be one of {', '.join(KINDS)}; "
                             f"got {self.kind!r}")
        if isinstance(self.derived_from, str):
            raise ValueError(f"{self.name}: derived_from is a tuple of names "
                             f"(got {self.derived_from!r})")
        if self.kind == "derived" and not self.derived_from:
            raise ValueError(f"{self.name}: a derived coefficient names what it derives from")
        if self.derive is not None and not (self.kind == "derived" and callable(self.derive)
                                            and len(self.derived_from) == 1):
            raise ValueError(f"{self.name}: derive is the function of one input's value that "
                             "gives a derived coefficient (kind 'derived', derived_from one "
                             f"name, derive callable; got {self.derive!r})")
        if self.per_lane is None:
            object.__setattr__(self, "per_lane", self.kind in PARAMETER_KINDS)
        if self.per_lane and self.kind == "structure":
            raise ValueError(f"{self.name}: structure is the same in every lane")
        if self.explore and self.kind != "input":
            raise ValueError(f"{self.name}: the explorer offers input coefficients only")

    @property
    def is_parameter(self) -> bool:
        """Whether the entry is a parameter (an input or a derived coefficient)."""
        return self.kind in PARAMETER_KINDS

    @property
    def kernel_constant(self) -> str:
        """The name of the kernel's index constant for this entry."""
        return self.constant or self.name.upper()

    def check(self, field_name: str, value: float) -> float:
        """``value`` as a float, or a :class:`~geardyn.errors.ParameterError` naming
        ``field_name`` when it is not a finite number or outside the declared range."""
        try:
            v = float(value)
        except (TypeError, ValueError):
            v = None
        if v is None or isinstance(value, bool):
            raise ParameterError(field_name, value, "must be a number")
        if not math.isfinite(v):
            raise ParameterError(field_name, value, "must be finite")
        for bound, bad, word in ((self.minimum, v < (self.minimum or 0.0), ">="),
                                 (self.maximum, v > (self.maximum or 0.0), "<="),
                                 (self.exclusive_minimum, v <= (self.exclusive_minimum or 0.0),
                                  ">"),
                                 (self.exclusive_maximum, v >= (self.exclusive_maximum or 0.0),
                                  "<")):
            if bound is not None and bad:
                raise ParameterError(field_name, value, f"must be {word} {bound:g}")
        return v

    def describe(self) -> str:
        """One line: the meaning, the unit and, for a derived coefficient, its inputs."""
        text = self.meaning or self.name
        if self.unit not in ("", "1"):
            text += f" [{self.unit}]"
        if self.kind == "derived":
            text += f" (derived from {', '.join(self.derived_from)})"
        return text


@dataclass(frozen=True)
class CoefficientBlock:
    """Declared entries at consecutive offsets 0, 1, ... (a header, or a block repeated per
    planet set or mesh)."""

    entries: tuple[Coefficient, ...]
    _offsets: dict[str, int] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        offsets = {c.name: k for k, c in enumerate(self.entries)}
        if len(offsets) != len(self.entries):
            raise ValueError("a coefficient block declares a name twice")
        object.__setattr__(self, "_offsets", offsets)

    @property
    def size(self) -> int:
        """Number of entries."""
        return len(self.entries)

    @property
    def names(self) -> tuple[str, ...]:
        """Every entry's name, in order."""
        return tuple(c.name for c in self.entries)

    def offset(self, name: str) -> int:
        """The offset of ``name`` in the block (a kernel index constant)."""
        try:
            return self._offsets[name]
        except KeyError:
            raise KeyError(f"no coefficient {name!r}; declared: {', '.join(self.names)}") from None

    def __getitem__(self, name: str) -> Coefficient:
        return self.entries[self.offset(name)]

    def constants(self) -> dict[str, int]:
        """Kernel constant name -> offset, for every entry."""
        return {c.kernel_constant: k for k, c in enumerate(self.entries)}

    def vocabulary(self) -> dict[str, Coefficient]:
        """The parameters of the block by name (names, units, meanings for study files, CLI
        help and the explorer)."""
        return {c.name: c for c in self.entries if c.is_parameter}


#: Derived coefficients that carry their function: name -> (the entry it follows, the function
#: of that entry's value), as :meth:`CoefficientLayout.derivations` gives them.
Derivations = Mapping[str, tuple[str, Callable[[float], float]]]


@dataclass(frozen=True)
class Slot:
    """One placed entry of a layout: its name in the vector and its declaration."""

    name: str
    coefficient: Coefficient


class CoefficientLayout:
    """A model's coefficient vector: declared entries placed at indices 0 .. size - 1.

    Built with :meth:`of` (blocks, each with a name suffix) or by :meth:`extend` calls;
    ``model`` names the model in error messages."""

    def __init__(self, model: str = "model") -> None:
        self.model = model
        self._slots: list[Slot] = []
        self._index: dict[str, int] = {}
        self._derivations: dict[str, tuple[str, Callable[[float], float]]] = {}

    # ------------------------------------------------------------------ building the layout
    @classmethod
    def of(cls, *blocks: CoefficientBlock | tuple[CoefficientBlock, str],
           model: str = "model") -> CoefficientLayout:
        """A layout of ``blocks`` in order; a ``(block, suffix)`` pair appends ``suffix`` to
        each of its names."""
        out = cls(model)
        for b in blocks:
            block, suffix = b if isinstance(b, tuple) else (b, "")
            out.extend(block.entries, suffix)
        return out

    @classmethod
    def plain(cls, names: Sequence[str], model: str = "model") -> CoefficientLayout:
        """Every entry an input coefficient named ``names`` (a model that declares nothing)."""
        return cls.of(CoefficientBlock(tuple(Coefficient(n) for n in names)), model=model)

    def extend(self, entries: Iterable[Coefficient], suffix: str = "", prefix: str = "") -> int:
        """Append ``entries`` (names as ``prefix + name + suffix``); returns the index of the
        first. A name placed twice (a suffix that makes two names equal) is found at its first
        place."""
        start = len(self._slots)
        for c in entries:
            name = prefix + c.name + suffix
            self._index.setdefault(name, len(self._slots))
            self._slots.append(Slot(name, c))
            if c.derive is not None:
                self._derivations.setdefault(name, (prefix + c.derived_from[0] + suffix,
                                                    c.derive))
        return start

    def place(self, names: Iterable[str], coefficient: Coefficient) -> int:
        """Append one entry per name in ``names``, each declared by ``coefficient`` (a series
        of like entries: indices, cache rows); returns the index of the first. A coefficient
        that carries a ``derive`` function is placed by :meth:`extend` instead."""
        if coefficient.derive is not None:
            raise ValueError(f"{coefficient.name}: a derived coefficient with its function is "
                             "placed by extend (its input's name is its own, with the same "
                             "prefix and suffix)")
        start = len(self._slots)
        for name in names:
            self._index.setdefault(name, len(self._slots))
            self._slots.append(Slot(name, coefficient))
        return start

    # ------------------------------------------------------------------ lookups
    @property
    def size(self) -> int:
        """Length of the vector."""
        return len(self._slots)

    @property
    def slots(self) -> tuple[Slot, ...]:
        """Every placed entry, in vector order."""
        return tuple(self._slots)

    def at(self, index: int) -> Slot:
        """The entry at vector index ``index``."""
        return self._slots[index]

    @property
    def names(self) -> tuple[str, ...]:
        """The parameters' names, in vector order (``Model.param_names``)."""
        return tuple(s.name for s in self._slots if s.coefficient.is_parameter)

    @property
    def all_names(self) -> tuple[str, ...]:
        """Every entry's name, structure and workspace included."""
        return tuple(s.name for s in self._slots)

    def parameter_indices(self) -> np.ndarray:
        """Indices of the parameters in the vector (in the order of :attr:`names`)."""
        return np.array([k for k, s in enumerate(self._slots) if s.coefficient.is_parameter],
                        dtype=np.int64)

    def __contains__(self, name: object) -> bool:
        return name in self._index

    def vocabulary(self) -> dict[str, Coefficient]:
        """The parameters by their names in the vector (names, units, meanings: the
        vocabulary of study files, CLI help, the explorer and dataset axes)."""
        return {s.name: s.coefficient for s in self._slots if s.coefficient.is_parameter}

    def derivations(self) -> dict[str, tuple[str, Callable[[float], float]]]:
        """The derived coefficients that carry their function (``derive``): name -> (the
        entry it follows, the function of its value), in vector order (``Model.derived``)."""
        return dict(self._derivations)

    def slot(self, name: str, value: object = None) -> Slot:
        """The entry ``name`` (any kind); :class:`~geardyn.errors.UnknownParameterError`
        listing the parameters when there is none (``value``: the value given with it)."""
        if name not in self._index:
            raise UnknownParameterError(name, value, self._unknown())
        return self._slots[self._index[name]]

    def index(self, name: str, value: object = None) -> int:
        """The vector index of the parameter ``name``. A structure or workspace entry, or an
        unknown name, is an :class:`~geardyn.errors.UnknownParameterError` (a ``KeyError``)."""
        s = self.slot(name, value)
        if not s.coefficient.is_parameter:
            raise UnknownParameterError(name, value, self._not_parameter(s))
        return self._index[name]

    def raw_index(self, name: str) -> int:
        """The vector index of any entry ``name`` (kernel-side code: structure, workspace)."""
        self.slot(name)
        return self._index[name]

    def _known(self) -> str:
        names = self.names
        if len(names) <= _LISTED:
            return ", ".join(names)
        return f"{', '.join(names[:_LISTED])}, ... ({len(names)} in all: param_names)"

    def _unknown(self) -> str:
        return f"{self.model} has no parameter of this name; known: {self._known()}"

    def _not_parameter(self, s: Slot) -> str:
        what = {"structure": "structure", "workspace": "kernel workspace"}[s.coefficient.kind]
        meaning = f"{s.coefficient.meaning}: " if s.coefficient.meaning else ""
        return f"{meaning}{what} of {self.model}, never a parameter; parameters: {self._known()}"

    # ------------------------------------------------------------------ vectors
    def build(self, values: Mapping[str, float], validate: bool = False) -> np.ndarray:
        """The vector with every entry from ``values`` (by name) or its declared ``default``;
        an entry with neither, or a name not in the layout, is an error naming it. With
        ``validate`` each parameter is checked against its declaration (:meth:`validate`)."""
        extra = [k for k in values if k not in self._index]
        if extra:
            raise UnknownParameterError(extra[0], values[extra[0]], self._unknown())
        if validate:
            self.validate({k: v for k, v in values.items()
                           if self._slots[self._index[k]].coefficient.is_parameter})
        p = np.empty(self.size)
        for k, s in enumerate(self._slots):
            v = values.get(s.name, s.coefficient.default)
            if v is None:
                raise ParameterError(s.name, None, f"{self.model}: no value given")
            p[k] = v
        return p

    def fill_derived(self, P: np.ndarray) -> np.ndarray:
        """Set, in place, every derived coefficient that carries its function (``derive``) in
        the vector or rows ``P`` from the entry it follows: each function is called once per
        distinct value, in Python (``math.cos``: the libm the compiled code calls, so the same
        bits). Returns ``P``. An input the layout does not hold is a ValueError naming both."""
        for name, (source, fn) in self._derivations.items():
            if source not in self._index:
                raise ValueError(f"{name}: derived from {source}, which {self.model} does not "
                                 "declare")
            col = P[..., self._index[source]]
            values, inverse = np.unique(col, return_inverse=True)
            P[..., self._index[name]] = np.array([fn(float(v)) for v in values])[
                inverse].reshape(col.shape)
        return P

    def read(self, p: np.ndarray, parameters_only: bool = True) -> dict[str, float]:
        """The vector ``p`` read back by name (parameters only, unless ``parameters_only`` is
        False)."""
        p = np.asarray(p, dtype=float)
        if p.shape[-1] != self.size:
            raise ValueError(f"{self.model}: a vector of {p.shape[-1]} entries for a layout of "
                             f"{self.size}")
        return {s.name: float(p[k]) for k, s in enumerate(self._slots)
                if s.coefficient.is_parameter or not parameters_only}

    def validate(self, values: Mapping[str, float]) -> dict[str, float]:
        """``values`` checked by name: each a known parameter (else an
        :class:`~geardyn.errors.UnknownParameterError`), finite and within its declared range
        (else a :class:`~geardyn.errors.ParameterError` naming it). Returns them as floats."""
        out = {}
        for name, value in values.items():
            self.index(name, value)
            out[name] = self.slot(name).coefficient.check(name, value)
        return out
