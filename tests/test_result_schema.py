"""One schema per result kind (:data:`geardyn.core.results.SCHEMAS`): the dataset builders fill
it and check against it, and :func:`geardyn.testing.assert_result` reads the same registry."""

from __future__ import annotations

import dataclasses

import pytest

import geardyn
from geardyn.core import results
from geardyn.testing import KINDS, assert_result


def _simulation():
    g = geardyn.GearPair(zeta=0.05, kappa=0.0, Fm=0.1, Fa=0.0)
    return geardyn.simulate(g, omega=1.2, run=geardyn.RunSettings(transient=10.0, samples=4))


def _require(monkeypatch, kind: str, name: str, dims: tuple[str, ...]) -> None:
    """Register one more required variable of ``kind`` (for this test only)."""
    sc = results.SCHEMAS[kind]
    more = dataclasses.replace(sc, variables={**sc.variables, name: dims})
    monkeypatch.setitem(results.SCHEMAS, kind, more)


def test_assert_result_knows_every_registered_kind():
    assert tuple(KINDS) == tuple(results.SCHEMAS)
    with pytest.raises(AssertionError, match="unknown result kind 'sweep'"):
        assert_result(_simulation(), "sweep")


def test_a_result_without_a_registered_variable_fails():
    ds = _simulation()
    assert_result(ds, "simulation")
    with pytest.raises(AssertionError, match="variable 'poincare_time' missing"):
        assert_result(ds.drop_vars("poincare_time"), "simulation")


def test_assert_result_reads_the_registry(monkeypatch):
    """A variable added to the registry is required by assert_result at once."""
    ds = _simulation()
    _require(monkeypatch, "simulation", "energy", ("time",))
    with pytest.raises(AssertionError, match="variable 'energy' missing"):
        assert_result(ds, "simulation")


def test_a_builder_that_omits_a_registered_variable_fails(monkeypatch):
    """The builder checks its dataset against the same registry: one that does not fill a
    registered variable fails where it builds, naming the variable."""
    _require(monkeypatch, "simulation", "energy", ("time",))
    with pytest.raises(results.ResultSchemaError, match="variable 'energy' missing"):
        _simulation()


def test_placeholders_follow_the_dataset():
    """Names in braces take the dataset's own attributes (the swept parameter, the states)."""
    ds = _simulation()
    _, coords, variables = results.SCHEMAS["simulation"].resolve(ds)
    assert all(variables[str(s)] == ("time",) for s in ds["state"].values)
    sc = results.SCHEMAS["bifurcation"]
    ds2 = ds.copy()
    ds2.attrs["param"] = "Fm"
    _, coords, variables = sc.resolve(ds2)
    assert coords["Fm"] == ("Fm",) and variables["period"] == ("Fm",)
