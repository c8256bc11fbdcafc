"""Shared test setup: keep compiled numba kernels in a repository-local cache by default."""

import os
from pathlib import Path

_CACHE = Path(__file__).resolve().parents[1] / ".geardyn-cache"
os.environ.setdefault("GEARDYN_CACHE_DIR", str(_CACHE))
os.environ.setdefault("NUMBA_CACHE_DIR", str(_CACHE / "numba"))
