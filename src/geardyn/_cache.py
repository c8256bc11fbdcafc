"""geardyn's one on-disk cache, the same for every entry point (``geardyn``, ``make``, the Python
API, the tests), set up at import.

``$GEARDYN_CACHE_DIR`` (default ``$XDG_CACHE_HOME/geardyn``, i.e. ``~/.cache/geardyn``) holds
the generated kernel modules (``kernels/``) and numba's compiled code (``numba/``: numba's
``NUMBA_CACHE_DIR``, which geardyn sets to this folder when the user has not set it). Explicitly
set variables win: ``NUMBA_CACHE_DIR`` keeps numba's code wherever it names.

This module runs before any numba function of geardyn is defined: numba picks the cache folder
of a function when it is decorated, so ``NUMBA_CACHE_DIR`` is set (and numba's configuration
reloaded, where numba was imported already) before that. It is set in ``os.environ``, so
subprocesses (test workers, Dask workers started from here) use the same folder.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping
from pathlib import Path

#: The environment variable that names geardyn's cache folder.
ENV = "GEARDYN_CACHE_DIR"
#: numba's own variable for its cache folder (numba reads it).
NUMBA_ENV = "NUMBA_CACHE_DIR"


def cache_root(environ: Mapping[str, str] | None = None) -> Path:
    """geardyn's cache folder: ``$GEARDYN_CACHE_DIR``, else ``$XDG_CACHE_HOME/geardyn``, else
    ``~/.cache/geardyn``."""
    env = os.environ if environ is None else environ
    root = env.get(ENV)
    if not root:
        base = env.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache")
        root = os.path.join(base, "geardyn")
    return Path(root)


def numba_cache_dir(environ: Mapping[str, str] | None = None) -> Path:
    """Where numba keeps compiled code: ``$NUMBA_CACHE_DIR`` where set, else
    ``cache_root()/numba``."""
    env = os.environ if environ is None else environ
    return Path(env.get(NUMBA_ENV) or cache_root(env) / "numba")


def _configure() -> str:
    """Point numba's cache at :func:`numba_cache_dir` unless the user set ``NUMBA_CACHE_DIR``;
    returns what was done (see :data:`APPLIED`)."""
    if os.environ.get(NUMBA_ENV):
        return f"{NUMBA_ENV} is set: numba's cache stays at {os.environ[NUMBA_ENV]}"
    os.environ[NUMBA_ENV] = str(numba_cache_dir())
    if "numba.core.config" in sys.modules:  # numba read its environment already: again
        sys.modules["numba.core.config"].reload_config()
    return f"{NUMBA_ENV} set to {os.environ[NUMBA_ENV]}"


#: What :func:`_configure` did at import.
APPLIED: str = _configure()
