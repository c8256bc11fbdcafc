"""Which path a model's sweeps run on is visible: ``KernelSource.kernel_path`` (what the
generated core module decides), a dataset's ``kernel_path`` attribute, and a SlowPathWarning,
once per model class, where a plain model runs one lane at a time."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import geardyn
from geardyn.core.kernel_source import KERNEL_PATHS
from geardyn.core.plan import LanePlan
from geardyn.errors import GeardynWarning, SlowPathWarning
from geardyn.solvers.kernels import kernels_for
from shared_models import OSCILLATOR, oscillator_rhs


def _plain(kind: type = geardyn.UserModel) -> geardyn.UserModel:
    return kind(oscillator_rhs, n_states=2, params=list(OSCILLATOR.values()),
                param_names=tuple(OSCILLATOR), name="plain oscillator")


def _models():
    from geardyn.io.toml import builtin_study

    return {"plain UserModel": _plain(), "GearPair (one form)": geardyn.GearPair(),
            "PlanetaryGearSet (lane blocks)": geardyn.build_model(
                builtin_study("planetary_example"))}


@pytest.mark.parametrize("name", sorted(_models()))
def test_the_kernel_path_is_the_one_the_generated_kernels_take(name):
    """kernel_path against the generated modules themselves: the fused lane-form loop where
    the core sets FUSED, the lane-block functions where the sweep module has ``rhs_lanes``."""
    model = _models()[name]
    core, sweep = kernels_for(model.kernel, "core"), kernels_for(model.kernel)
    taken = ("lane-form" if core.FUSED else
             "lane-block" if "rhs_lanes" in vars(sweep) else "per-lane")
    assert model.kernel.kernel_path == taken
    assert taken == {"plain UserModel": "per-lane", "GearPair (one form)": "lane-form",
                     "PlanetaryGearSet (lane blocks)": "lane-block"}[name]


def test_a_plain_model_says_once_per_class_that_it_runs_per_lane():
    class Plain(geardyn.UserModel):  # a class of its own: no earlier test has warned for it
        pass

    model = _plain(Plain)
    P = np.tile(model.params, (2, 1))
    with pytest.warns(SlowPathWarning, match=r"one lane at a time.*from_one_form") as caught:
        LanePlan.build(model, P, geardyn.RunSettings())
    assert len(caught) == 1 and issubclass(SlowPathWarning, GeardynWarning)
    with warnings.catch_warnings():
        warnings.simplefilter("error", GeardynWarning)
        LanePlan.build(_plain(Plain), P, geardyn.RunSettings())  # the same class: silent
        LanePlan.build(geardyn.GearPair(), np.tile(geardyn.GearPair().params, (2, 1)),
                       geardyn.RunSettings())  # the fast path: silent


def test_a_sweep_records_its_kernel_path():
    with pytest.warns(SlowPathWarning) if _first_plain_sweep() else warnings.catch_warnings():
        ds = geardyn.bifurcation(_plain(), "Omega", [0.9, 1.1],
                                 geardyn.RunSettings(transient=20.0, samples=2))
    assert ds.attrs["kernel_path"] == "per-lane" in KERNEL_PATHS


def _first_plain_sweep() -> bool:
    from geardyn.core import kernel_source

    return geardyn.UserModel not in kernel_source._SLOW_WARNED
