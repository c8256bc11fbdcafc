"""geardyn's one on-disk cache, the same for every entry point (``geardyn``, ``make``, the Python
API, the tests), set up at import.

``$GEARDYN_CACHE_DIR`` (default ``$XDG_CACHE_HOME/geardyn``, i.e. ``~/.cache/geardyn``) holds
the generated kernel modules (``kernels/``), numba's compiled code of geardyn's functions
(``numba/``) and the digests of geardyn's source files (``stamps/``, below). Explicitly set
variables win: ``NUMBA_CACHE_DIR`` keeps numba's code wherever it names.

geardyn changes no numba setting and no environment variable for this: it registers a cache
locator (:class:`GeardynCacheLocator`, first in numba's list of locators) that answers only for
geardyn's own functions (files in the geardyn package and the generated kernels); every other
function keeps numba's own locators. Where ``NUMBA_CACHE_DIR`` is set, it keeps geardyn's code
there, in numba's own layout (the generated kernels' in one folder, below). The names of the
cache files carry the vector width the code was compiled at
(:func:`geardyn._jit_target.cache_tag`), so that each width has its own entries.
numba picks the locator of a function when it is decorated, so this module runs before geardyn
defines any numba function. Subprocesses that import geardyn (test workers, Dask workers)
register it too. Where ``NUMBA_CACHE_LOCATOR_CLASSES`` is set, numba uses only the classes it
names (numba's setting wins).

numba checks a cached function against its own file only, while its compiled code also holds
what it took from other modules: functions it inlined or called (:mod:`geardyn.models.elements`'
dead zone), and module constants frozen in at compile time (coefficient offsets from
:mod:`geardyn.models.derived`). For geardyn's functions the stamp numba keeps with their code
(:func:`source_stamp`) is therefore a hash of the file and of every geardyn module it imports,
transitively: an edit to any of them recompiles the function rather than loading stale code.
Each file's digest and imports are kept in ``stamps/`` for the file's state (times, size,
inode; as Python keeps a module's bytecode for its source's), so that a process (each test
worker, each ``geardyn`` command) reads them instead of parsing every module at import.

A cache folder can be copied or moved (into a Docker image, a CI cache, another machine's home,
a Dask worker's folder; ``cp -r`` or ``cp -a``, file times kept or not) and is reused there: the
generated kernel modules' compiled code is kept in one folder below numba's cache folder,
``numba/kernels`` (:data:`KERNELS_SUBPATH`), whatever the cache's path (a kernel module's name
is a hash of its code), and their stamp names each file relative to the folder that moves with
it (:func:`stamp_name`: the kernel module relative to ``kernels/``, the package's files relative
to the package), and hashes its code, not its times. The memos of ``stamps/`` are kept by a
file's path and state: in a copy those of the kernel modules (new paths, new states) are not
found, and each is parsed once again. The package's own functions are kept by the path of their
folder, as numba keeps them, so that two checkouts of geardyn sharing one cache each keep their
own entries (where their code differs, one entry per function would be compiled again at each
switch). What recompiles, in a copy as in the original: another geardyn or numba version, an
edited model or geardyn module (the kernel's name or its stamp), another CPU or vector width
(numba's index and :func:`geardyn._jit_target.cache_tag`), and the package's own functions where
the package is at another path, where they are called (the kernels hold their code and still
load: a simulation on a copied cache with the package copied elsewhere compiled nothing). Where
``NUMBA_CACHE_DIR`` is set, the kernels' code is in its ``kernels`` folder: every geardyn cache
that uses that numba folder shares it (safe: the names are hashes of the code), and it stays
valid where only ``$GEARDYN_CACHE_DIR`` is moved; copy both folders to take it along.
"""

from __future__ import annotations

import ast
import contextlib
import functools
import hashlib
import os
from collections.abc import Mapping
from pathlib import Path

from numba.core import caching, config

from geardyn import _jit_target

#: The environment variable that names geardyn's cache folder.
ENV = "GEARDYN_CACHE_DIR"
#: numba's own variable for its cache folder (numba reads it).
NUMBA_ENV = "NUMBA_CACHE_DIR"
#: The geardyn package's folder: numba functions defined in files below it are geardyn's.
PACKAGE_DIR = Path(__file__).resolve().parent


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
    """Where numba keeps geardyn's compiled code: ``$NUMBA_CACHE_DIR`` where set, else
    ``cache_root()/numba``."""
    env = os.environ if environ is None else environ
    return Path(env.get(NUMBA_ENV) or cache_root(env) / "numba")


def kernels_dir() -> Path:
    """The folder of the generated kernel modules, absolute: ``cache_root()/kernels``."""
    return Path(os.path.abspath(cache_root() / "kernels"))


def is_geardyn_file(py_file: str | os.PathLike[str]) -> bool:
    """Whether ``py_file`` is geardyn's: in the geardyn package or a generated kernel module
    (:func:`kernels_dir`)."""
    path = Path(os.path.abspath(py_file))
    return any(path.is_relative_to(folder) for folder in (PACKAGE_DIR, kernels_dir()))


def is_kernel_file(py_file: str | os.PathLike[str]) -> bool:
    """Whether ``py_file`` is a generated kernel module (in :func:`kernels_dir`)."""
    return Path(os.path.abspath(py_file)).is_relative_to(kernels_dir())


@functools.cache
def stamp_name(path: Path, kernels: Path, package: Path) -> str:
    """The name :func:`source_stamp` gives the absolute file ``path``: relative to the folder
    that moves with it, so that the stamp does not change where the folder is copied or moved:
    ``kernels/<file>`` for a generated kernel module (relative to ``kernels``, the
    :func:`kernels_dir`), ``geardyn/<file>`` for a file of the package (relative to
    ``package``, the :data:`PACKAGE_DIR`); any other file by its absolute path. Kept per
    argument: every cached function's stamp names the same files."""
    for prefix, folder in (("kernels", kernels), ("geardyn", package)):
        if path.is_relative_to(folder):
            return f"{prefix}/{path.relative_to(folder).as_posix()}"
    return path.as_posix()


def _module_file(name: str) -> Path | None:
    """The source file of geardyn's module ``name`` (None: not a module of the package)."""
    parts = name.split(".")
    if parts[0] != "geardyn":
        return None
    base = PACKAGE_DIR.joinpath(*parts[1:])
    for path in (base.with_suffix(".py"), base / "__init__.py"):
        if path.is_file():
            return path
    return None


def _parse_imports(tree: ast.Module, path: Path) -> frozenset[Path]:
    """The files of the geardyn modules that the module ``tree`` (the file ``path``) imports at
    its top level."""
    package = "geardyn" + "".join("." + p for p in path.relative_to(PACKAGE_DIR).parent.parts) \
        if path.is_relative_to(PACKAGE_DIR) else ""
    found: set[Path] = set()
    for node in tree.body:
        names: list[str] = []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            module = node.module or ""
            if node.level:
                parent = package.rsplit(".", node.level - 1)[0] if node.level > 1 else package
                module = f"{parent}.{module}" if module else parent
            names = [module, *(f"{module}.{a.name}" for a in node.names)]
        # the package itself is no dependency (its __init__ imports every layer)
        found.update(f for f in map(_module_file, names)
                     if f is not None and f != PACKAGE_DIR / "__init__.py")
    return frozenset(found)


def _parse_digest(tree: ast.Module) -> bytes:
    """A hash of the module ``tree``'s code: its syntax tree without docstrings and positions
    (comments, docstrings and layout change nothing)."""
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if (isinstance(body, list) and body and isinstance(body[0], ast.Expr)
                and isinstance(body[0].value, ast.Constant)
                and isinstance(body[0].value.value, str)):
            body[0] = ast.Pass()
    return hashlib.sha256(ast.dump(tree, include_attributes=False).encode()).digest()


@functools.cache
def _memo_key() -> bytes:
    """What a memo of :func:`_facts` holds for besides its file's state: this module's code
    (which defines the digest) and the package folder (which resolves the imports)."""
    return hashlib.sha256(Path(__file__).read_bytes() + str(PACKAGE_DIR).encode()).digest()


def _memo_path(path: Path) -> Path:
    """The memo of ``path``'s :func:`_facts` in the cache (one file per source file)."""
    return cache_root() / "stamps" / hashlib.sha256(str(path).encode()).hexdigest()[:32]


def _state(st: os.stat_result) -> tuple[int, int, int, int]:
    """A file's state for :func:`_facts`: modified and changed time (ns), size, inode (a write,
    or a file put in its place, even with its modified time kept, is a new state)."""
    return st.st_mtime_ns, st.st_ctime_ns, st.st_size, st.st_ino


@functools.cache
def _facts(path: Path, state: tuple[int, int, int, int]) -> tuple[bytes, frozenset[Path]]:
    """``path``'s code digest (:func:`_parse_digest`) and the files of the geardyn modules it
    imports at its top level, for the file's :func:`_state` ``state`` (an edited file is
    parsed again). Parsing and hashing the modules of every cached function costs ~0.3 s CPU
    per process (at ``import geardyn``), so the result is also kept in the cache
    (:func:`_memo_path`) for that state of the file and the same :func:`_memo_key`, as Python
    keeps a module's bytecode for the state of its source: other processes read it."""
    head = _memo_key() + f"{path}\0{state}\0".encode()
    memo = _memo_path(path)
    try:
        data = memo.read_bytes()
    except OSError:
        data = b""
    if data.startswith(head) and len(data) >= len(head) + 32:
        found = data[len(head) + 32:].decode()
        return data[len(head):len(head) + 32], frozenset(map(Path, filter(None, found.split("\0"))))
    tree = ast.parse(path.read_bytes())
    imports = _parse_imports(tree, path)
    digest = _parse_digest(tree)
    tmp = memo.with_name(f"{memo.name}.{os.getpid()}.tmp")
    try:  # an optimisation: where the cache cannot be written, each process parses
        memo.parent.mkdir(parents=True, exist_ok=True)
        tmp.write_bytes(head + digest + "\0".join(map(str, sorted(imports))).encode())
        os.replace(tmp, memo)
    except OSError:
        with contextlib.suppress(OSError):
            tmp.unlink()
    return digest, imports


def dependency_files(py_file: str | os.PathLike[str]) -> tuple[Path, ...]:
    """``py_file`` and the files of every geardyn module it imports, transitively (top-level
    ``import``/``from ... import`` statements), sorted."""
    seen: set[Path] = set()
    todo = [Path(os.path.abspath(py_file))]
    while todo:
        path = todo.pop()
        if path in seen:
            continue
        seen.add(path)
        st = os.stat(path)
        todo.extend(_facts(path, _state(st))[1])
    return tuple(sorted(seen))


def source_stamp(py_file: str | os.PathLike[str]) -> bytes:
    """numba's stamp of a cached function of ``py_file``: the code of ``py_file`` and of its
    :func:`dependency_files` (:func:`_facts`), each named by :func:`stamp_name`, so its cached
    code is loaded only while none of them changed but in comments and docstrings, and is
    loaded where the cache folder (or the package) was copied or moved with the same code. The
    files are taken in the order of their names (their absolute paths' order changes where the
    cache moves to the other side of the package)."""
    h = hashlib.sha256()
    kernels = kernels_dir()
    named = sorted((stamp_name(path, kernels, PACKAGE_DIR), path)
                   for path in dependency_files(py_file))
    for name, path in named:
        h.update(name.encode() + b"\0")
        h.update(_facts(path, _state(os.stat(path)))[0])
    return h.digest()


#: The folder (below numba's cache folder) of the generated kernel modules' compiled code.
KERNELS_SUBPATH = "kernels"


class GeardynCacheLocator(caching.UserProvidedCacheLocator):
    """numba's cache locator for geardyn's functions: the layout of numba's own
    ``NUMBA_CACHE_DIR`` locator, rooted at numba's ``NUMBA_CACHE_DIR`` where set, else at
    :func:`numba_cache_dir`; the vector width in the file names. The package's functions are
    kept by their folder's path, as numba keeps them (two checkouts of geardyn sharing one
    cache each keep their own entries); the generated kernel modules' in one folder,
    :data:`KERNELS_SUBPATH`, whatever the path of the cache (their names are hashes of their
    code). It declines (numba's other locators decide) for any other file."""

    def __init__(self, py_func, py_file):  # noqa: ANN001 (numba's signature)
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno
        self._cache_path = os.path.join(config.CACHE_DIR or str(numba_cache_dir()),
                                        self.get_suitable_cache_subpath(py_file))

    @classmethod
    def get_suitable_cache_subpath(cls, py_file: str) -> str:
        """:data:`KERNELS_SUBPATH` for a generated kernel module, else numba's (the name and a
        hash of the path of the file's folder)."""
        if is_kernel_file(py_file):
            return KERNELS_SUBPATH
        return super().get_suitable_cache_subpath(py_file)

    def get_source_stamp(self) -> bytes:
        """:func:`source_stamp` of the function's file (numba's own: of the file alone)."""
        return source_stamp(self._py_file)

    def get_disambiguator(self) -> str:
        """The function's first line and the vector width (``12-simd512``)."""
        return f"{self._lineno}-{_jit_target.cache_tag()}"

    @classmethod
    def from_function(cls, py_func, py_file):  # noqa: ANN001, ANN206 (numba's signature)
        if not is_geardyn_file(py_file):
            return None
        return super(caching.UserProvidedCacheLocator, cls).from_function(py_func, py_file)


def _register() -> str:
    """Put :class:`GeardynCacheLocator` first in numba's locators (once); returns what was
    done (see :data:`APPLIED`)."""
    locators = caching.CacheImpl._locator_classes
    if GeardynCacheLocator not in locators:
        locators.insert(0, GeardynCacheLocator)
    if config.CACHE_DIR:
        return f"{NUMBA_ENV} is set: numba's cache stays at {config.CACHE_DIR}"
    return f"geardyn's functions cached in {numba_cache_dir()}"


#: What :func:`_register` did at import.
APPLIED: str = _register()
