"""Fixtures of every test."""

from __future__ import annotations

import pytest

from geardyn.core.settings import forget_deprecations


@pytest.fixture(autouse=True)
def _fresh_deprecations():
    """Each deprecated keyword warns once per process: every test starts as a fresh process
    would, so that a test asserting the warning does not depend on which ran before it."""
    forget_deprecations()
    yield
