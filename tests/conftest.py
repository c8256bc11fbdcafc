"""Fixtures of every test."""

from __future__ import annotations

import pytest

from geardyn.core.moved import forget_deprecations


@pytest.fixture(autouse=True)
def _fresh_deprecations():
    """Each deprecated keyword warns once per process: every test starts as a fresh process
    would, so that a test asserting the warning does not depend on which ran before it."""
    forget_deprecations()
    yield


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    """With ``GEARDYN_COMPILE_REPORT`` set: the kernels each test compiles
    (tests/compile_report.py)."""
    from compile_report import CompileRecorder, directory, write

    folder = directory()
    if folder is None:
        yield
        return
    with CompileRecorder() as rec:
        yield
    record = rec.record()
    if record["functions"]:
        write(folder, item.nodeid, record)
