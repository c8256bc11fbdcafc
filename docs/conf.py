"""Sphinx configuration of the geardyn documentation site (``make docs``).

Why Sphinx: it is the tool of the scientific Python stack whose docs geardyn's users read
(NumPy, SciPy, xarray, scikit-learn). autodoc + numpydoc render the package's numpydoc
docstrings ("Parameters / ----------") as they are written; myst-parser reads the design notes
in docs/*.md unchanged, so they stay plain Markdown on GitHub and pages of the site; and
sphinx-gallery runs the scripts in examples/ at every build and shows their figures, so the
worked examples cannot drift from the code (the gallery tool of scikit-learn, SciPy's and
xarray's tutorials). MkDocs + mkdocstrings would read the notes as well, but has no maintained
equivalent of sphinx-gallery's executed, figure-capturing examples.

The build is offline (no intersphinx inventories are fetched) and strict: ``make docs`` runs
``sphinx-build -W --keep-going`` with ``nitpicky = True``, so a broken cross-reference, a
docstring that does not parse or an example that raises fails the build.
"""

from __future__ import annotations

import os
import sys
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT / "docs" / "_ext"))
os.environ.setdefault("MPLBACKEND", "Agg")

import geardyn  # noqa: E402

project = "geardyn"
author = "the geardyn authors"
copyright = "geardyn authors"  # noqa: A001
version = release = geardyn.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "api/generated/*.md", "figures/*.sh", "Thumbs.db", ".DS_Store"]
templates_path = ["_templates"]

# Single backticks in docstrings mean code (as in the Markdown notes), not a cross-reference.
default_role = "literal"

# --- strict cross-references -------------------------------------------------------------------
nitpicky = True
# The build is offline: names of other libraries (numpy, xarray, typing, ...) in signatures have
# no inventory to resolve against. geardyn's own names must resolve.
nitpick_ignore_regex = [
    (r"py:.*", r"(numpy|np|xarray|xr|typing|collections|pathlib|dask|distributed|pydantic"
               r"|pydantic_core|numba|matplotlib|zarr|pint|datetime|enum|dataclasses|types"
               r"|os|io|abc|typing_extensions|scipy)(\..*)?"),
    (r"py:.*", r"(int|float|str|bool|complex|bytes|object|dict|list|tuple|set|frozenset|type"
               r"|None|Any|Callable|Sequence|Mapping|Iterable|Iterator|Literal|Path|ndarray"
               r"|NDArray|ArrayLike|Self|Enum|IntEnum|BaseModel|Dataset|DataArray|Figure|Axes"
               r"|Client|Future|optional|array_like|array-like|callable|default|ValueError"
               r"|TypeError|Exception|AssertionError|RuntimeError|KeyError)"),
    ("py:class", r"dict\[str"),  # a wrapped annotation of a return tuple, split by autodoc
]



def _internal_reference(app, env, node, contnode):
    """A reference to a geardyn name that exists but has no page of its own (an internal module,
    a module constant such as ``CONVERGE``): rendered as code. A name that does not import is
    left unresolved, so nitpicky mode fails the build on it (a renamed or removed target)."""
    from docutils import nodes

    if node.get("refdomain") != "py":
        return None
    target = node["reftarget"].lstrip("~.")
    if target.startswith("geardyn."):
        found = _imports(target)
    else:  # a short name: a member of the class being documented, or a module constant
        found = _class_member(node, target) or any(
            name.startswith("geardyn") and hasattr(mod, target)
            for name, mod in list(sys.modules.items()))
    return nodes.literal(target, node.astext() or target) if found else None


def _class_member(node, target: str) -> bool:
    """Whether ``target`` is an attribute or an annotated field of the class in whose
    docstring the reference stands."""
    import importlib

    module, klass = node.get("py:module"), node.get("py:class")
    if not (module and klass):
        return False
    obj = importlib.import_module(module)
    for part in klass.split("."):
        obj = getattr(obj, part, None)
    return obj is not None and (hasattr(obj, target) or any(
        target in vars(c).get("__annotations__", {}) for c in getattr(obj, "__mro__", ())))


def _imports(dotted: str) -> bool:
    """Whether ``dotted`` names an importable module or an attribute reached from one."""
    import importlib

    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for attr in parts[cut:]:
            if not hasattr(obj, attr):
                return False
            obj = getattr(obj, attr)
        return True
    return False


def _pydantic_signature(app, what, name, obj, options, signature, return_annotation):
    """A parameter class (pydantic model) shows its fields and defaults, not the validators
    wrapped into their annotations."""
    import inspect

    from pydantic import BaseModel

    if what != "class" or not (inspect.isclass(obj) and issubclass(obj, BaseModel)):
        return None
    parts = []
    for field, info in obj.model_fields.items():
        if info.is_required():
            parts.append(field)
        elif info.default_factory is not None:
            parts.append(f"{field}=...")
        else:
            parts.append(f"{field}={info.default!r}")
    return "(*, " + ", ".join(parts) + ")", None


def setup(app):
    app.connect("missing-reference", _internal_reference, priority=900)
    app.connect("autodoc-process-signature", _pydantic_signature)


# --- autodoc / numpydoc ------------------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"members": True, "member-order": "bysource", "inherited-members": False,
                           "exclude-members": "model_config, model_fields, model_computed_fields"}
autodoc_typehints = "signature"
autodoc_class_signature = "mixed"
autodoc_preserve_defaults = True
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()
# numpydoc drops a section it does not know (with only a UserWarning): make that fail the build.
warnings.filterwarnings("error", message="Unknown section", category=UserWarning)

# --- MyST (the notes in docs/*.md) -------------------------------------------------------------
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# --- sphinx-gallery (examples/*.py, executed at build) -----------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "ignore_pattern": r"(__init__|_model)\.py",  # helper modules of the examples
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": False,
    "only_warn_on_example_error": False,
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib", "figure_scraper.scrape"),
    "capture_repr": (),
    "reset_modules": ("matplotlib",),
    "show_memory": False,
    "plot_gallery": "True",
}

# --- HTML --------------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"geardyn {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "header_links_before_dropdown": 7,
}
html_static_path: list[str] = []
html_show_sourcelink = False
