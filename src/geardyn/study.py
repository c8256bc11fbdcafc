"""Studies turned into models: the one place that knows which model a study file names.

:mod:`geardyn.io.toml` reads and validates a study file (or a packaged one,
``geardyn/studies/*.toml``) into a :class:`~geardyn.io.toml.Study`, plain validated data;
:func:`build_model` makes the model it describes (a :class:`~geardyn.SpurPair` of its
``[gears]`` for a ``spur_pair`` study), :func:`mesh_stiffness` the potential-energy mesh
stiffness of its ``[gears]``. This module sits above both ``models`` and ``io``
(``tests/test_layers.py``), so that reading a study never imports a model's kernels, and the
packaged study files stay data.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import xarray as xr
from pydantic import ValidationError

from geardyn.core.model import Model
from geardyn.errors import ParameterError, StudyError
from geardyn.io.study_models import STUDY_MODELS, study_model
from geardyn.io.toml import FaultTable, PlanetaryGearSetParams, Study
from geardyn.models.catt import CATTDevice
from geardyn.models.derived import INTERPRETATIONS
from geardyn.models.gear_pair import GearPair
from geardyn.models.planetary import Member, PlanetaryGearSet
from geardyn.models.planetary_coefficients import INPUTS as PLANETARY_INPUTS
from geardyn.models.spur_pair import SpurPair, period_cycles
from geardyn.units import to_si

__all__ = ["BUILDERS", "FAULTED", "build_model", "check_usable", "faulted_model",
           "mesh_stiffness", "planetary_model", "spur_pair_model", "study_omega", "train_model"]


def require_model(study: Study) -> None:
    """A :class:`~geardyn.StudyError` unless ``study`` describes a model (has ``[params]``): a
    study of gears alone is for ``geardyn stiffness``, one of a gear train (``[train]``)
    alone for ``geardyn modes``."""
    if study.params is None:
        what = ("a gear train ([train]) for geardyn modes" if study.train is not None
                else "gears ([gears]) for geardyn stiffness")
        raise StudyError(f"study {study.study.name!r} has no [params]: it describes {what},"
                         " not a model")


def build_model(study: Study, interpretation: str | None = None, omega: float | None = None
                ) -> Model:
    """The study's model: a :class:`~geardyn.CATTDevice`, a :class:`~geardyn.GearPair`, a
    :class:`~geardyn.PlanetaryGearSet`, a :class:`~geardyn.SpurPair` or a gear train's
    ``TrainModel``, as the builder of its ``[study].model`` makes it (``BUILDERS``, one per
    kind of ``geardyn.io.study_models.STUDY_MODELS``).

    ``interpretation`` and ``omega`` override the study's (``omega`` defaults to
    ``[run].omega``, else 1; a spur pair's to the Omega of its ``[params].speed``). Raises
    :class:`~geardyn.ParameterError` for an unknown interpretation or parameters that give no
    usable model (:func:`check_usable`).
    """
    if interpretation is not None and interpretation not in INTERPRETATIONS:
        raise ParameterError(
            "interpretation", interpretation, f"must be one of {', '.join(INTERPRETATIONS)}"
        )
    require_model(study)
    om = omega if omega is not None else study.run.omega
    build = BUILDERS[study_model(study.study.model).name]
    return check_usable(lambda: build(study, om, interpretation))


def _catt_model(study: Study, omega: float | None, interpretation: str | None) -> Model:
    return CATTDevice(study.planetary_params,
                      interpretation or study.study.interpretation,  # type: ignore[arg-type]
                      omega=1.0 if omega is None else float(omega))


def _gear_pair_model(study: Study, omega: float | None, interpretation: str | None) -> Model:
    kwargs = study.params.model_dump()  # type: ignore[union-attr]
    if omega is not None:
        kwargs["Omega"] = float(omega)
    return GearPair(**kwargs)


#: What builds the model of each study model kind (:data:`~geardyn.io.study_models.STUDY_MODELS`)
#: from a study: ``(study, omega or None, interpretation or None) -> model``.
BUILDERS: dict[str, Callable[[Study, float | None, str | None], Model]] = {
    "catt": _catt_model,
    "gear_pair": _gear_pair_model,
    "spur_pair": lambda study, omega, _: spur_pair_model(study, omega),
    "planetary": lambda study, omega, _: planetary_model(study.params, omega),  # type: ignore
    "train": lambda study, omega, _: train_model(study, omega),
}


def _spur_pair_faulted(study: Study, tables: list[dict]) -> Model:
    faults = [FaultTable(**t) for t in tables]
    return spur_pair_model(study.model_copy(update={"faults": faults or None}))


def _planetary_faulted(study: Study, tables: list[dict]) -> Model:
    params = study.params
    faults = [FaultTable(**t) for t in tables]
    geometry = params.geometry.model_copy(update={"faults": faults or None})  # type: ignore
    return planetary_model(params.model_copy(update={"geometry": geometry}))  # type: ignore


def _train_faulted(study: Study, tables: list[dict]) -> Model:
    train = study.train.model_copy(update={"faults": list(tables)}).build()  # type: ignore
    return train_model(study, train=train)


#: What builds the model of a study with other faults, per study model kind that takes them
#: (``StudyModel.dataset``): ``(study, fault tables) -> model``, the tables (``[]``: healthy) in
#: place of the study's own (``StudyModel.dataset.table``).
FAULTED: dict[str, Callable[[Study, list[dict]], Model]] = {
    "spur_pair": _spur_pair_faulted,
    "planetary": _planetary_faulted,
    "train": _train_faulted,
}


def faulted_model(study: Study, tables: list[dict]) -> Model:
    """The study's model with the fault ``tables`` (each a fault table's fields; ``[]``:
    healthy) in place of the study's own faults (:data:`FAULTED`); a
    :class:`~geardyn.StudyError` for a kind that takes none."""
    kind = study_model(study.study.model)
    if kind.name not in FAULTED:
        takes = ", ".join(k for k, m in STUDY_MODELS.items() if m.dataset is not None)
        raise StudyError(f"study {study.study.name!r}: a {kind.name} study takes no other "
                         f"faults (one of {takes} does)")
    return FAULTED[kind.name](study, tables)


def mesh_stiffness(study: Study, faults: bool = True, loaded: bool = True) -> xr.Dataset:
    """The potential-energy mesh stiffness of the study's ``[gears]`` pair
    (:func:`~geardyn.gears.potential_energy_stiffness`, or
    :func:`~geardyn.gears.helical_stiffness` for a helical pair, with the ``[stiffness]``
    settings and the ``[[faults]]``; ``faults=False``: the healthy pair), the study's name in
    its attrs. With a load (``[stiffness]`` torque or force) and ``loaded``, the variables of
    the loaded contact (:func:`~geardyn.gears.loaded_contact`, or
    :func:`~geardyn.gears.helical_loaded_contact`, with ``[[relief]]`` and ``[crowning]``)
    join it, and its attrs ``force_N``, ``relief``, ``crowning`` (and ``torque_Nm``)."""
    from geardyn.gears import (
        HelicalMesh,
        helical_loaded_contact,
        helical_stiffness,
        loaded_contact,
        potential_energy_stiffness,
    )

    mesh, kw = study.stiffness_inputs(faults=faults)
    helical = isinstance(mesh, HelicalMesh)
    ds = (helical_stiffness if helical else potential_energy_stiffness)(mesh, **kw)
    load = study.contact_inputs(mesh) if loaded else None
    if load is not None:
        if helical:
            contact = helical_loaded_contact(mesh, ds, load["force"], load["relief"],
                                             load["crowning"])
        else:
            contact = loaded_contact(mesh, ds, load["force"], load["relief"])
        ds = ds.assign(contact.data_vars)
        ds.attrs.update(contact.attrs)
        if load["torque"] is not None:
            ds.attrs["torque_Nm"] = load["torque"]
    ds.attrs["study"] = study.study.name
    return ds


def train_model(study: Study, omega: float | None = None, train: object = None) -> Model:
    """The :class:`~geardyn.trains.TrainModel` of a ``train`` study: the ``[train]`` table's
    gear train (or ``train``, a :class:`~geardyn.trains.GearTrain` in its place) with the
    inputs of ``[params]`` (at the forcing frequency Omega ``omega`` where given). Errors name
    ``params.<field>``."""
    from geardyn.trains import TrainModel

    kw = study.params.model_dump()  # type: ignore[union-attr]
    try:
        model = TrainModel(study.gear_train if train is None else train, **kw)
    except ParameterError as exc:
        raise ParameterError(f"params.{exc.field}", exc.value, exc.reason) from None
    return model if omega is None else model.with_omega(float(omega))


def spur_pair_model(study: Study, omega: float | None = None) -> SpurPair:
    """:meth:`SpurPair.from_geometry` of a ``spur_pair`` study: the pair, bores, material and
    faults of ``[gears]`` and ``[[faults]]``, the angles and quadrature of ``[stiffness]``,
    the dynamics of ``[params]`` (with the forcing frequency Omega [rad/s] ``omega`` where
    given). ``[stiffness].cycles``, where the study gives it, must be the period's mesh
    cycles (the table spans one forcing period). Errors name ``params.<field>`` or
    ``stiffness.cycles``."""
    mesh, kw = study.stiffness_inputs()
    dyn = study.params.model_dump()  # type: ignore[union-attr]
    period = dyn.get("period")
    table = study.stiffness
    if table is not None and table.cycles is not None:
        faulty = sorted({getattr(f, "gear", None) for f in kw.get("faults", ())} - {None})
        try:
            want = period_cycles(mesh, period or (faulty[0] if faulty else "pinion"))
        except ParameterError as exc:
            raise ParameterError(f"params.{exc.field}", exc.value, exc.reason) from None
        if kw["cycles"] != want:
            raise ParameterError("stiffness.cycles", table.cycles, f"a spur_pair model's table"
                                 f" spans its forcing period ({want} mesh cycles); leave it out"
                                 " or give that")
    kw.pop("cycles")
    inertia = dyn.pop("inertia")
    try:
        model = SpurPair.from_geometry(
            mesh, **kw, **{k: v for k, v in dyn.items() if v is not None},
            **({} if inertia is None else {"inertia": tuple(inertia)}))
    except ParameterError as exc:
        raise ParameterError(f"params.{exc.field}", exc.value, exc.reason) from None
    return model if omega is None else model.with_omega(float(omega))


def study_omega(study: Study, model: Model, given: float | None = None) -> float | None:
    """The forcing frequency Omega of a run of ``study``: ``given`` (a command's --omega),
    else ``[run].omega``, else, for a model whose ``[params]`` set it (a spur pair's speed),
    the model's (a spur pair's speed, a train's input speed); None where the study sets
    none."""
    if given is not None:
        return given
    if study.run.omega is not None:
        return study.run.omega
    return model.omega if study_model(study.study.model).omega_from_params else None


def planetary_model(params: PlanetaryGearSetParams, omega: float | None = None
                    ) -> PlanetaryGearSet:
    """The :class:`~geardyn.PlanetaryGearSet` of a planetary study's ``[params]`` (with the
    dimensionless mesh frequency ``omega`` where given). A bad value raises
    :class:`ParameterError` naming ``params.<field>``."""
    kw = params.model_dump()
    for name in ("sun", "ring", "carrier", "planet"):
        kw[name] = Member(**kw[name])
    kw["fixed"] = tuple(kw["fixed"])
    geometry = kw.pop("geometry")
    held = kw.pop("held")
    try:
        if geometry is None:
            if held is not None:
                raise ParameterError("held", held, "sets the input-speed kinematics of a set "
                                     "built from [params.geometry]; give that table")
            for i in PLANETARY_INPUTS:  # required unless [params.geometry] stands for them
                if i.alternative == "geometry" and kw[i.name] is None:
                    raise ParameterError(i.name, None, "required (or give [params.geometry])")
            model = PlanetaryGearSet(**kw)
        else:
            model = _from_geometry(geometry, kw, held)
    except ParameterError as exc:
        raise ParameterError(f"params.{exc.field}", exc.value, exc.reason) from None
    return model if omega is None else model.with_omega(float(omega))


def _from_geometry(table: dict, kw: dict, held: str | None = None) -> PlanetaryGearSet:
    """:meth:`PlanetaryGearSet.from_geometry` of a ``[params.geometry]`` table; ``kw`` the
    other ``[params]``: those the geometry gives must keep their defaults."""
    from geardyn.gears import PlanetaryGeometry, SpurGear
    from geardyn.models.planetary import _FROM_GEOMETRY

    fields = PlanetaryGearSetParams.model_fields
    for name in _FROM_GEOMETRY:
        if name not in ("n_planets", "planet_angles") and kw[name] != fields[name].default:
            raise ParameterError(name, kw[name], "comes from [params.geometry]; remove it")
    gears = {}
    for name in ("sun", "planet", "ring"):
        g = table[name]
        gears[name] = SpurGear(
            g["teeth"], table["module"], table["pressure_angle"],
            g["face_width"] if g["face_width"] is not None else table["face_width"],
            profile_shift=g["profile_shift"], addendum=table["addendum"],
            dedendum=table["dedendum"], internal=name == "ring", name=f"geometry.{name}")
    angles = kw.pop("planet_angles")
    stage = PlanetaryGeometry(
        gears["sun"], gears["planet"], gears["ring"], n_planets=kw["n_planets"],
        planet_angles=None if angles is None else tuple(to_si(a, "angle") for a in angles),
        centre_distance=None if table["centre_distance"] is None
        else to_si(table["centre_distance"], "length"))
    extra = {k: v for k, v in kw.items() if k not in _FROM_GEOMETRY}
    waves = {"waveform_options": {"transition": table["transition"]}}
    if table["stiffness"] == "potential_energy":
        if table["transition"] != 0.0:
            raise ParameterError("geometry.transition", table["transition"],
                                 "shapes the ISO waves; the potential-energy stiffness has none")
        waves = {}
    faults = _geometry_faults(table.get("faults") or [])
    try:
        return PlanetaryGearSet.from_geometry(
            stage, held=held, stiffness=table["stiffness"],
            stiffness_options=table["stiffness_options"] or None, coast=table["coast"],
            faults=faults, **waves, **extra)
    except ParameterError as exc:
        if exc.field.split(".")[0] in ("stiffness", "stiffness_options", "waveform_options",
                                        "coast", "faults"):
            raise ParameterError(f"geometry.{exc.field}", exc.value, exc.reason) from None
        kind, _, name = exc.field.partition(".")
        hit = [i for i, f in enumerate(faults) if f.kind == kind]
        if hit and name:
            same = [i for i in hit if getattr(faults[i], name, None) == exc.value]
            i = (same or hit)[0]
            raise ParameterError(f"geometry.faults[{i}].{name}", exc.value,
                                 exc.reason) from None
        raise


def _geometry_faults(tables: list[dict]) -> list:
    """The fault objects of ``[[params.geometry.faults]]`` (:class:`~geardyn.io.toml.FaultTable`
    each); errors name ``geometry.faults[<i>].<field>``."""
    from geardyn.io.toml import FaultTable

    out = []
    for i, t in enumerate(tables):
        try:
            out.append(FaultTable(**t).build(("faults", i)))
        except ValidationError as exc:
            err = exc.errors(include_url=False)[0]
            field = f"geometry.faults[{i}]" + "".join(f".{p}" for p in err["loc"][2:])
            raise ParameterError(field, err.get("input"), err["msg"]) from None
    return out


def check_usable(build: Callable[[], Model]) -> Model:
    """The model ``build()`` returns, if its coefficients, natural frequencies and initial state
    are finite; else a :class:`ParameterError` naming the first quantity that is not.

    Values that each pass validation can still overflow together (a module of 1e200 m, an inertia
    of 1e-308 kg m^2): the model would then integrate NaNs. Floating-point warnings raised while
    building are silenced, as the error replaces them.
    """
    with np.errstate(all="ignore"):
        try:
            model = build()
            checks = [(f"coefficient {n}", v) for n, v in model.coefficient_values().items()]
            if model.capabilities.natural_frequencies:
                checks += [("natural frequency", w) for w in model.natural_frequencies()]
            checks += [(f"initial state {n}", v)
                       for n, v in zip(model.state_names, model.initial_state(), strict=True)]
        except (ArithmeticError, ValueError) as exc:  # overflow, singular matrix, ...
            if isinstance(exc, ParameterError | ValidationError):
                raise
            reason = exc.args[-1] if isinstance(exc, OverflowError) and exc.args else str(exc)
            reason = " ".join(str(reason).split()) or type(exc).__name__
            raise ParameterError("params", reason, "the parameters give no usable model (a value"
                                 " is too extreme)") from None
    for what, value in checks:
        if not math.isfinite(float(value)):
            raise ParameterError("params", float(value), f"the model's {what} is not finite (a"
                                 " parameter value is too extreme)")
    return model
