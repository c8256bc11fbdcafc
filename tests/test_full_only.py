"""numba's cheap module pipeline skipped in geardyn's compiles only
(:func:`geardyn._jit_target._full_only`): a function compiled with geardyn's pipeline runs the
full pipeline alone, a plain numba function in the same process runs both, and both give the
result numpy computes."""

from __future__ import annotations

import numba
import numpy as np
from numba.core import codegen

from geardyn._jit_target import WidthCompiler


def _costs(monkeypatch) -> list:
    """The ``cost`` of every module pipeline numba builds from here on while it finalises a
    code library of ``_body`` (numba's own helpers, such as ``np.sin``'s, have theirs)."""
    seen: list = []
    finalising: list = []
    build = codegen.CPUCodegen._module_pass_manager
    finalize = codegen.CPUCodeLibrary.finalize

    def recording(self, **kwargs):
        if finalising and finalising[-1] == "_body":
            seen.append(kwargs.get("cost"))
        return build(self, **kwargs)

    def tracking(self):
        finalising.append(self.name)
        try:
            return finalize(self)
        finally:
            finalising.pop()

    monkeypatch.setattr(codegen.CPUCodegen, "_module_pass_manager", recording)
    monkeypatch.setattr(codegen.CPUCodeLibrary, "finalize", tracking)
    return seen


def _body(a, b):
    out = np.empty_like(a)
    for i in range(a.size):
        out[i] = np.sin(a[i]) * b[i] + 0.5 * a[i]
    return out


def test_cheap_pipeline_skipped_for_geardyn_only(monkeypatch):
    a = np.linspace(-2.0, 3.0, 37)
    b = np.linspace(1.0, 0.1, 37)
    expected = np.sin(a) * b + 0.5 * a

    seen = _costs(monkeypatch)
    ours = numba.njit(pipeline_class=WidthCompiler)(_body)
    np.testing.assert_array_equal(ours(a, b), expected)
    assert seen == [None]  # the full pipeline alone

    seen.clear()
    plain = numba.njit(_body)
    np.testing.assert_array_equal(plain(a, b), expected)
    assert seen == ["cheap", None]  # numba's own order, outside geardyn's pipeline
