"""The vector width of geardyn's compiled kernels: numba's CPU target, set up at import.

LLVM tunes code for most Intel server CPUs with AVX-512 (Skylake-SP to Emerald Rapids) to
prefer 256-bit vectors (``prefer-256-bit``, against the clock drop of 512-bit code on the
first of them), while for AMD Zen 4 it prefers 512 bits. geardyn's fused step loops are
vector code over lanes and gain from the wider registers (the figures are in
``bench/RESULTS.md``). The kernels are compiled without fastmath, every lane's
arithmetic is elementwise, so results are bitwise the same at any width
(``tests/test_jit_target.py``).

``GEARDYN_SIMD_WIDTH`` (environment) chooses:

``512`` (default)
    512-bit vectors where the CPU has them: LLVM's ``prefer-256-bit`` tuning turned off.
``256``
    256-bit vectors at most (``prefer-256-bit`` on), on any CPU.
``native``
    LLVM's own choice for this CPU (numba's default).

numba reads its CPU features when its CPU target is first set up (at the first ``njit``
function defined), so this module runs before geardyn defines any kernel, and it changes
nothing where that has happened already (numba was used before geardyn was imported), or where
the user set ``NUMBA_CPU_NAME`` or ``NUMBA_CPU_FEATURES`` (numba's own settings win).
:data:`APPLIED` says what was done. numba's kernel cache is keyed by the features, so kernels
compiled at one width are never loaded at another.

This is the one process-wide setting ``import geardyn`` makes (``numba.config.CPU_FEATURES``,
except with ``native``): numba has one CPU target per process, whose LLVM target machine is
created once, with these features, when the first function is compiled; a width for geardyn's
kernels alone would need a numba target of geardyn's own, for every kernel and model function.
numba functions of other code compiled in the same process get the same tuning (their results
are bitwise the same at any width, as above, unless compiled with fastmath).
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Mapping

#: The environment variable that chooses the vector width.
ENV = "GEARDYN_SIMD_WIDTH"
#: Its values (see above) and the tuning each appends to the host's CPU features.
MODES: dict[str, str | None] = {"512": "-prefer-256-bit", "256": "+prefer-256-bit",
                                "native": None}
DEFAULT = "512"


def mode_from_env(environ: Mapping[str, str]) -> str:
    """The vector-width mode ``environ`` asks for (``ENV``, default ``DEFAULT``); a clear
    error naming the variable for any other value."""
    value = environ.get(ENV, DEFAULT).strip().lower() or DEFAULT
    if value not in MODES:
        raise ValueError(f"{ENV}={environ.get(ENV)!r}: must be one of "
                         f"{', '.join(MODES)} (unset: {DEFAULT})")
    return value


def features_for(host_features: str, mode: str) -> str | None:
    """numba's CPU feature string for ``mode``: the host's features with the mode's tuning
    appended, or None (leave numba's default) for ``native``."""
    tuning = MODES[mode]
    return None if tuning is None else f"{host_features},{tuning}"


def _configure() -> str:
    """Set numba's CPU features for the requested width; returns what was done (see
    :data:`APPLIED`)."""
    mode = mode_from_env(os.environ)
    if mode == "native":
        return "native: LLVM's default vector width for this CPU"
    if os.environ.get("NUMBA_CPU_NAME") or os.environ.get("NUMBA_CPU_FEATURES"):
        return "numba: NUMBA_CPU_NAME / NUMBA_CPU_FEATURES are set and take precedence"
    import llvmlite.binding as ll
    from numba.core import config, registry

    if "_toplevel_target_context" in vars(registry.cpu_target):
        if ENV in os.environ:
            warnings.warn(f"{ENV}={os.environ[ENV]} not applied: numba's CPU target was set "
                          "up before geardyn was imported (import geardyn first)",
                          RuntimeWarning, stacklevel=3)
        return "too late: numba's CPU target was set up before geardyn was imported"
    config.CPU_FEATURES = features_for(ll.get_host_cpu_features().flatten(), mode)
    return f"{mode}: {MODES[mode]} appended to the host's CPU features"


#: What :func:`_configure` did at import (the mode and how it was applied, or why not).
APPLIED: str = _configure()
