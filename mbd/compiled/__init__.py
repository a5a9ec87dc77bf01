"""Compiled (numba) engine path. The plain numpy path (:mod:`mbd.element`, :mod:`mbd.assembly`,
:mod:`mbd.hht`) stays the reference: tests hold the two together to round-off.

Kernel convention (one module per group of element families; every function ``@njit(cache=True)``; a family
declaring ``compiled_twin = "module.name"`` has ``pack_name``, ``evaluate_name`` and ``update_name`` there,
see :mod:`.registry`):

``pack(elem) -> (P, G)``
    Python side, once at assembly: the family's per-instance parameters as one C-contiguous float64
    array P of shape (n, n_p) (column order documented in the module) and its family-wide values as
    a float64 array G (law ids, law coefficients). Raises :class:`NotImplementedError` naming the
    family when it uses something the compiled path cannot do (e.g. a Python callable of time).

``evaluate(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac)``
    t the time; (phi, omega, domega) the reference frame's angle, speed and acceleration; ql, vl the
    (n, k) local coordinates (x, y, θ per body, in R); z the (n, n_z) internal state (a (n, 0) array
    when the family has none); writes the generalized forces F (n, k) and, when ``jac``, J_q = ∂F/∂q
    and J_v = ∂F/∂v (n, k, k) — the same quantities as :func:`mbd.element.evaluate`.

``update(z, t0, t1, ql0, vl0, ql1, vl1, P, G) -> z1`` (families with internal state only)
    the internal state after an accepted step, as ``Element.update_internal``.

``outputs(t, phi, omega, domega, ql, vl, z, P, G, O)`` (families whose outputs the statistics read)
    the family's outputs at one state into the rows of O (n_outputs, n), in the order its module's
    ``NAME_OUTPUTS`` gives them (the reference's names): written by the same code that computes the forces,
    where it computes each value (:mod:`.outputs` evaluates them for K states at once).
"""

import ast as _ast
import hashlib as _hashlib
import importlib as _importlib
import json as _json
import os as _os
import sys as _sys
import time as _time
from pathlib import Path as _Path

from numba import config as _numba_config
from numba.core import types as _nbtypes

from ..compile_time import compiling


def _sources() -> list:
    """The files the compiled path compiles from: this package's modules, the step rules and the EHL film law."""
    here = _Path(__file__).resolve().parent
    return sorted(here.glob("*.py")) + [here.parent / "rules.py", here.parent / "elements" / "ehl.py"]


def _imports(path: _Path, sources: set) -> set:
    """The files of ``sources`` that the module at ``path`` imports (its relative imports, read from its source)."""
    found = set()
    for node in _ast.walk(_ast.parse(path.read_bytes())):
        if not isinstance(node, _ast.ImportFrom) or node.level == 0:
            continue
        base = path.parent
        for _ in range(node.level - 1):
            base = base.parent
        target = base.joinpath(*node.module.split(".")) if node.module else base
        names = [target.with_suffix(".py"), target / "__init__.py"] if node.module else []
        names += [p for a in node.names for p in (target / f"{a.name}.py", target / a.name / "__init__.py")]
        found.update(p for p in names if p in sources)
    return found - {path}


def source_keys(sources=None) -> dict:
    """Each compiled module's key (module stem -> sha256 of its own source and of every source it imports,
    directly or through others, in :func:`_sources`): a cached kernel of that module is current while its key is."""
    sources = [_Path(p) for p in (sources or _sources())]
    within = set(sources)
    direct = {p: _imports(p, within) for p in sources}
    keys = {}
    for p in sources:
        seen, todo = {p}, [p]
        while todo:
            for d in direct[todo.pop()] - seen:
                seen.add(d)
                todo.append(d)
        digest = _hashlib.sha256()
        for d in sorted(seen):
            digest.update(d.name.encode() + b"\0" + d.read_bytes())
        keys[p.stem] = digest.hexdigest()
    return keys


def stale_modules(stored: dict, keys: dict) -> set:
    """The module stems whose cached kernels are stale: their key changed (or was never stored)."""
    return {stem for stem, key in keys.items() if stored.get(stem) != key}


_ALL = "all sources"     # the stamp's hash of every source together (:func:`_drop_stale_kernels`)


def sources_hash(sources, root) -> str:
    """One sha256 of every source's name (relative to ``root``) and content: the keys (:func:`source_keys`) are a
    function of it, so a stamp whose hash is current holds current keys."""
    whole = _hashlib.sha256()
    for p in sources:
        whole.update(_Path(p).relative_to(root).as_posix().encode() + b"\0" + _Path(p).read_bytes() + b"\0")
    return whole.hexdigest()


def _drop_stale_kernels() -> None:
    """numba keys a cached function on its own source file only (the file's time stamp and size, and the
    function's bytecode): a kernel compiled into a caller in another file — the dispatch (registry), the assembly,
    the step loop — would keep a changed kernel's old code. So each module's cached kernels are dropped when its
    key changes (:func:`source_keys`: its source and every source it imports, kept beside the cache): an edit
    to the step loop recompiles the step loop and loads the family kernels; an edit to a kernel module recompiles
    it and the modules importing it, not the other kernel modules."""
    here = _Path(__file__).resolve().parent
    roots = [_Path(_numba_config.CACHE_DIR)] if _numba_config.CACHE_DIR else [here / "__pycache__", here.parent / "__pycache__"]
    stamp = roots[0] / "compiled_sources.json"
    try:
        try:
            stored = _json.loads(stamp.read_text()) if stamp.is_file() else {}
        except ValueError:
            stored = {}
        # the keys are a function of the sources alone: sources unchanged since the stamp (one hash of them all,
        # under a name no module has) need no parse of their imports (≈ 0.16 s in every process that imports mbd)
        sources = _sources()
        whole = sources_hash(sources, here.parent)
        if stored.get(_ALL) == whole:
            return
        keys = source_keys(sources)
        stale = stale_modules(stored, keys)
        # a source edited while the keys were computed: its stale kernels go, but no stamp vouches for keys that may
        # belong to other contents than the hash (the next import computes them again)
        settled = sources_hash(sources, here.parent) == whole
        keys[_ALL] = whole
        names = tuple(stem + "." for stem in stale)
        for root in roots:
            for f in root.rglob("*.nb[ic]") if root.is_dir() else ():
                if f.name.startswith(names):
                    f.unlink(missing_ok=True)
        if not settled:
            return
        stamp.parent.mkdir(parents=True, exist_ok=True)
        tmp = stamp.with_suffix(f".{_os.getpid()}.tmp")
        tmp.write_text(_json.dumps(keys, indent=0, sort_keys=True))
        _os.replace(tmp, stamp)
    except OSError:          # a read-only install: numba then compiles in memory (it cannot cache either)
        pass


def kernels_cached(function="stepper.advance", groups: int | None = None) -> bool:
    """Does numba's disk cache hold the compiled ``function`` of this code, so that a run loads it in about a second
    instead of compiling it? ``function``: "module.name" in this package (by default the step loop; checked by its
    index file, :func:`_drop_stale_kernels` removes stale ones) — with ``groups`` (a :data:`.registry.GROUPS` mask)
    compiled for that set of families (:func:`cached_groups`), without for any —, or a cached numba function of
    another package (a kernel depending on its own file only: its index file for its current first line, newer than
    its source)."""
    if not isinstance(function, str):
        code = function.py_func.__code__
        index = _Path(function.stats.cache_path) / (f"{_Path(code.co_filename).stem}.{function.py_func.__qualname__}-"
                                                    f"{code.co_firstlineno}.py{_sys.version_info[0]}{_sys.version_info[1]}.nbi")
        return index.is_file() and index.stat().st_mtime >= _Path(code.co_filename).stat().st_mtime
    if groups is not None:
        return groups in cached_groups(function)
    here = _Path(__file__).resolve().parent
    root = _Path(_numba_config.CACHE_DIR) if _numba_config.CACHE_DIR else here / "__pycache__"
    return any(root.rglob(f"{function}-*.nbi")) if root.is_dir() else False


def compile_announced(compile, cold: bool, what: str, done: str, about: str) -> None:
    """Call ``compile`` (it compiles or loads numba kernels) now, before a run's first step: a progress bar's ETA then
    leaves the compile out. When ``cold`` (:func:`kernels_cached` says numba's cache does not hold them) a first run
    says what it is doing instead of looking stuck, in one line before ("mbd: compiling ``what`` (...; ``about``,
    then cached)") and one after ("mbd: ``done`` compiled in N s")."""
    if cold:
        print(f"mbd: compiling {what} (the first run of this code on this machine; {about}, then cached)",
              file=_sys.stderr, flush=True)
    t0 = _time.perf_counter()
    with compiling():           # a run's wall time leaves it out (mbd.compile_time)
        compile()
    if cold:
        print(f"mbd: {done} compiled in {_time.perf_counter() - t0:.0f} s", file=_sys.stderr, flush=True)


def cached_groups(function: str = "stepper.advance") -> set:
    """The family-group masks (:data:`.registry.GROUPS`) for which numba's disk cache holds ``function`` (whose
    first argument is ``groups``) of this code: the entries numba itself would load (same code, same machine)."""
    module, _, name = function.partition(".")
    disp = getattr(_importlib.import_module(f"{__name__}.{module}"), name)
    try:                    # numba's cache index (private API, read only): an unreadable one counts as empty
        cache = disp._cache
        codegen = disp.targetctx.codegen()
        return {key[0][0].literal_value for key in cache._cache_file._load_index()
                if isinstance(key[0][0], _nbtypes.IntegerLiteral) and cache._index_key(key[0], codegen) == key}
    except Exception:       # noqa: BLE001 — e.g. a numba whose cache internals differ: compile the exact set
        return set()


_drop_stale_kernels()
