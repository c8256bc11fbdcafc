"""Every deprecated use warns once per process, from one registry
(:func:`geardyn.core.moved.warn_once`) that :func:`~geardyn.core.moved.forget_deprecations`
clears: deprecated keywords, attributes and sweeps of the models, and names at their old home."""

from __future__ import annotations

import importlib
import warnings

import geardyn
from geardyn.core.moved import forget_deprecations

#: An old home (a name moved from it answers with a DeprecationWarning).
OLD = "geardyn.models.base"


def _deprecations(calls) -> list[str]:
    """The DeprecationWarning messages of ``calls`` (each made in turn; every warning shown,
    whatever Python's own once-per-place filter would hide)."""
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        for call in calls:
            call()
    return [str(w.message) for w in record if issubclass(w.category, DeprecationWarning)]


def _params() -> geardyn.PlanetaryParams:
    return geardyn.PlanetaryParams.paper(xi1=0.1, xi2=0.1)


def test_the_catt_devices_deprecations_warn_once_each():
    device = geardyn.CATTDevice(_params())
    got = _deprecations([
        lambda: geardyn.CATTDevice(_params(), one_form=True),
        lambda: geardyn.CATTDevice(_params(), one_form=False),
        lambda: device.one_form,
        lambda: device.one_form,
        lambda: device.lane_params("N", [3.0, 4.0]),
        lambda: device.lane_params("N", [3.0, 5.0]),
    ])
    assert [m.split(" ")[0] for m in got] == ["CATTDevice(one_form=...)", "CATTDevice.one_form",
                                              "sweeping"]


def test_a_moved_name_warns_once_and_again_after_forget_deprecations():
    base = importlib.import_module(OLD)
    got = _deprecations([lambda: base.Model, lambda: base.Model])
    assert got == [f"{OLD}.Model is deprecated: import it from geardyn.core.model"]
    forget_deprecations()  # as tests/conftest.py does before each test: a fresh process
    assert _deprecations([lambda: base.Model]) == got
    assert base.Model is geardyn.Model


def test_one_registry_for_keywords_names_and_models():
    """A deprecated keyword, a moved name and a model's deprecated keyword, forgotten together."""
    base = importlib.import_module(OLD)
    g = geardyn.GearPair(zeta=0.05, kappa=0.0, Fm=0.1, Fa=0.05)
    calls = [lambda: geardyn.simulate(g, 0.8, periods=2, steps_per_period=64),
             lambda: base.Model, lambda: geardyn.CATTDevice(_params(), one_form=True)]
    first = _deprecations(calls)
    assert len(first) == 3
    assert _deprecations(calls) == []
    forget_deprecations()
    assert _deprecations(calls) == first
