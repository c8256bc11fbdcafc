"""The study model kinds: what each value of ``[study].model`` declares, read by the study file
schema (:mod:`geardyn.io.toml`), the model builders (:mod:`geardyn.study`), the command line
and the explorer instead of comparing the kind's name.

:data:`STUDY_MODELS` is the registry; :func:`study_model` looks a kind up (a
:class:`~geardyn.ParameterError` naming the known kinds for any other). What builds the model
of a kind is :data:`geardyn.study.BUILDERS` (one layer up, keyed by the same names; a test
checks that every kind has one).
"""

from __future__ import annotations

from dataclasses import dataclass

from geardyn.core.coefficients import CoefficientBlock
from geardyn.core.inputs import PhysicalInput, explored
from geardyn.errors import ParameterError
from geardyn.models.gear_pair_coefficients import GEAR_PAIR
from geardyn.models.params import PAPER_INPUTS
from geardyn.models.planetary_coefficients import INPUTS as PLANETARY_INPUTS
from geardyn.models.spur_pair_coefficients import INPUTS as SPUR_PAIR_INPUTS
from geardyn.trains.inputs import INPUTS as TRAIN_INPUTS

__all__ = ["PARAMS_VIEWS", "STUDY_MODELS", "DatasetFaults", "StudyModel", "study_model"]

#: How ``geardyn params show`` presents a kind's model: ``"paper"`` (the paper's derived
#: quantities, Eq. (10) coefficients, omega_n and natural frequencies), ``"coefficients"`` (the
#: declared dimensionless coefficients), ``"spur_pair"`` (a spur pair's inputs and series),
#: ``"modes"`` (time and length scales, natural frequencies and the swept inputs), ``"train"``
#: (``"modes"`` with the meshes' orders).
PARAMS_VIEWS = ("paper", "coefficients", "spur_pair", "modes", "train")


@dataclass(frozen=True)
class DatasetFaults:
    """What ``geardyn dataset`` needs of a study of the kind.

    ``table``
        The table of the study's own faults, which each condition's fault replaces.
    ``check``
        How a condition's fault is checked: ``"gears"`` against the study's ``[gears]`` pair
        (its stiffness inputs), ``"model"`` by building the model with it.
    ``needs``, ``refusal``
        A study table the kind needs for a dataset (a dotted path, ``"params.geometry"``) and
        the refusal where it is missing ("" none).
    """

    table: str
    check: str
    needs: str = ""
    refusal: str = ""

    def __post_init__(self) -> None:
        if self.check not in ("gears", "model"):
            raise ValueError(f"check={self.check!r}: one of gears, model")
        if bool(self.needs) != bool(self.refusal):
            raise ValueError("needs and refusal go together")


@dataclass(frozen=True)
class StudyModel:
    """One kind of study model, the value of ``[study].model``.

    ``name``
        The kind (``"spur_pair"``).
    ``params``
        The class name of its ``[params]`` table in :mod:`geardyn.io.toml`.
    ``label``
        What its parameters describe, in messages (``"SpurPair"``).
    ``inputs``
        The declarations its ``[params]`` names come from: a model's declared physical inputs,
        or its declared coefficients (a :class:`~geardyn.core.coefficients.CoefficientBlock`,
        whose entries give the explorer's help).
    ``example``
        A study of the kind: a built-in study's name or TOML text.
    ``plot_state``
        The coordinate figures show by default ("" none: the study names it).
    ``transient_periods``
        The default transient in forcing periods of the lowest Omega of a run (a model in
        seconds); None: ``[run].transient``'s default.
    ``omega_from_params``
        ``[params]`` sets the forcing frequency (a speed): a run without ``--omega`` or
        ``[run].omega`` runs at the model's Omega.
    ``paper_device``
        The paper's device: ``[study].interpretation`` applies (the explorer offers it), and
        ``[params]`` is the device's parameters, in full or as ``base = "paper"`` with changes
        by the paper's names (:data:`~geardyn.models.params.PAPER_NAMES`).
    ``requires``
        Tables a study of the kind must have, each with what it holds.
    ``spur_pair_gears``
        Its model is built from the ``[gears]`` pair as an external spur pair on its unloaded
        mesh stiffness: the fields of a helical or internal pair and of a loaded contact are
        refused.
    ``explore_given_only``
        The explorer offers an input only where the study gives it as one number (an input
        may be a per-mesh table, which is not a control).
    ``params_view``
        How ``geardyn params show`` presents the model (:data:`PARAMS_VIEWS`).
    ``dataset``
        What ``geardyn dataset`` needs of the study (:class:`DatasetFaults`; None: it takes
        none of the kind).
    ``geometry``
        The table of ``[params]`` a model of the kind may be built from (a dotted path,
        ``"params.geometry"``; "" none): where the study has it, the explorer offers its
        controls and those of its ``[[<geometry>.faults]]``.
    """

    name: str
    params: str
    label: str
    inputs: CoefficientBlock | tuple[PhysicalInput, ...]
    example: str
    params_view: str
    plot_state: str = ""
    transient_periods: float | None = None
    omega_from_params: bool = False
    paper_device: bool = False
    requires: tuple[tuple[str, str], ...] = ()
    spur_pair_gears: bool = False
    explore_given_only: bool = False
    dataset: DatasetFaults | None = None
    geometry: str = ""

    def __post_init__(self) -> None:
        if self.params_view not in PARAMS_VIEWS:
            raise ValueError(f"params_view={self.params_view!r}: one of {', '.join(PARAMS_VIEWS)}")

    @property
    def explored(self) -> tuple[str, ...]:
        """The inputs the explorer offers as controls (flagged ``explore``), in declared
        order."""
        if isinstance(self.inputs, CoefficientBlock):
            return tuple(c.name for c in self.inputs.entries if c.explore)
        return explored(self.inputs)

    @property
    def coefficients(self) -> CoefficientBlock | None:
        """Its declared coefficients where ``[params]`` names them (else None)."""
        return self.inputs if isinstance(self.inputs, CoefficientBlock) else None


_GEAR_PAIR_EXAMPLE = """[study]
name = "gear_pair_example"
model = "gear_pair"
[params]
zeta = 0.05
Fa = 0.2
[run]
omega = 1.3
"""

#: The registry: every kind of study model, by name. ``geardyn dataset`` lists the kinds it
#: takes in this order.
STUDY_MODELS: dict[str, StudyModel] = {m.name: m for m in (
    StudyModel("catt", "PlanetaryParams", "PlanetaryParams", PAPER_INPUTS, "paper_fig3",
               "paper", plot_state="X_sq", paper_device=True),
    StudyModel("gear_pair", "GearPairParams", "GearPair", GEAR_PAIR, _GEAR_PAIR_EXAMPLE,
               "coefficients", plot_state="x"),
    StudyModel("spur_pair", "SpurPairParams", "SpurPair", SPUR_PAIR_INPUTS, "spur_pair_cracked",
               "spur_pair", plot_state="x", transient_periods=50.0, omega_from_params=True,
               requires=(("gears", "the pair the model is built from"),
                         ("params", "the pair's speed, torque and dynamics")),
               spur_pair_gears=True,
               dataset=DatasetFaults("[[faults]]", "gears")),
    StudyModel("planetary", "PlanetaryGearSetParams", "PlanetaryGearSet", PLANETARY_INPUTS,
               "planetary_example", "modes", plot_state="u_s", geometry="params.geometry",
               dataset=DatasetFaults(
                   "[[params.geometry.faults]]", "model", needs="params.geometry",
                   refusal="geardyn dataset takes a planetary set built from [params.geometry]"
                           " (the ring sensor's ring, the faults' teeth)")),
    StudyModel("train", "TrainModelParams", "TrainModel", TRAIN_INPUTS, "two_stage_train",
               "train", omega_from_params=True, explore_given_only=True,
               requires=(("train", "the gear train whose model [params] describes"),),
               dataset=DatasetFaults("[[train.faults]]", "model")),
)}


def study_model(name: str) -> StudyModel:
    """The registered kind ``name``; a :class:`~geardyn.ParameterError` naming
    ``study.model`` and the known kinds for any other."""
    try:
        return STUDY_MODELS[name]
    except (KeyError, TypeError):
        raise ParameterError("study.model", name,
                             f"unknown study model; one of {', '.join(STUDY_MODELS)}") from None
