"""A setting or parameter is validated once, where it enters, by one declared rule: the
explorer's and the command line's choices are the study file's (the same value accepted or
refused by both), a ``base = "paper"`` table is resolved once, the geometry a kind is built from
is declared, and every model with a rectangular stiffness waveform checks its contact ratio and
harmonics by one rule."""

from __future__ import annotations

import math
from unittest import mock

import pytest
from pydantic import ValidationError

import geardyn
from geardyn.cli.common import Interpretation
from geardyn.cli.errors import format_error
from geardyn.errors import ParameterError
from geardyn.explore.state import CONTINUATIONS, INTERPRETATIONS, ExplorerState, key_path
from geardyn.io.study_models import STUDY_MODELS
from geardyn.io.toml import PaperBase, Study, builtin_study, load_study, params_class
from geardyn.models.params import PlanetaryParams
from geardyn.study import build_model

#: Values tried on both sides: every declared one and near misses.
CANDIDATES = (*INTERPRETATIONS, *CONTINUATIONS, "carrier_only", "As-printed", "sideways", "",
              "true")


def _accepted_by_study_file(table: str, key: str, value: str) -> bool:
    doc = builtin_study("paper_fig3").to_toml_dict()
    doc[table][key] = value
    try:
        Study.model_validate(doc)
    except ValidationError:
        return False
    return True


@pytest.mark.parametrize("value", CANDIDATES)
def test_the_explorer_and_the_study_file_accept_the_same_interpretations(value):
    state = ExplorerState(builtin_study("paper_fig3"), "paper_fig3", describe_error=format_error)
    message = state.set_interpretation(value)
    assert (message is None) == _accepted_by_study_file("study", "interpretation", value)
    if message is not None:  # the refusal names the setting and the value
        assert message.startswith("interpretation:") and repr(value) in message


@pytest.mark.parametrize("value", CANDIDATES)
def test_the_explorer_and_the_study_file_accept_the_same_continuations(value):
    state = ExplorerState(builtin_study("paper_fig3"), "paper_fig3", describe_error=format_error)
    message = state.set_continuation(value)
    assert (message is None) == _accepted_by_study_file("sweep", "continuation", value)
    if message is not None:
        assert message.startswith("continuation:") and repr(value) in message


def test_the_command_lines_choices_are_the_study_files():
    """``--interpretation`` (an enumeration kept in the light CLI modules) offers exactly the
    values the study file accepts, and so do ``--continuation``'s."""
    assert tuple(m.value for m in Interpretation) == INTERPRETATIONS
    for value in INTERPRETATIONS:
        assert _accepted_by_study_file("study", "interpretation", value)
    for value in CONTINUATIONS:
        assert _accepted_by_study_file("sweep", "continuation", value)


PAPER_BASE = """
[study]
name = "changed"
[params]
base = "paper"
[params.changes]
backlash = 1e-4
xi1 = 0.07
"""


def test_a_paper_base_table_is_resolved_once_and_as_the_paper_says():
    paper = PlanetaryParams.paper
    with mock.patch.object(PlanetaryParams, "paper", side_effect=paper) as spy:
        study = load_study(PAPER_BASE)
    assert spy.call_count == 1
    expected = PlanetaryParams.paper(backlash=1e-4, xi1=0.07)  # the device, built directly
    assert study.planetary_params == expected
    assert isinstance(study.params, PaperBase) and study.params.device is study.planetary_params


def test_a_paper_base_given_as_an_object_is_checked_as_a_file_is():
    ok = Study(params=PaperBase(base="paper", changes={"backlash": 1e-4, "xi1": 0.07}))
    assert ok.planetary_params == load_study(PAPER_BASE).planetary_params
    with pytest.raises(ValidationError) as err:  # an invalid change names its key
        Study(params=PaperBase(base="paper", changes={"xi1": -1.0}))
    assert err.value.errors()[0]["loc"][:3] == ("params", "changes", "xi1")
    with pytest.raises(ValidationError) as err:
        load_study(PAPER_BASE.replace("xi1 = 0.07", "xi1 = -1.0"))
    assert err.value.errors()[0]["loc"][:3] == ("params", "changes", "xi1")


@pytest.mark.parametrize("kind", [m for m in STUDY_MODELS.values() if m.geometry])
def test_a_declared_geometry_table_is_a_table_of_the_kinds_params(kind):
    path = key_path(kind.geometry)
    assert path[0] == "params" and len(path) == 2
    assert path[1] in params_class(kind).model_fields


def _planetary(**kw) -> geardyn.Model:
    M = geardyn.Member
    return geardyn.PlanetaryGearSet(
        n_planets=3, sun=M(0.4, 0.39, 1e8, 0.0, radius=0.03), ring=M(2.35, 3.0, 1e8, 1e9),
        carrier=M(5.43, 6.29, 1e8, 0.0), planet=M(0.66, 0.61, 1e8),
        sun_mesh_stiffness=5e8, ring_mesh_stiffness=5e8, sun_backlash="2 um",
        ring_backlash="1 um", modal_damping=0.02, sun_torque=50.0, **kw)


def _train(**kw) -> geardyn.Model:
    doc = builtin_study("two_stage_train").to_toml_dict()
    doc["params"].update(kw)
    return build_model(Study.model_validate(doc))


@pytest.mark.parametrize("field, value", [
    ("harmonics", 0), ("harmonics", 1), ("harmonics", 200), ("harmonics", 201),
    ("contact_ratio", 1.0), ("contact_ratio", 1.001), ("contact_ratio", 1.999),
    ("contact_ratio", 2.0)])
def test_the_planetary_set_and_a_gear_train_check_the_waveform_inputs_alike(field, value):
    """The same value is accepted or refused (naming the field) by both models, and the
    refusal is the declared range: 1 < contact_ratio < 2, 1 <= harmonics <= 200."""
    inside = 1 <= value <= 200 if field == "harmonics" else 1.0 < value < 2.0
    for build in (_planetary, _train):
        if inside:
            assert isinstance(build(**{field: value}), geardyn.Model)
        else:
            with pytest.raises(ParameterError) as err:
                build(**{field: value})
            assert err.value.field.rpartition(".")[2] == field and err.value.value == value


OMEGAS = (5e-324, 1e-310, 1e-300, 0.0, -1.0, 1.0, 1e308, float("inf"), float("nan"))


@pytest.mark.parametrize("omega", OMEGAS)
def test_the_study_file_and_the_option_accept_the_same_omega(omega):
    """``[run].omega`` and ``--omega`` are one rule: the same value accepted or refused by both,
    the refusal naming where it came from; the rule is that the period 2 pi / Omega is a
    positive finite number (computed here, independently)."""
    from geardyn.core.settings import check_omega  # the rule every --omega option calls

    period = 2 * math.pi / omega if omega != 0 else math.inf
    usable = math.isfinite(omega) and math.isfinite(period) and period > 0
    doc = builtin_study("paper_fig3").to_toml_dict()
    doc["run"]["omega"] = omega
    try:
        Study.model_validate(doc)
        by_study = True
    except ValidationError as exc:
        assert exc.errors()[0]["loc"] == ("run", "omega")
        by_study = False
    try:
        check_omega(omega, "--omega")
        by_option = True
    except ParameterError as exc:
        assert exc.field == "--omega"
        by_option = False
    assert by_study == by_option == usable


def test_a_study_omega_without_a_period_is_refused_as_the_study_key(tmp_path):
    """The CLI names the study key, not ``--omega``, for a study's unusable ``[run].omega``."""
    import tomli_w
    from typer.testing import CliRunner

    from geardyn.cli.main import app

    doc = builtin_study("paper_fig3").to_toml_dict()
    doc["run"]["omega"] = 5e-324
    path = tmp_path / "tiny.toml"
    path.write_text(tomli_w.dumps(doc))
    result = CliRunner().invoke(app, ["simulate", str(path)])
    assert result.exit_code != 0
    assert "run.omega" in result.output and "--omega" not in result.output


#: Values of the gear pair's inputs on both sides of their ranges (Omega, zeta, backlash
#: >= 0; |kappa| < 1, which keeps the mesh stiffness 1 + kappa cos(...) positive).
GEAR_PAIR_VALUES = [("Omega", -1e-9, False), ("Omega", 0.0, True), ("zeta", -0.01, False),
                    ("zeta", 0.0, True), ("kappa", -1.0, False), ("kappa", -0.999, True),
                    ("kappa", 0.999, True), ("kappa", 1.0, False), ("backlash", -1e-12, False),
                    ("backlash", 0.0, True), ("Fm", float("inf"), False),
                    ("Fa", float("nan"), False), ("kappa_phase", -7.0, True)]


@pytest.mark.parametrize("name, value, valid", GEAR_PAIR_VALUES)
def test_the_gear_pairs_constructor_with_params_and_study_file_agree(name, value, valid):
    """The constructor, ``with_params`` and a ``gear_pair`` study's ``[params]`` accept or
    refuse the same value, each naming the input."""
    outcomes = []
    for enter in (lambda: geardyn.GearPair(**{name: value}),
                  lambda: geardyn.GearPair().with_params(**{name: value})):
        try:
            enter()
            outcomes.append(True)
        except ParameterError as exc:
            assert exc.field == name
            outcomes.append(False)
    if name != "Omega":  # a study's Omega is [run].omega (its own rule, above)
        doc = {"study": {"name": "gp", "model": "gear_pair"}, "params": {name: value}}
        try:
            Study.model_validate(doc)
            outcomes.append(True)
        except ValidationError as exc:
            assert exc.errors()[0]["loc"] == ("params", name)
            outcomes.append(False)
    assert outcomes == [valid] * len(outcomes)


@pytest.mark.parametrize("command, table, key", [
    (["bifurcation"], "run", "periods"), (["frc"], "run", "periods"),
    (["map", "--x", "Omega:1:1.5:2", "--y", "xi1:0.01:0.3:2"], "run", "periods"),
    (["basins", "--omega", "1.1", "--x", "X_sq:-1:1:2", "--y", "V_sq:-1:1:2"], "run",
     "periods")])
def test_too_few_samples_are_refused_naming_the_study_key_they_came_from(tmp_path, command,
                                                                         table, key):
    """RunSettings takes one sample; a command that classifies periods needs two, and its
    refusal names where the one came from (the study's key, not ``--samples``)."""
    import tomli_w
    from typer.testing import CliRunner

    from geardyn.cli.main import app

    doc = builtin_study("paper_fig3").to_toml_dict()
    doc["sweep"].pop("samples", None)
    doc.setdefault(table, {})[key] = 1
    path = tmp_path / "one_sample.toml"
    path.write_text(tomli_w.dumps(doc))
    result = CliRunner().invoke(app, [command[0], str(path), *command[1:], "--out",
                                      str(tmp_path / "x.nc")])
    assert result.exit_code != 0 and not (tmp_path / "x.nc").exists()
    assert f"{table}.{key}" in result.output and "--samples" not in result.output
    assert ">= 2" in result.output


#: ``geardyn reproduce``'s options and the ReproductionSettings fields they set, with values
#: the settings refuse (one rule for both).
REPRODUCE_REFUSED = [("--resolution", "num", 1), ("--samples", "samples", 0),
                     ("--transient", "transient", math.inf), ("--transient", "transient", -1.0)]


@pytest.mark.parametrize(("option", "field", "value"), REPRODUCE_REFUSED)
def test_reproduce_refuses_what_its_settings_refuse(tmp_path, option, field, value):
    from typer.testing import CliRunner

    from geardyn.cli.main import app
    from geardyn.reproduction import ReproductionSettings

    with pytest.raises(ValueError, match=rf"^{field} must be "):
        ReproductionSettings(**{field: value})
    result = CliRunner().invoke(app, ["reproduce", "fig3", option, str(value), "--no-figures",
                                      "--jobs", "1", "--out", str(tmp_path / "out")])
    assert result.exit_code != 0 and not (tmp_path / "out").exists()
    assert result.output.strip().count("\n") == 0  # one line
    assert option in result.output and repr(value) in result.output
    assert "Traceback" not in result.output and field + " must" not in result.output


def _omega_entry_points():
    """Each library entry point that takes a forcing frequency, as ``call(omega)``."""
    import numpy as np

    from geardyn.analysis.basins import basins
    from geardyn.analysis.frc import frequency_response
    from geardyn.analysis.lyapunov import lyapunov_lanes
    from geardyn.analysis.map2d import estimate_map
    from geardyn.analysis.orbits import shooting_problem
    from geardyn.analysis.runup import steady_record
    from geardyn.analysis.spectrum import amplitude_spectrum
    from geardyn.core.plan import LanePlan

    pair = geardyn.GearPair()

    def params(w):
        p = np.array(pair.params, dtype=float)
        p[pair.omega_index] = w
        return p

    problem = shooting_problem(pair, 1.0)
    return {
        "LanePlan.build": lambda w: LanePlan.build(pair, params(w)[None, :],
                                                   geardyn.RunSettings()),
        "basins": lambda w: basins(pair, w, None, None),
        "estimate_map": lambda w: estimate_map(pair, 1, [w], 10.0, 4),
        "ShootingProblem.with_params": lambda w: problem.with_params(params(w)),
        "lyapunov": lambda w: geardyn.lyapunov(pair.with_omega(w)),
        "simulate": lambda w: geardyn.simulate(pair, w),
        "lyapunov_lanes": lambda w: lyapunov_lanes(pair, params(w)[None, :]),
        "frequency_response": lambda w: frequency_response(pair, [w, 1.0]),
        "amplitude_spectrum": lambda w: amplitude_spectrum(np.ones(8), dt=0.1, omega=w),
        "steady_record": lambda w: steady_record(pair.with_omega(w), 4, 1.0),
    }


#: Entry points given a model made by ``with_omega`` (which refuses -1, nan and inf itself).
BUILT_BY_WITH_OMEGA = {"lyapunov", "steady_record"}
#: Entry points where Omega = 0 is the autonomous model, not a refusal.
AUTONOMOUS_AT_ZERO = {"lyapunov", "simulate"}


@pytest.mark.parametrize("omega", [0.0, -1.0, math.nan, math.inf, 5e-324])
@pytest.mark.parametrize("entry", sorted(_omega_entry_points()))
def test_every_entry_point_refuses_an_unusable_omega_by_one_rule(entry, omega):
    """Omega > 0 with a finite period 2 pi / Omega (5e-324 is positive but its period
    overflows), the rule of ``[run].omega`` and ``--omega``: the same ParameterError (a
    ValueError) naming Omega at every entry point."""
    from geardyn.core.settings import OMEGA_RULE

    if omega == 0.0 and entry in AUTONOMOUS_AT_ZERO:
        pytest.skip("Omega = 0 is the autonomous model here")
    with pytest.raises(ParameterError) as caught:
        _omega_entry_points()[entry](omega)
    exc = caught.value
    assert exc.field.lower() == "omega" and isinstance(exc, ValueError)
    assert not (0 < omega < math.inf and math.isfinite(2 * math.pi / omega))  # all unusable
    by_model = entry in BUILT_BY_WITH_OMEGA and not (omega > 0 and math.isfinite(omega))
    assert exc.reason == OMEGA_RULE or by_model, exc


@pytest.mark.parametrize("omega", [0.0, -1.0, 5e-324])
@pytest.mark.parametrize("where", ["continuation", "grazing"])
def test_continuation_leaves_its_domain_where_omega_breaks_the_one_rule(where, omega):
    """A branch or a grazing curve that moves Omega leaves its valid region at an Omega the
    rule refuses (5e-324 included: positive, but its period overflows), saying the rule."""
    from geardyn.analysis.arclength import OutsideDomain
    from geardyn.analysis.branch import _Invalid, _Tracer
    from geardyn.analysis.grazing import GrazingProblem
    from geardyn.analysis.orbits import shooting_problem
    from geardyn.core.settings import OMEGA_RULE

    pair = geardyn.GearPair()
    if where == "continuation":
        tracer = _Tracer(pair, "Omega", 1, 1.0, None, None, 1e-9, 12)
        with pytest.raises(_Invalid) as caught:
            tracer.params_at(omega)
    else:
        gp = GrazingProblem(pair, "Omega", "zeta", 0, shooting_problem(pair, 1.0), 1.0, 1.0)
        with pytest.raises(OutsideDomain) as caught:
            gp.params_at(omega, 0.05)
    assert OMEGA_RULE in str(caught.value)


@pytest.mark.parametrize("command", [
    ["map", "--x", "Omega:{w}:1.5:2", "--y", "xi1:0.01:0.3:2"],
    ["bifurcation", "--param", "Omega", "--range", "{w}:1.5:2"],
    ["frc", "--param", "Omega", "--range", "{w}:1.5:2"]])
@pytest.mark.parametrize("omega", [-1.0, 5e-324])
def test_every_command_refuses_an_omega_range_by_the_one_rule(tmp_path, command, omega):
    """An Omega axis or range with an unusable end: the one rule's words, naming the option."""
    from typer.testing import CliRunner

    from geardyn.cli.main import app
    from geardyn.core.settings import OMEGA_RULE

    path = tmp_path / "fig3.toml"
    import tomli_w

    path.write_text(tomli_w.dumps(builtin_study("paper_fig3").to_toml_dict()))
    args = [a.format(w=omega) for a in command]
    result = CliRunner().invoke(app, [args[0], str(path), *args[1:], "--out",
                                      str(tmp_path / "x.nc")])
    assert result.exit_code != 0 and not (tmp_path / "x.nc").exists()
    assert OMEGA_RULE in result.output and "Traceback" not in result.output
    assert ("--x" if command[0] == "map" else "--range") in result.output


@pytest.mark.parametrize("ends", [(-1.0, 1.0), (5e-324, 1.0)])
def test_the_explorer_refuses_an_omega_window_by_the_one_rule(ends):
    from geardyn.core.settings import OMEGA_RULE

    state = ExplorerState(builtin_study("paper_fig3"), "paper_fig3", describe_error=format_error)
    assert state.param == "Omega"
    before = state.window
    assert OMEGA_RULE in state.zoom(*ends) and state.window == before



class _Accepted(Exception):
    """Raised where a command goes on past its checks (nothing runs)."""


def _continuation_refusals(tmp_path):
    """Each entry point that takes a sweep's continuation, as ``call(value)``: None where it
    accepts the value, else its refusal as the one line the user sees."""
    import tomli_w
    from typer.testing import CliRunner

    from geardyn.cli.main import app

    path = tmp_path / "fig3.toml"
    path.write_text(tomli_w.dumps(builtin_study("paper_fig3").to_toml_dict()))

    def refusal(call):
        try:
            call()
        except ValueError as err:
            return format_error(err)
        return None

    def study_file(value):
        doc = builtin_study("paper_fig3").to_toml_dict()
        doc["sweep"]["continuation"] = value
        Study.model_validate(doc)

    def library(value):
        try:  # no values: refused after the continuation is taken (nothing runs)
            geardyn.bifurcation(geardyn.GearPair(), "Omega", [], continuation=value)
        except ParameterError:
            raise
        except ValueError:
            return

    def command(name):
        def call(value):
            with mock.patch(f"geardyn.cli.{name}.load_study_source", side_effect=_Accepted):
                result = CliRunner().invoke(app, [name, str(path), "--continuation", value])
            if isinstance(result.exception, _Accepted):
                return None
            assert result.exit_code == 2 and result.output.count("\n") == 1, result.output
            return result.output.strip()
        return call

    def explorer(value):
        state = ExplorerState(builtin_study("paper_fig3"), "paper_fig3",
                              describe_error=format_error)
        return state.set_continuation(value)

    return {"study file": lambda v: refusal(lambda: study_file(v)),
            "bifurcation()": lambda v: refusal(lambda: library(v)),
            "geardyn bifurcation": command("bifurcation"),
            "geardyn explore": command("explore"),
            "explorer": explorer}


@pytest.mark.parametrize("value", ["sideways", "Up", "", *CONTINUATIONS])
def test_every_entry_point_takes_a_continuation_by_one_vocabulary(tmp_path, value):
    """[sweep].continuation, bifurcation(), --continuation of both commands and the explorer:
    each listed value accepted everywhere, anything else refused everywhere in the same words
    (each naming its own field)."""
    from geardyn.core.settings import CONTINUATION_RULE, SWEEP_CONTINUATIONS

    refusals = {where: call(value) for where, call in _continuation_refusals(tmp_path).items()}
    if value in SWEEP_CONTINUATIONS:
        assert refusals == dict.fromkeys(refusals)
    else:
        said = {where: msg[msg.index(": must") + 2:] for where, msg in refusals.items()}
        assert said == dict.fromkeys(said, f"{CONTINUATION_RULE} (got {value!r})")


def test_the_continuation_options_list_the_vocabulary():
    from typer.testing import CliRunner

    from geardyn.cli.main import app
    from geardyn.core.settings import SWEEP_CONTINUATIONS

    for name in ("bifurcation", "explore"):
        result = CliRunner().invoke(app, [name, "--help"], env={"COLUMNS": "200"})
        assert "[" + "|".join(SWEEP_CONTINUATIONS) + "]" in result.output


def _refused(build) -> bool:
    """Whether ``build()`` refuses its input (a study's ValidationError or a ParameterError)."""
    try:
        build()
    except (ValidationError, ParameterError):
        return True
    return False


def _count_entry_points(field: str):
    """Each entry point that takes ``n_planets`` or a stiffness series' ``harmonics``, as
    ``build(value)``."""
    from geardyn.trains import Gear, Inertia, planetary_stage

    def study(name, **params):
        doc = builtin_study(name).to_toml_dict()
        if doc["params"].pop("geometry", None) is not None:  # a set of given stiffnesses
            doc["params"]["sun"]["radius"] = 0.03
            doc["params"].update(sun_mesh_stiffness=5e8, ring_mesh_stiffness=5e8)
        doc["params"].update(params)
        return lambda: build_model(Study.model_validate(doc))

    def catt(**changes):
        data = PlanetaryParams.paper().model_dump()
        for path, value in changes.items():
            *head, key = path.split(".")
            target = data
            for part in head:
                target = target[part]
            target[key] = value
        return lambda: PlanetaryParams.model_validate(data)

    if field == "n_planets":
        def stage(n):
            return lambda: planetary_stage(
                sun=Gear("sun", 1e-3, 1.0, 0.03, n_teeth=20),
                ring=Gear("ring", 1e-1, 5.0, 0.09, n_teeth=60),
                carrier=Inertia("carrier", 1e-2, 2.0), planet=Gear("p", 1e-4, 0.5, 0.03,
                                                                   n_teeth=20),
                n_planets=n, pin_stiffness=1e8, sun_mesh_stiffness=5e8,
                ring_mesh_stiffness=5e8, sun_pressure_angle=0.4, ring_pressure_angle=0.4)
        return {"PlanetaryGearSet": lambda n: lambda: _planetary_with(n_planets=n),
                "planetary study": lambda n: study("planetary_example", n_planets=n),
                "CATT study": lambda n: catt(n_planets=n),
                "planetary_stage": stage}
    rectangular = {"waveform": "rectangular"}
    return {"PlanetaryGearSet": lambda h: lambda: _planetary_with(harmonics=h, **rectangular),
            "planetary study": lambda h: study("planetary_example", harmonics=h, **rectangular),
            "train study": lambda h: study("two_stage_train", harmonics=h, **rectangular),
            "CATT study": lambda h: catt(**{"sun_mesh.waveform": "rectangular",
                                            "sun_mesh.harmonics": h})}


def _planetary_with(**kw) -> geardyn.Model:
    M = geardyn.Member
    return geardyn.PlanetaryGearSet(**{
        "n_planets": 3, "sun": M(0.4, 0.39, 1e8, 0.0, radius=0.03), "ring": M(2.35, 3.0, 1e8, 1e9),
        "carrier": M(5.43, 6.29, 1e8, 0.0), "planet": M(0.66, 0.61, 1e8),
        "sun_mesh_stiffness": 5e8, "ring_mesh_stiffness": 5e8, **kw})


@pytest.mark.parametrize("field, value", [
    ("n_planets", 0), ("n_planets", 1), ("n_planets", 32), ("n_planets", 33), ("n_planets", 64),
    ("n_planets", 65), ("harmonics", 0), ("harmonics", 1), ("harmonics", 200),
    ("harmonics", 201)])
def test_every_entry_point_takes_a_count_within_one_declared_limit(field, value):
    """n_planets and a stiffness series' harmonics have one declared range each (the counts
    N_PLANETS and HARMONICS): every constructor and study table accepts or refuses alike."""
    from geardyn.models.planetary_coefficients import HARMONICS, N_PLANETS

    declared = {"n_planets": N_PLANETS, "harmonics": HARMONICS}[field]
    inside = declared.minimum <= value <= declared.maximum
    refused = {where: _refused(make(value)) for where, make in _count_entry_points(field).items()}
    assert refused == dict.fromkeys(refused, not inside)
    assert (declared.minimum, declared.maximum) == {"n_planets": (1, 32),
                                                    "harmonics": (1, 200)}[field]
