"""The split step (a grid step with located edge crossings) of a model with lane-scalar
functions evaluates them, with the state and the stages in registers (``_split_rhs``,
``_rk4_stages``, ``_hermite`` in :mod:`geardyn.solvers._step_core`); its results are bitwise
those of the split on the model's array functions. The reference here is the same reduced CATT
device through the general model's array functions (``catt_kernels.catt_rhs``, one planet set
in the coefficient vector), which have no lane forms, so its kernel takes the generic path
(structure-of-arrays blocks, the array forms of the split's helpers): the general model's own
kernel functions, so that its kernels are those the general model and
tests/test_catt_one_form.py compile."""

from __future__ import annotations

import copy

import numpy as np

import geardyn
from geardyn.core.kernel_source import KernelSource
from geardyn.models import catt_kernels as ck
from geardyn.solvers.ensemble import run_lanes
from geardyn.solvers.kernels import kernels_for


def test_the_split_in_the_lane_form_equals_the_array_form_bitwise():
    model = geardyn.CATTDevice(geardyn.PlanetaryParams.paper(xi1=0.05, xi2=0.05))
    generic = copy.copy(model)
    generic.kernel = KernelSource(ck.catt_rhs, ck.catt_events, ck.catt_observe)
    assert kernels_for(model.kernel).FUSED
    assert not kernels_for(generic.kernel).FUSED
    omegas = np.array([0.6, 1.1, 1.7, 2.3, 2.9, 3.5])  # contact lost in most of them
    P = model.lane_params("Omega", omegas)
    kw = {"run": geardyn.RunSettings(transient=60.0, samples=8, locate_edges=True)}
    fused = run_lanes(model, P, model.initial_state(), **kw)
    plain = run_lanes(generic, P, model.initial_state(), **kw)
    assert np.all(fused.status == 0)
    assert np.sum(fused.crossings) > 50  # the split ran, many times
    np.testing.assert_array_equal(fused.samples, plain.samples)
    np.testing.assert_array_equal(fused.final, plain.final)
    np.testing.assert_array_equal(fused.crossings, plain.crossings)
