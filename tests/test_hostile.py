"""Hostile input (property-based, hypothesis): malformed parameter sets and study files thrown at
the loader and at the command line.

The property: every input either works, or fails with an expected error whose one-line message
names the offending field, option or value. For the API that is a ``GeardynError``, a pydantic
``ValidationError`` or a ``ValueError`` (never another type); for the command line, exit status
2, exactly one line ``error: ...`` on stderr and no traceback. Runs that would succeed are kept
tiny (two points, a transient of one, two samples, 16 steps per period); grids and runs whose
cost is excessive must be refused by the estimate, in well under a second.

About 1,200 generated inputs in all (see ``EXAMPLES``), derandomized so that a run is
reproducible.
"""

from __future__ import annotations

import datetime
import itertools
import math
import subprocess
import sys
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import tomli_w
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from pydantic import ValidationError
from typer.testing import CliRunner

from geardyn.cli.errors import format_error
from geardyn.cli.main import app
from geardyn.errors import GeardynError
from geardyn.io.toml import (
    builtin_study_text,
    load_params,
    load_study,
    paper_study,
)
from geardyn.models.params import PAPER_NAMES, PlanetaryParams
from geardyn.study import build_model

#: Generated inputs per property; the total is above 1000.
EXAMPLES = {
    "paper_changes": 250,
    "full_params": 200,
    "study_documents": 200,
    "magnitudes": 150,
    "garbage_text": 80,
    "cli_params_show": 80,
    "cli_simulate": 110,
    "cli_bifurcation": 110,
    "cli_map": 50,
    "cli_study_argument": 40,
}

API_ERRORS = (ValidationError, GeardynError, ValueError)


def hostile(name: str):
    return settings(max_examples=EXAMPLES[name], deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.filter_too_much])


# --------------------------------------------------------------------------- values
EXTREME_FLOATS = [0.0, -0.0, 1e308, -1e308, 1e-308, -1e-308, 5e-324, math.nan, math.inf,
                  -math.inf, -1.0, -1e-9, 1.0]
UNIT_STRINGS = [
    "50 um", "0.05 mm", "0.825e9 N/m", "20 deg", "1500 N m", "7.13e-4 kg*m**2", "3 mm",  # valid
    "50 kg", "1e9 N", "3 furlongs per gram", "20 s", "5 N m", "1 m/s",  # wrong dimension
    "-5 um", "0 N/m", "-1e308 N m",  # negative / zero
    "1e999 m", "nan m", "inf N/m", "-inf deg", "1e-400 mm",  # not finite / underflow
    "", "   ", "m", "um", "(1 m", "1 m;2", "1 meter + 1 s", "1 degC", "1j m", "5 %",
    "10**10**10 um", "2**2**2**2**2 m", "((10**99)**99)**99 m", "9" * 200 + " m",
    "__import__('os') m", "1 m\x00", "1,5 mm", "five mm", "[1 m]",
]
#: Keys no table knows; distinctive, so that an error message naming them can be recognised.
UNKNOWN_KEYS = st.from_regex(r"zz_[a-z]{1,6}", fullmatch=True)

scalars = st.one_of(
    st.sampled_from(EXTREME_FLOATS),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(2**63), max_value=2**63 - 1),
    st.sampled_from([0, -1, 1, 3, 64, 65, 2**63 - 1]),
    st.booleans(),
    st.sampled_from(UNIT_STRINGS),
    st.text(max_size=12),
    st.datetimes(min_value=datetime.datetime(1, 1, 1)),
)
#: Values many fields accept, so that a fair share of the inputs is valid.
plausible = st.one_of(
    st.floats(min_value=1e-3, max_value=10.0),
    st.integers(min_value=1, max_value=8),
    st.sampled_from(UNIT_STRINGS[:7]),
)
#: Extreme magnitudes, both signs: 10**-308 .. 10**308, the extremes themselves, and zero.
magnitudes = st.one_of(
    st.builds(lambda m, e, sign: sign * m * 10.0**e, st.floats(1.0, 9.99),
              st.integers(-308, 307), st.sampled_from([1.0, 1.0, -1.0])),
    st.sampled_from([1e308, 1e-308, 5e-324, 0.0, -1e308, 1.7976931348623157e308]),
)
#: Anything TOML can hold: scalars, arrays, tables.
toml_values = st.one_of(
    plausible,
    scalars,
    st.lists(scalars, max_size=3),
    st.dictionaries(UNKNOWN_KEYS, scalars, max_size=2),
)
#: What a Python caller can pass besides: None, bytes, complex, huge integers, objects.
python_values = st.one_of(
    toml_values,
    st.none(),
    st.binary(max_size=8),
    st.complex_numbers(max_magnitude=1e3),
    st.integers(min_value=2**63, max_value=10**400),
    st.builds(object),
)


# --------------------------------------------------------------------------- helpers
def names_one_of(message: str, names: set[str]) -> bool:
    """True when ``message`` names at least one of ``names`` (fields, options, values)."""
    return any(n and n in message for n in names)


def api_outcome(call, names: set[str]):
    """Run ``call``; an error must be an expected type with a one-line message naming one of
    ``names``. Returns the result, or None after an expected error."""
    try:
        result = call()
    except API_ERRORS as exc:
        event(f"error {type(exc).__name__}")
        message = format_error(exc)
        assert message and "\n" not in message, message
        assert names_one_of(message, names), (message, names)
        return None
    event("ok")
    return result


def leaves(doc: Any, prefix: tuple = ()) -> list[tuple]:
    """Every path of a nested dict/list document (tables, arrays and values)."""
    out = [prefix] if prefix else []
    if isinstance(doc, dict):
        for k, v in doc.items():
            out += leaves(v, (*prefix, k))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            out += leaves(v, (*prefix, i))
    return out


def mutate(data, doc: dict, n_max: int, values=toml_values,
           ops=("delete", "replace", "replace", "unknown", "magnitude")) -> tuple[dict, set[str]]:
    """Apply 1..n_max hostile mutations to a copy of ``doc``: delete an entry, replace it with a
    hostile value, add an unknown key to a table, or give a number an extreme magnitude.
    Returns the document and the names (keys on the mutated paths, unknown keys) an error
    message may name."""
    doc = _copy(doc)
    names: set[str] = set()
    for _ in range(data.draw(st.integers(1, n_max), label="mutations")):
        op = data.draw(st.sampled_from(ops), label="op")
        paths = leaves(doc)
        if op == "magnitude":
            paths = [p for p in paths if _is_number(_get(doc, p))]
        if not paths:
            op, paths = "unknown", []
        path = data.draw(st.sampled_from(paths), label="path") if paths else ()
        names |= {str(k) for k in path if isinstance(k, str)}
        parent = _get(doc, path[:-1]) if path else doc
        if op == "unknown":
            table = _get(doc, path) if path and isinstance(_get(doc, path), dict) else parent
            if not isinstance(table, dict):
                table = doc
            key = data.draw(UNKNOWN_KEYS, label="unknown key")
            table[key] = data.draw(toml_values, label="value")
            names.add(key)
        elif op == "delete":
            del parent[path[-1]]
        elif op == "magnitude":
            parent[path[-1]] = data.draw(magnitudes, label="magnitude")
        else:
            parent[path[-1]] = data.draw(values, label="value")
    return doc, names


def _is_number(value) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _copy(doc):
    if isinstance(doc, dict):
        return {k: _copy(v) for k, v in doc.items()}
    if isinstance(doc, list):
        return [_copy(v) for v in doc]
    return doc


def _get(doc, path):
    for k in path:
        doc = doc[k]
    return doc


def study_bases() -> dict[str, dict]:
    """Valid study documents of each form: full parameters, the paper's plus changes, a built-in
    study with a sweep, a gear pair."""
    return {
        "full": paper_study().to_toml_dict(),
        "paper_changes": {"study": {"name": "s"}, "params": {"base": "paper", "changes": {
            "xi": 0.05, "backlash": "50 um", "B1": "100 N m", "Lambda": 2.0}},
            "run": {"omega": 1.1, "transient": 1.0, "periods": 2}},
        "builtin": tomllib.loads(builtin_study_text("paper_fig3")),
        "gear_pair": {"study": {"model": "gear_pair"}, "params": {"zeta": 0.05, "kappa": 0.2},
                      "run": {"omega": 1.2}},
        "bare_params": paper_study().to_toml_dict()["params"],
    }


BASES = study_bases()


# --------------------------------------------------------------------------- API
@hostile("paper_changes")
@given(changes=st.dictionaries(
    st.integers(0, 4).flatmap(lambda i: UNKNOWN_KEYS if i == 0 else st.sampled_from(
        sorted(PAPER_NAMES) * 3 + sorted(PlanetaryParams.model_fields))),
    st.one_of(plausible, python_values), min_size=1, max_size=3))
def test_paper_changes_either_apply_or_name_the_parameter(changes):
    names = set(changes)
    for key in changes:
        for path in PAPER_NAMES.get(key, ()):
            names |= set(path)
    p = api_outcome(lambda: PlanetaryParams.paper(**changes), names)
    if p is not None:
        assert isinstance(p, PlanetaryParams)


@hostile("full_params")
@given(data=st.data())
def test_planetary_params_either_validate_or_name_the_field(data):
    doc, names = mutate(data, PlanetaryParams.paper().model_dump(), 3, values=python_values)
    p = api_outcome(lambda: PlanetaryParams(**doc), names)
    if p is not None:
        assert isinstance(p, PlanetaryParams)


@hostile("study_documents")
@given(data=st.data(), base=st.sampled_from(sorted(BASES)))
def test_study_documents_either_load_or_name_the_field(data, base):
    doc, names = mutate(data, BASES[base], 3)
    names |= {"params", "empty"}  # an overflowing model names [params]; {} is "empty"
    text = tomli_w.dumps(doc)
    study = api_outcome(lambda: load_study(text), names)
    if study is not None:
        model = api_outcome(lambda: build_model(study), names)
        assert model is None or model.n_states >= 2
    params = api_outcome(lambda: load_params(text), names | {"gear_pair"})
    assert params is None or isinstance(params, PlanetaryParams)


@hostile("magnitudes")
@given(data=st.data(), base=st.sampled_from(["full", "paper_changes", "gear_pair"]))
def test_extreme_magnitudes_give_a_model_or_name_the_field(data, base):
    """Numbers of any magnitude in a valid study: a model with finite coefficients, natural
    frequencies and initial state, or an error naming the field (or [params] as a whole, when
    values that are each valid overflow together)."""
    doc, names = mutate(data, BASES[base], 3, ops=("magnitude",))
    study = api_outcome(lambda: load_study(tomli_w.dumps(doc)), names)
    if study is None:
        return
    model = api_outcome(lambda: build_model(study), names | {"params"})
    if model is not None:
        assert np.all(np.isfinite(model.params)) and np.all(np.isfinite(model.initial_state()))


@hostile("garbage_text")
@given(raw=st.one_of(
    st.binary(max_size=64),
    st.text(max_size=64),
    st.sampled_from([b"", b"\xff\xfe\x00", b"[params\n", b"[[params]]\nx=1\n", b"params = 3\n",
                     b"[params]\nbase='paper'\n[params]\n", b"\x00" * 8, b"= = =",
                     b'[study]\nname="a"\n', b"[foo]\nbar=1\n", b"x = 1e999\n"]),
))
def test_garbage_files_are_refused_naming_the_file_or_key(raw, tmp_path_factory):
    path = tmp_path_factory.mktemp("garbage") / "study.toml"
    path.write_bytes(raw.encode("utf-8", "surrogatepass") if isinstance(raw, str) else raw)
    try:
        names = {str(path), *map(str, tomllib.loads(path.read_text("utf-8")))}
    except (UnicodeDecodeError, tomllib.TOMLDecodeError):
        names = {str(path)}
    names |= {"params", "sun"}  # what a parameter document without them lacks
    api_outcome(lambda: load_study(path), names)
    api_outcome(lambda: load_params(path), names)


def test_known_api_defects_stay_fixed():
    """The defects the properties found, one example each."""
    with pytest.raises(ValueError, match="xi3"):  # was a KeyError
        PlanetaryParams.paper(xi3=0.1)
    with pytest.raises(KeyError):  # still a KeyError for `except KeyError` callers
        PlanetaryParams.paper(xi3=0.1)
    for text in ("10**10**10 um", "2**2**2**2**2 m"):  # exhausted memory / OverflowError
        with pytest.raises(ValidationError, match="backlash"):
            PlanetaryParams.paper(backlash=text)
    with pytest.raises(ValidationError, match="n_planets"):  # true was read as 1 planet
        PlanetaryParams.paper(N=True)
    with pytest.raises(ValidationError, match="backlash"):  # OverflowError
        PlanetaryParams.paper(backlash=10**400)
    with pytest.raises(API_ERRORS, match="unknown key"):  # was "params.sun: Field required"
        load_study("[parms]\nbase = 'paper'\n")
    with pytest.raises(API_ERRORS, match="must be a table"):  # was a union member's name
        load_study("params = 3\n")
    with pytest.raises(API_ERRORS, match="zz"):  # load_params ignored the other tables
        load_params("zz = 1\n[params]\nbase = 'paper'\n")
    with pytest.raises(API_ERRORS, match="params"):  # OverflowError from math
        build_model(load_study("[params]\nbase='paper'\n[params.changes]\nbacklash=1e308\n"))


# --------------------------------------------------------------------------- command line
RUNNER = CliRunner()
_counter = itertools.count()


@pytest.fixture(scope="module")
def workdir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("hostile")


def invoke(args: list[str]) -> tuple[int, str, str]:
    result = RUNNER.invoke(app, args)
    if result.exception is not None and not isinstance(result.exception, SystemExit):
        raise result.exception  # a traceback: the property fails with it
    return result.exit_code, result.stdout, result.stderr


def assert_runs_or_one_line_error(args: list[str], names: set[str]) -> int:
    code, _, err = invoke(args)
    event(f"exit {code}")
    if code == 0:
        return code
    assert code == 2, (args, code, err)
    assert "Traceback" not in err, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), (args, err)
    assert names_one_of(lines[0], names), (args, lines[0], names)
    return code


def study_file(workdir: Path, doc: dict | bytes) -> Path:
    path = workdir / f"study{next(_counter)}.toml"
    path.write_bytes(doc if isinstance(doc, bytes) else tomli_w.dumps(doc).encode())
    return path


#: Hostile values of each kind of option: each is invalid or blatantly too costly, never a
#: valid run that is merely long.
FLOAT_OPTION = ["nan", "inf", "-inf", "-1", "0", "1e308", "-1e308", "1e400", "abc", "", "1,5",
                "0x10", "1e12"]
COUNT_OPTION = ["-1", "0", "1", "3.5", "abc", "", "1e9", str(10**12), str(10**30), str(2**63),
                str(10**400)]
OMEGA_OPTION = ["nan", "inf", "-1", "0", "1e308", "1e12", "5e-324", "abc", ""]
RANGES = ["0.1:4:1e9", "0.1:4:1000000000", "0.1:4:" + str(10**30), "1:1:2", "nan:1:2",
          "1:inf:2", "-1:2:2", "0:1:2", "1:2", "1:2:3:4", "a:b:c", "", ":::", "1:2:1", "1:2:-5",
          "1:2:2.5", "1e308:-1e308:2"]
AXES = [("Omega:0.1:4:100000", "xi:0.01:0.3:100000"), ("Omega:1:2", "xi:0.01:0.3:2"),
        ("zz:1:2:2", "xi:0.01:0.3:2"), ("Omega:1:1.5:2", "xi:1:2:0"),
        ("Omega:-1:2:2", "xi:0.01:0.3:2"), ("Omega:1:1.5:2", "xi:nan:1:2"),
        ("Omega:1:1.5:2", "backlash:0:1e308:2"), ("Omega:1:1.5:2", "Omega:1:2:2"),
        ("Omega:1:1.5:" + str(10**20), "xi:0.01:0.3:" + str(10**20)),
        ("Omega:1:1.5:2", "xi:-1:0.3:2"), ("Omega:1:1.5:2", "N:1:3:2")]


def hostile_options(data, base: list[tuple[str, str]], kinds: dict[str, list[str]],
                    extra: list[list[str]]) -> tuple[list[str], set[str]]:
    """``base`` options with 0..2 of them given hostile values (and maybe an extra hostile
    argument); returns the argument list and the names an error may give."""
    options = dict(base)
    names: set[str] = set()
    for _ in range(data.draw(st.integers(0, 2 if kinds else 0), label="hostile options")):
        option = data.draw(st.sampled_from(sorted(kinds)), label="option")
        value = data.draw(st.sampled_from(kinds[option]), label="option value")
        options[option] = value
        names |= {option, option.lstrip("-")}
        if len(value) >= 3:
            names.add(value)
    args = [a for kv in options.items() for a in kv]
    if data.draw(st.booleans(), label="extra argument"):
        more = data.draw(st.sampled_from(extra), label="extra")
        args += more
        names |= {m for m in more if len(m) >= 3} | {m.lstrip("-") for m in more}
    return args, names


def hostile_study(data, workdir: Path, bases: list[str]) -> tuple[str, set[str]]:
    """A study argument: a valid study, or one with 1..2 hostile changes."""
    base = data.draw(st.sampled_from(bases), label="base")
    if data.draw(st.booleans(), label="mutate study"):
        doc, names = mutate(data, BASES[base], 2)
        names.add("params")
    else:
        doc, names = _copy(BASES[base]), set()
    path = study_file(workdir, doc)
    return str(path), names | {str(path)}


COMMON_EXTRA = [["--bogus"], ["--interpretation", "bogus"], ["extra-argument"],
                ["--interpretation", "as-printed"]]


@hostile("cli_params_show")
@given(data=st.data())
def test_cli_params_show(data, workdir):
    study, names = hostile_study(data, workdir, ["full", "paper_changes", "builtin", "gear_pair"])
    args, more = hostile_options(data, [], {}, COMMON_EXTRA)
    assert_runs_or_one_line_error(["params", "show", study, *args], names | more)


@hostile("cli_simulate")
@given(data=st.data())
def test_cli_simulate(data, workdir):
    study, names = hostile_study(data, workdir, ["full", "paper_changes", "builtin", "gear_pair"])
    base = [("--omega", "1.1"), ("--transient", "1"), ("--periods", "2"),
            ("--steps-per-period", "16")]
    kinds = {"--omega": OMEGA_OPTION, "--transient": FLOAT_OPTION, "--periods": COUNT_OPTION,
             "--steps-per-period": COUNT_OPTION}
    extra = [*COMMON_EXTRA, ["--plot", str(workdir / "x.gif")], ["--state", "zz", "--plot",
             str(workdir / "x.png")], ["--out", str(workdir / "file.nc" / "x.nc")]]
    args, more = hostile_options(data, base, kinds, extra)
    assert_runs_or_one_line_error(["simulate", study, *args], names | more)


@hostile("cli_bifurcation")
@given(data=st.data())
def test_cli_bifurcation(data, workdir):
    study, names = hostile_study(data, workdir, ["full", "paper_changes", "builtin", "gear_pair"])
    base = [("--range", "1:1.5:2"), ("--transient", "1"), ("--samples", "2"),
            ("--steps-per-period", "16"), ("--omega", "1.1"), ("--quiet", "--quiet")]
    kinds = {"--range": RANGES, "--transient": FLOAT_OPTION, "--samples": COUNT_OPTION,
             "--steps-per-period": COUNT_OPTION, "--omega": OMEGA_OPTION,
             "--param": ["Omega", "xi", "backlash", "N", "zz", "", "Km_sq", "waveform", "zeta"]}
    extra = [*COMMON_EXTRA, ["--continuation", "sideways"], ["--continuation", "up"],
             ["--state", "zz"], ["--state", "[/bold]"], ["--out", str(workdir / "x.txt")],
             ["--plot", str(workdir / "x.gif")], ["--converge", "nan"], ["--converge", "2"]]
    args, more = hostile_options(data, base, kinds, extra)
    args = [a for a in args if a != "--quiet"] + ["--quiet"]
    assert_runs_or_one_line_error(["bifurcation", study, *args], names | more)


@hostile("cli_map")
@given(data=st.data())
def test_cli_map(data, workdir):
    study, names = hostile_study(data, workdir, ["full", "paper_changes", "builtin"])
    axes = data.draw(st.sampled_from([("Omega:1:1.5:2", "xi:0.01:0.3:2")] * 3 + AXES),
                     label="axes")
    base = [("--x", axes[0]), ("--y", axes[1]), ("--transient", "1"), ("--samples", "2"),
            ("--steps-per-period", "16"), ("--out", str(workdir / "map.nc"))]
    kinds = {"--transient": FLOAT_OPTION, "--samples": COUNT_OPTION,
             "--steps-per-period": COUNT_OPTION, "--chunk": COUNT_OPTION,
             "--out": [str(workdir / "map.txt"), str(workdir / "map.nc" / "x" / "m.zip")]}
    args, more = hostile_options(data, base, kinds, COMMON_EXTRA + [["--plot", "m.gif"]])
    names |= {"--x", "--y", *axes} | more
    assert_runs_or_one_line_error(["map", study, *args], names)


@hostile("cli_study_argument")
@given(data=st.data(), raw=st.one_of(st.binary(max_size=48), st.sampled_from([
    b"", b"\xff\xfe", b"[params\n", b"[foo]\nx=1\n", b"params=3\n", b"[study]\nname=1\n"])))
def test_cli_study_argument(data, raw, workdir):
    kind = data.draw(st.sampled_from(["garbage", "missing", "directory", "name"]), label="kind")
    if kind == "garbage":
        study = str(study_file(workdir, raw))
    elif kind == "missing":
        study = str(workdir / "no" / "such.toml")
    elif kind == "directory":
        study = str(workdir)
    else:
        study = data.draw(st.sampled_from(["no_such_study", "", "paper_fig3", "PAPER_FIG3",
                                           "paper fig3", "a\x00b"]), label="name")
    command = data.draw(st.sampled_from([
        ["params", "show"], ["simulate"], ["bifurcation"], ["map"]]), label="command")
    tail = {"params": [], "simulate": ["--omega", "1.1", "--transient", "1", "--periods", "2"],
            "bifurcation": ["--range", "1:1.5:2", "--transient", "1", "--samples", "2", "-q"],
            "map": ["--x", "Omega:1:1.5:2", "--y", "xi:0.01:0.3:2", "--transient", "1",
                    "--samples", "2", "--out", str(workdir / "m.nc")]}[command[0]]
    try:
        keys = set(map(str, tomllib.loads(raw.decode("utf-8"))))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError):
        keys = set()
    names = {study, repr(study), "STUDY", "params", "sun", *keys} - {""}
    assert_runs_or_one_line_error([*command, study, *tail, "--steps-per-period", "16"]
                                  if command[0] != "params" else [*command, study], names)


def test_excessive_grids_are_refused_with_an_estimate(workdir, monkeypatch):
    """Huge sweeps and maps are refused before anything of their size is allocated, quoting the
    estimated memory or time; ``--yes`` is what overrides it. The time is estimated at a fixed
    speed (``GEARDYN_NS_PER_LANE_STEP``), not at this machine's measured one."""
    monkeypatch.setenv("GEARDYN_NS_PER_LANE_STEP", "300")
    cases = [
        (["bifurcation", "paper_fig3", "--range", "0.1:4:1000000000", "-q"], "sweep too large"),
        (["bifurcation", "paper_fig3", "--range", "0.1:4:1000", "--samples", str(10**9), "-q"],
         "sweep too large"),
        (["bifurcation", "paper_fig3", "--range", "0.1:4:1000", "--transient", "1e9", "-q"],
         "sweep too long"),
        (["map", "paper_fig3", "--x", "Omega:0.1:4:100000", "--y", "xi:0.01:0.3:100000",
          "--out", str(workdir / "m.nc")], "map too large"),
        (["simulate", "paper_fig3", "--omega", "1", "--periods", str(10**9)],
         "simulation too large"),
    ]
    for args, fragment in cases:
        code, _, err = invoke(args)
        assert code == 2 and err.count("\n") == 1, (args, err)
        assert fragment in err and "memory" in err and "pass --yes" in err, err
        assert "lane-steps" in err  # the estimate is quoted


@pytest.mark.parametrize("limit,fragment", [("TIME_LIMIT_S", "too long"),
                                             ("MEMORY_FRACTION", "too large")])
def test_limits_refuse_and_yes_overrides(monkeypatch, limit, fragment):
    """With the limit set to zero, a tiny sweep and a tiny simulation are refused quoting the
    estimate; ``--yes`` runs them."""
    import geardyn.cli.common as common

    monkeypatch.setattr(common, limit, 0.0)
    sweep = ["bifurcation", "paper_fig3", "--range", "1:1.5:2", "--transient", "1",
             "--samples", "2", "-q"]
    single = ["simulate", "paper_fig3", "--omega", "1.1", "--transient", "1", "--periods", "2"]
    for args, what in ((sweep, "sweep"), (single, "simulation")):
        code, _, err = invoke(args)
        assert code == 2 and f"{what} {fragment}" in err and "lane-steps" in err, err
        code, out, err = invoke([*args, "--yes"])
        assert code == 0, err
        assert "Omega" in out


def test_console_script_exit_status_and_no_traceback(workdir):
    """Real runs of the installed console script: status 2, one line, no traceback; a study
    that does not load and an option refused, each in a process of its own (every process
    imports geardyn, ~5 s CPU); the other calls, whose code past the entry point is the same,
    through the same command in this process."""
    exe = Path(sys.executable).with_name("geardyn")
    if not exe.exists():
        pytest.skip("the geardyn console script is not installed next to this interpreter")
    garbage = study_file(workdir, b"\xff\xfe\x00garbage\x80")
    calls = [
        (["params", "show", str(garbage)], str(garbage)),
        (["bifurcation", "paper_fig3", "--range", "0.1:4:1000000000", "-q"], "--range"),
        (["simulate", "paper_fig3", "--omega", "nan"], "--omega"),
        (["map", "paper_fig3", "--x", "Omega:0.1:4:100000", "--y", "xi:0.01:0.3:100000",
          "--out", str(workdir / "m.nc")], "--x/--y"),
    ]
    procs = [(subprocess.Popen([str(exe), *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True), fragment) for args, fragment in calls[:2]]
    results = []
    for proc, _ in procs:
        _, err = proc.communicate(timeout=300)
        results.append((proc.returncode, err))
    for args, _ in calls[2:]:
        code, _, err = invoke(args)
        results.append((code, err))
    for (code, err), (args, fragment) in zip(results, calls, strict=True):
        assert code == 2, (args, err)
        assert "Traceback" not in err
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: ") and fragment in lines[0], err
