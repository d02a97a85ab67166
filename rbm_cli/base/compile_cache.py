"""numba's on-disk cache of rbm's compiled functions, keyed on every compiled source.

numba keeps a compiled function (``@njit(cache=True)``) in an index file checked against
a stamp of the one source file the function is written in (its modification time and
size). The compiled code of a function holds its callees and the values of the globals
it reads, frozen at compile time; a change to a callee or a constant in another module
goes unseen (numba's documentation says so, and numba's issue tracker). After a change to
``step/rk.py`` the cached ``run_kernel`` of ``step/stepper.py`` still ran the old code.

Here every cached function of the package gets the stamp ``(numba's stamp, "rbm sources
sha256:<digest>")``, where the digest covers the contents of

- every module of the package that defines compiled functions (a decorator ``@njit`` or
  ``@jit``, found by a look at each ``*.py`` file, so a new kernel module is covered
  without a list of names), and
- the package's modules whose names the compiled functions read (``from rbm_cli.x
  import NAME`` with NAME used inside a compiled function): their constants are frozen
  into the compiled code. One level: a constant computed there from a third module's is
  not followed.

A change to any of them makes every cached function stale at once: the next use compiles
again and rewrites the same index files (no cache folder per digest, nothing grows).
numba's own checks stay (its version, the file's stamp). The stamp is set by a cache
locator placed first in numba's list (:func:`key_numba_cache`); it wraps the locator numba
would have chosen (``NUMBA_CACHE_DIR``, ``__pycache__`` beside the source, the user-wide
folder), so the cache lives where it did. numba's list is read when a function is
decorated: :mod:`rbm_cli.base.jit`, whose ``jit`` decorates every compiled function of the
package, calls :func:`key_numba_cache` when it is imported, before any decorator runs;
functions decorated earlier get the stamp afterwards, when still unused.
tests/test_kernel_cache.py checks that every compiled function has it.

numba's cache internals are private (``numba.core.caching``); if they change, the key is
not set (:func:`key_numba_cache` returns False) and numba's own check is what remains. So
it is when ``NUMBA_CACHE_LOCATOR_CLASSES`` replaces numba's list of locators.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import re
import sys
from functools import cache
from pathlib import Path

#: The package whose compiled sources key the cache.
PACKAGE = Path(__file__).resolve().parents[1]
#: A compiled function's decorator, at the start of a line.
_DECORATOR = re.compile(r"^[ \t]*@(?:numba\.)?n?jit\b", re.MULTILINE)
#: Tag of the digest in a stamp.
TAG = "rbm sources sha256"


#: ``from rbm_cli.x import a, b as c`` (parenthesised lists included), at the start of a line.
_IMPORT = re.compile(r"^from[ \t]+(rbm_cli(?:\.\w+)+)[ \t]+import[ \t]+(\([^)]*\)|[^\n]*)", re.M)


def _python_files(root: Path) -> list[Path]:
    """Every ``*.py`` file under ``root`` (no ``__pycache__``), sorted."""
    found = []
    for folder, dirs, files in os.walk(root):
        dirs[:] = [d for d in dirs if d != "__pycache__"]
        found += [Path(folder, f) for f in files if f.endswith(".py")]
    return sorted(found)


def _compiled_text(text: str) -> str:
    """The text of the compiled functions of a module: each top-level statement that
    starts with a compiled decorator (all of the module if one is indented)."""
    if any(m.group(0)[:1] in " \t" for m in _DECORATOR.finditer(text)):
        return text
    blocks, current = [], None
    for line in text.splitlines():
        starts = line[:1] not in ("", " ", "\t", "#", ")", "]")
        if starts and not (current is not None and current[-1].startswith("@")):
            if current is not None:
                blocks.append(current)
            current = [line] if _DECORATOR.match(line) else None
        elif current is not None:
            current.append(line)
    if current is not None:
        blocks.append(current)
    return "\n".join(line for block in blocks for line in block)


def _global_sources(text: str, root: Path) -> set[Path]:
    """Package modules whose imported names the compiled functions of ``text`` read
    (a name counts when it appears as a word in a compiled function's text)."""
    words = set(re.findall(r"\w+", _compiled_text(text)))
    found = set()
    for module, names in _IMPORT.findall(text):
        names = re.sub(r"#[^\n]*", "", names).strip("()")
        local = {part.split(" as ")[-1].strip() for part in names.split(",")}
        module_file = _module_file(module, root)
        if module_file is not None and local & words:
            found.add(module_file)
    return found


def _module_file(module: str, root: Path) -> Path | None:
    """The file of module ``rbm_cli.a.b`` under ``root`` (the package folder), or None."""
    parts = module.split(".")[1:]
    for path in (root.joinpath(*parts).with_suffix(".py"), root.joinpath(*parts, "__init__.py")):
        if path.is_file():
            return path
    return None


def compiled_sources(root: Path = PACKAGE) -> dict[Path, bytes]:
    """The files whose contents key the cache, with their contents: modules with compiled
    functions and the modules their compiled functions read names from (see the module's
    docstring), by path, sorted."""
    texts = {path: path.read_bytes() for path in _python_files(root)}
    sources = {}
    for path, data in texts.items():
        if b"jit" not in data:  # cheap first look
            continue
        text = data.decode("utf-8", errors="replace")
        if _DECORATOR.search(text):
            sources[path] = data
            for other in _global_sources(text, root):
                sources[other] = texts.get(other) or other.read_bytes()
    return dict(sorted(sources.items()))


@cache
def source_digest(root: Path = PACKAGE) -> str:
    """SHA-256 (hex) of the compiled sources: each file's path in the package and contents."""
    h = hashlib.sha256()
    for path, data in compiled_sources(root).items():
        h.update(path.relative_to(root).as_posix().encode() + b"\0")
        h.update(data + b"\0")
    return h.hexdigest()


def _inside_package(py_file) -> bool:
    try:
        return Path(py_file).resolve().is_relative_to(PACKAGE)
    except (OSError, TypeError, ValueError):
        return False


def _stamp(inner_stamp) -> tuple:
    return (inner_stamp, f"{TAG}:{source_digest()}")


def _locator_class(caching):
    """A numba cache locator for the package's files: numba's own choice, with the stamp
    of :func:`_stamp`."""

    class SourcesLocator(caching._CacheLocator):
        def __init__(self, inner):
            self._inner = inner

        def ensure_cache_path(self):
            return self._inner.ensure_cache_path()

        def get_cache_path(self):
            return self._inner.get_cache_path()

        def get_source_stamp(self):
            return _stamp(self._inner.get_source_stamp())

        def get_disambiguator(self):
            return self._inner.get_disambiguator()

        def __getattr__(self, name):  # what numba reads of its own locator (_py_file: the
            return getattr(self._inner, name)  # warning that a function cannot be cached)

        @classmethod
        def from_function(cls, py_func, py_file):
            if not _inside_package(py_file):
                return None
            for other in _impl_class(caching)._locator_classes:
                if other is not cls and not getattr(other, "rbm_sources", False):
                    inner = other.from_function(py_func, py_file)
                    if inner is not None:
                        return cls(inner)
            return None

    SourcesLocator.rbm_sources = True
    return SourcesLocator


def _impl_class(caching):
    return getattr(caching, "CacheImpl", None) or caching._CacheImpl  # _CacheImpl: numba < 0.58


def key_numba_cache() -> bool:
    """Key numba's cache of every compiled function of the package on :func:`source_digest`.

    Places the locator first in numba's list (once per process) and stamps the package's
    compiled functions decorated before that and not yet used. Returns False when numba's
    cache internals are not the ones this reads (nothing is changed then).
    """
    try:
        # lazy: numba.core loads only where needed (docs/architecture.md, Start-up)
        from numba.core import caching

        classes = _impl_class(caching)._locator_classes
        if not any(getattr(c, "rbm_sources", False) for c in classes):
            classes.insert(0, _locator_class(caching))
        _tolerate_old_indexes(caching.IndexDataCacheFile)
        _tolerate_unwritable_cache(caching.Cache)
    except (ImportError, AttributeError, TypeError):
        return False
    for dispatcher in package_dispatchers():
        index = getattr(getattr(dispatcher, "_cache", None), "_cache_file", None)
        stamp = getattr(index, "_source_stamp", None)
        if stamp is not None and not is_keyed(stamp) and not dispatcher.overloads:
            index._source_stamp = _stamp(stamp)
    return True


def _tolerate_old_indexes(index_class) -> None:
    """Make numba read an index it cannot unpickle as an empty one (stale: compiled again).

    numba unpickles an index before it compares its stamp; the signatures in it name the
    types they were compiled for, and an index written by another version of the package
    can name a type that no longer exists (a renamed record of arrays): the load then
    raises instead of finding the cache stale. Patched once per process."""
    load = index_class._load_index
    if getattr(load, "rbm_tolerant", False):
        return

    def _load_index(self):
        try:
            return load(self)
        except (AttributeError, ImportError, EOFError, pickle.UnpicklingError):
            return {}

    _load_index.rbm_tolerant = True
    index_class._load_index = _load_index


def _tolerate_unwritable_cache(cache_class) -> None:
    """Make numba go on, without a cache, when it cannot write one (a full disk, a file
    size limit, a read-only folder): the function just compiled runs, and the next process
    compiles it again. numba raises instead, and a run on a full disk then ended in a
    traceback before it could say what it could not write. Patched once per process."""
    save = cache_class.save_overload
    if getattr(save, "rbm_tolerant", False):
        return

    def save_overload(self, sig, data):
        try:
            save(self, sig, data)
        except OSError:
            pass

    save_overload.rbm_tolerant = True
    cache_class.save_overload = save_overload


def is_keyed(stamp) -> bool:
    """Whether a cache stamp carries the sources' digest (of the files as they are now)."""
    return isinstance(stamp, tuple) and len(stamp) == 2 and stamp[1] == f"{TAG}:{source_digest()}"


def package_dispatchers() -> list:
    """The compiled functions (numba dispatchers) of the package's imported modules."""
    found = []
    for name, module in list(sys.modules.items()):
        if name.split(".")[0] != PACKAGE.name or module is None:
            continue
        for obj in list(vars(module).values()):
            py_func = getattr(obj, "py_func", None)
            if py_func is not None and getattr(py_func, "__module__", None) == name:
                if hasattr(obj, "_cache"):
                    found.append(obj)
    return found


def cache_empty(dispatcher) -> bool | None:
    """Whether a compiled function has no usable on-disk cache.

    Returns
    -------
    bool or None  True: numba's cache index of the function is missing, stale (source
        or numba changed) or empty; False: it holds a compiled version; None: cannot
        tell (numba's cache internals are not the ones read here, or caching is off).
    """
    if not hasattr(dispatcher, "py_func"):
        return False  # not compiled (RBM_JIT=0): nothing to load
    try:
        index = dispatcher._cache._cache_file
        overloads = index._load_index()
    except Exception:  # numba's private cache API changed: say so, change nothing else
        return None
    if not isinstance(overloads, dict):
        return None
    return not overloads
