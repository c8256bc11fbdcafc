"""The helper process :func:`geardyn.solvers.compile_share.compile_ahead` starts
(``python -m geardyn.solvers.compile_helper MODULE PATH name=signature ...``)."""

from __future__ import annotations

import importlib.util
import sys
from collections.abc import Sequence

from geardyn.solvers.compile_share import signature_types
from geardyn.solvers.kernels import _quiet_module


def compile_in_helper(module_name: str, path: str, specs: Sequence[str]) -> None:
    """Import the generated module from ``path``
    and compile each ``name=signature`` of ``specs`` under its lock."""
    spec = importlib.util.spec_from_file_location(module_name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module
    spec.loader.exec_module(module)
    _quiet_module(module)
    for item in specs:
        name, _, text = item.partition("=")
        getattr(module, name).compile(signature_types(text))


if __name__ == "__main__":
    compile_in_helper(sys.argv[1], sys.argv[2], sys.argv[3:])
