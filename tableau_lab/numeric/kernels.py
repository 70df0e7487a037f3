r"""The step loop of :mod:`stepcore` made runnable: compiled (numba, float64 or double-double)
or pure Python (float64 as the reference, mpmath at any precision), and driven in chunks.

A compiled loop is one module per problem, arithmetic and method shape (s, r, d), written
under the cache directory (``$TABLEAU_LAB_CACHE``, else ``~/.cache/tableau_lab``) with a name
that hashes its text (:func:`module_source`): an import of the problem's generated functions
(:mod:`problem_code`; a module of their own, compiled once per problem and arithmetic for every
shape), the specialisation's constants (the stage iteration, projection, which matrices have no
zero), the arithmetic module's :data:`~.ops_f64.OPERATIONS` and the functions of
:data:`stepcore.LOOP <.stepcore.LOOP>`, each one's source whole, with ``dims`` returning the
shape as constants (the small loops over stages, values and components unroll).  numba caches
the machine code beside it, so the compile cost is paid once per problem and shape (reported
as ``compile_seconds``, never inside a rate); the method's coefficients and the step size are
data.  The pure loop runs the same function objects of :mod:`stepcore`, bound to :mod:`ops_f64`
or :mod:`ops_mp` and Python wrappers of the problem.

:func:`drive` runs a loop in chunks between which Python records (through ``record``),
reports progress and lets Ctrl-C through, and returns an :class:`Outcome` (the counters,
the final input vector, the status).

>>> from tableau_lab.exact.tableau_json import load
>>> from tableau_lab.numeric.export import to_numeric
>>> from tableau_lab.numeric.codegen import compile_problem
>>> from tableau_lab.numeric.integrate import integrate
>>> cp = compile_problem("pendulum")
>>> nm = to_numeric(load("methods/gauss2.json"))
>>> fast = integrate(nm, cp, cp.y0, 0.01, 1000, kernel="compiled")
>>> slow = integrate(nm, cp, cp.y0, 0.01, 1000, kernel="python")
>>> bool(abs(fast.final - slow.final).max() < 1e-13), fast.nfev == slow.nfev
(True, True)
"""
from __future__ import annotations

import contextlib
import functools
import hashlib
import importlib.util
import inspect
import math
import os
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from types import FunctionType
from typing import NamedTuple

import numpy as np

from ..files import atomic_write_text, path_exists
from . import limits as L
from .inliner import inline_functions
from .stepcore import Coefficients, Controls, ProblemData, Span, State

__all__ = ["available", "cache_dir", "code_dir", "compile_state", "Shape", "loop_shape", "dense_matrices", "run_shape",
           "invariant_index", "write_problem_module", "module_source", "specialisation", "compiled_loop", "linked_loop",
           "linked_files", "linked_data", "generic_shape", "pure_loop",
           "Pack", "LoopState", "Outcome", "drive"]

HERE = Path(__file__).resolve().parent
_MODULES: dict = {}        # module file -> module (the cache folder may change: TABLEAU_LAB_CACHE)
_BY_KEY: dict = {}         # (cache folder, problem.key, kind, shape) -> module: generated once per process
_COMPILE: dict = {}        # module name -> seconds of the first (compiling or cache-loading) call
_SOURCES: dict = {}        # (problem.key, kind) -> the problem module's text (compile_state, then compiled_loop)


def available() -> bool:
    """numba importable."""
    return importlib.util.find_spec("numba") is not None


def _user_cache() -> Path:
    return Path.home() / ".cache" / "tableau_lab"     # the default root of cache_dir and shared_dir


def cache_dir() -> Path:
    """The folder of the generated modules: ``$TABLEAU_LAB_CACHE/kernels``, else
    ``~/.cache/tableau_lab/kernels``.  A ``TABLEAU_LAB_CACHE`` that is there but not a folder
    (a file, a device) is refused (:class:`~tableau_lab.errors.InputError`, exit 2)."""
    given = os.environ.get("TABLEAU_LAB_CACHE")
    root = Path(given or _user_cache())
    for folder in (root, root / "kernels"):
        if path_exists(folder) and not folder.is_dir():
            from ..errors import InputError
            from ..inputs import printable
            raise InputError(f"{'TABLEAU_LAB_CACHE=' if given else ''}{printable(root)}: the compiled-kernel cache "
                             f"folder {printable(folder)} is not a folder; point TABLEAU_LAB_CACHE at a folder "
                             "(or unset it for ~/.cache/tableau_lab)")
    return root / "kernels"


def code_dir() -> Path:
    """The folder of generated Python code: ``codes`` beside the compiled kernels
    (:func:`cache_dir`) — a problem's generated functions (``codegen``: sympy's derivatives and
    lambdify, most of a short pure run's preparation) and the pure loop's inlined text
    (``inliner``), so that a run of a problem met before generates neither."""
    return cache_dir().parent / "codes"


DENSE = ("DENSE_A", "DENSE_B", "DENSE_U", "DENSE_V")     # stepcore's names


class Shape(NamedTuple):
    """What a compiled loop is specialised to: the method's shape (s stages, r values, dimension
    d; the small loops unroll), the stage iteration (limits.EXPLICIT, NEWTON, FIXED or SPLIT:
    the others' code is not compiled), whether the run projects (1 or 0), and which of the
    method's matrices have no zero (:func:`dense_matrices`; () for none known: every
    coefficient tested in the step)."""
    s: int
    r: int
    d: int
    mode: int
    projects: int
    dense: tuple = ()


def loop_shape(s: int, r: int, d: int, mode: int, projects: bool = False, dense: tuple = ()):
    """The :class:`Shape` a compiled loop is specialised to, or None (one loop for any shape
    and run per problem) when the environment variable TABLEAU_LAB_SPECIALISE is "0"."""
    if os.environ.get("TABLEAU_LAB_SPECIALISE", "1") == "0":
        return None
    if mode not in (L.EXPLICIT, L.NEWTON, L.FIXED, L.SPLIT):
        raise ValueError(f"a loop is specialised to an explicit method, NEWTON, FIXED or SPLIT, not mode {mode}")
    if dense and len(dense) != len(DENSE):
        raise ValueError(f"dense: {len(DENSE)} flags ({', '.join(DENSE)}), not {len(dense)}")
    return Shape(int(s), int(r), int(d), int(mode), int(bool(projects)), tuple(int(x) for x in dense))


def dense_matrices(pk: "Pack") -> tuple:
    """stepcore's ``DENSE`` for the method of ``pk``: 1 for each of A (both classes), B, U and V
    without a zero entry, whose coefficients the compiled step uses without testing (or
    selecting on) them; 0 for the others, tested coefficient by coefficient when the step runs.
    (Per-coefficient masks, tried, cost a shift and a test where LLVM does not unroll the loop:
    docs/speed.md.)  Double-double coefficients are zero when their leading part is."""

    def lead(M):                                 # the leading parts of a double-double array
        return np.asarray(M)[..., 0] if pk.kind == "dd" else np.asarray(M)

    return tuple(int(bool(np.all(lead(M) != 0))) for M in (pk.A, pk.B, pk.U, pk.V))


def run_shape(pk: "Pack"):
    """The :class:`Shape` of a run with the loop arrays ``pk`` (or None, as :func:`loop_shape`)."""
    mode = L.EXPLICIT if pk.flags[L.F_EXPLICIT] == 1 else int(pk.flags[L.F_MODE])
    s, r, d = pk.A.shape[1], pk.U.shape[1], pk.cls.shape[0]
    return loop_shape(s, r, d, mode, len(pk.proj) > 0, dense_matrices(pk))


def invariant_index(prob) -> dict:
    """Invariant name -> its index in the loops' ``inv_``/``grad_`` (the problem's order)."""
    P = getattr(prob, "problem", prob)
    return {k: i for i, k in enumerate(getattr(P, "invariants", ()))}


_HEADER = """# generated by tableau_lab.numeric.kernels from stepcore.py, {ops} and the problem: do not edit
# sources {stamp}
import math

import numpy as np

from tableau_lab.numeric.jit import alloc, helper, kernel, prim
from tableau_lab.numeric.limits import *
from tableau_lab.numeric.stepcore import {records}
{extra}from {problem_module} import {problem_names}
{aliases}
heavy = {heavy}      # the Newton matrix's LU: inlined (unrolled) for small s·d only
"""

_PROBLEM_HEADER = """# generated by tableau_lab.numeric.kernels: the functions of one problem, compiled once for
# every loop that imports them; do not edit
# sources {stamp}
import math
import numpy as np
from tableau_lab.numeric.jit import cold, helper
{extra}
hot = {hot}
"""


def _stamp(files) -> str:
    """A digest of the package sources a generated module depends on: numba's cache does not
    follow imports, so the generated text names their version."""
    return hashlib.sha256(b"".join((HERE / f).read_bytes() for f in files)).hexdigest()[:16]


def problem_module_source(problem, kind: str) -> str:
    """The problem's functions (:mod:`problem_code`) as a module of their own, compiled once per
    problem and arithmetic (the Jacobian of the outer solar system alone takes 15 s): the
    loops of every method shape import them."""
    from .problem_code import problem_source
    if (problem.key, kind) in _SOURCES:
        return _SOURCES[(problem.key, kind)]
    dd = kind == "dd"
    inline = not dd and problem.dimension <= L.INLINE_PROBLEM_DIMENSION
    text = _PROBLEM_HEADER.format(extra="from tableau_lab.numeric.ddmath import *" if dd else "",
                                  stamp=_stamp(["jit.py"] + (["ddmath.py"] if dd else [])),
                                  hot="helper" if inline else "cold")
    text += "\n\n" + problem_source(problem, tuple(problem.invariants), dd=dd, hot="@hot\n", cold="@cold\n")
    _SOURCES[(problem.key, kind)] = text
    return text


def _section(title: str, text: str) -> str:
    return f"\n\n# ---- {title} " + "-" * max(4, 90 - len(title)) + "\n\n\n" + text


def _definitions(module, names, written=None) -> str:
    """The source of each of ``module``'s functions ``names``, whole (decorators included), or
    ``name = other`` for a name bound to another function of the list, or the text
    ``written[name]``."""
    parts = []
    for name in names:
        fn = getattr(module, name)
        if written and name in written:
            parts.append(written[name])
        else:
            parts.append(inspect.getsource(fn) if fn.__name__ == name else f"{name} = {fn.__name__}\n")
    return "\n\n".join(parts)


def specialisation(shape) -> dict:
    """stepcore's :data:`~.stepcore.SPECIALISED` constants for a loop specialised to ``shape``
    (a :class:`Shape`), or their generic values (None)."""
    from .stepcore import SPECIALISED
    values = dict(SPECIALISED)
    if shape is not None:
        values.update(LOOP_MODE=shape.mode, LOOP_PROJECTS=shape.projects)
        values.update(zip(DENSE, shape.dense, strict=False))
    return values


def shape_text(shape) -> str:
    """A loop's :class:`Shape` in words (None: any shape).

    >>> shape_text(Shape(2, 1, 2, L.SPLIT, 0))
    's = 2, r = 1, d = 2, SPLIT, no projection'
    """
    if shape is None:
        return "any shape and run"
    mode = {L.EXPLICIT: "explicit", L.NEWTON: "NEWTON", L.FIXED: "FIXED", L.SPLIT: "SPLIT"}[shape.mode]
    sizes = f"s = {shape.s}, r = {shape.r}, d = {shape.d}" if shape.s else "any shape"     # s = 0: the linked loop's
    return f"{sizes}, {mode}, {'projection' if shape.projects else 'no projection'}"


@functools.lru_cache(maxsize=256)
def module_source(kind: str, shape, problem_module: str, separable: bool) -> str:
    """The text of a compiled loop for ``kind`` "f64" or "dd" specialised to ``shape`` (a
    :class:`Shape`), or for any shape and run (None); the problem's functions come from the
    module named ``problem_module`` (:func:`problem_module_source`; ``separable``: it has the
    q- and p-rates).  Needs no sympy: a frozen job writes its loops itself.

    The text is assembled from named parts, each real Python: a header of imports, the
    specialisation's constants (:func:`specialisation`), the arithmetic module's
    :data:`~.ops_f64.OPERATIONS` and :data:`stepcore.LOOP <.stepcore.LOOP>`, each function's source
    whole; only ``dims`` is written here, returning the shape as constants.

    >>> text = module_source("f64", Shape(2, 1, 2, L.SPLIT, 0), "problem_module", False)
    >>> code = compile(text, "loop.py", "exec")
    >>> [line.strip("# -") for line in text.splitlines() if line.startswith("# ----")]
    ['specialised to s = 2, r = 1, d = 2, SPLIT, no projection', 'arithmetic: ops_f64', 'the step loop: stepcore']
    """
    from . import ops_f64, stepcore
    if kind == "dd":                 # ops_dd imports numba (ddmath): not for a float64 text (compile_state)
        from . import ops_dd as ops
    else:
        ops = ops_f64
    ops_file = f"{ops.__name__.rsplit('.', 1)[1]}.py"
    stamp = _stamp(["stepcore.py", "limits.py", "jit.py", ops_file] + (["ddmath.py"] if kind == "dd" else []))
    small = shape is not None and 0 < shape.s * shape.d <= L.INLINE_LINEAR_ALGEBRA
    names = ["f_", "jac_", "inv_", "grad_"] + (["fq_", "fp_"] if separable else [])
    # the q-stage iteration is never run for a problem that is not separable, but a loop for any
    # shape (LOOP_MODE a value, not a constant) still compiles its calls
    text = _HEADER.format(ops=ops_file, stamp=stamp, records=", ".join(r.__name__ for r in stepcore.RECORDS),
                          extra="from tableau_lab.numeric.ddmath import *\n" if kind == "dd" else "",
                          problem_module=problem_module, problem_names=", ".join(names),
                          aliases="" if separable else "fq_ = fp_ = f_\n", heavy="helper" if small else "prim")
    title = "generic: any shape and run" if shape is None else f"specialised to {shape_text(shape)}"
    named = {L.ANY: "ANY", L.EXPLICIT: "EXPLICIT", L.NEWTON: "NEWTON", L.FIXED: "FIXED", L.SPLIT: "SPLIT"}
    values = specialisation(shape)
    values["LOOP_MODE"] = named[values["LOOP_MODE"]]          # by name: limits' constants
    if values["LOOP_PROJECTS"] == L.ANY:
        values["LOOP_PROJECTS"] = "ANY"
    text += _section(title, "".join(f"{k} = {v}\n" for k, v in values.items()))
    text += _section(f"arithmetic: {ops_file[:-3]}", _definitions(ops, ops_f64.OPERATIONS))
    written = {}
    if shape is not None and shape.s:           # the shape as constants (s = 0: as data): the small loops unroll
        written["dims"] = f"@helper\ndef dims(A, Y):\n    return {shape.s}, {shape.r}, {shape.d}\n"
    return text + _section("the step loop: stepcore", _definitions(stepcore, [fn.__name__ for fn in stepcore.LOOP],
                                                                   written))


def _module_name(prefix: str, source: str) -> str:
    return f"{prefix}_{hashlib.sha256(source.encode()).hexdigest()[:20]}"


def _write(prefix: str, source: str, folder: Path | None = None) -> tuple:
    name = _module_name(prefix, source)
    path = (folder or cache_dir()) / f"{name}.py"
    if not path.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_text(path, source)
    return name, str(path)


def write_problem_module(problem, kind: str = "f64") -> tuple:
    """Generate the problem's module (:func:`problem_module_source`; needs sympy) and write it
    to the cache unless it is there: (module name, path)."""
    return _write("tableau_lab_problem", problem_module_source(problem, kind))


def load_module(name: str, path: str):
    """Import the generated module ``name`` from ``path`` once per process (numba compiles its
    functions on their first call, or loads them from its disk cache beside the module)."""
    key = str(path)
    if key not in _MODULES:
        spec = importlib.util.spec_from_file_location(name, path)
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod
        spec.loader.exec_module(mod)
        _MODULES[key] = mod
    return _MODULES[key]


def _problem_files(problem, kind: str) -> tuple:
    """(name, path) of the problem's module: a frozen problem's ``kernel_files`` (kind -> (name,
    path)), else generated and written (:func:`write_problem_module`)."""
    files = getattr(problem, "kernel_files", None) or {}
    return files[kind] if kind in files else write_problem_module(problem, kind)


def _problem_name(problem, kind: str) -> str:
    """The name of the problem's module, nothing written (:func:`_problem_files`)."""
    files = getattr(problem, "kernel_files", None) or {}
    if kind in files:
        return files[kind][0]
    return _module_name("tableau_lab_problem", problem_module_source(problem, kind))


def loop_files(problem, kind: str = "f64", shape=None) -> tuple:
    """(problem module name, its path, loop module name, its path) of :func:`compiled_loop`,
    generated and written on first use (:func:`_problem_files`); nothing imported."""
    pname, ppath = _problem_files(problem, kind)
    return (pname, ppath, *_write("tableau_lab_kernel", module_source(kind, shape, pname, problem.separable)))


def compiled_loop(problem, kind: str = "f64", shape=None):
    """The compiled loop of ``problem`` for ``kind`` and ``shape`` (:func:`loop_shape`): its
    files written on first use (:func:`loop_files`), imported once per process; numba compiles
    on the first call or loads its disk cache.  ``loop.sibling(mode)``: the loop of the same
    problem and shape for another stage iteration (the run switched to Newton).  With
    TABLEAU_LAB_SPECIALISE=linked a float64 loop is the one of :func:`linked_loop`."""
    if kind == "f64" and shape is not None and os.environ.get("TABLEAU_LAB_SPECIALISE") == "linked":
        return linked_loop(problem, shape)
    key = (str(cache_dir()), problem.key, kind, shape)
    if key in _BY_KEY:
        return _described(_BY_KEY[key], problem, kind, shape)
    pname, ppath, name, path = loop_files(problem, kind, shape)
    load_module(pname, ppath)                   # first: the loop imports it by name
    mod = load_module(name, path)
    mod.invariant_index = invariant_index(problem)
    mod.sibling = lambda mode: mod if shape is None else compiled_loop(problem, kind, shape._replace(mode=int(mode)))
    _BY_KEY[key] = mod
    return _described(mod, problem, kind, shape)


def _described(mod, problem, kind: str, shape):
    """``mod`` with the words of its compile notice for the run about to use it (problems whose
    texts are the same share a module)."""
    arith = "float64" if kind == "f64" else kind
    mod.described = f"{getattr(problem, 'name', problem.key)} ({arith}, {shape_text(shape)})"
    return mod


class _LinkedLoop:
    """A linked loop (:mod:`linked`: one module per stage iteration and projection for every
    problem and method shape) bound to one problem: the module's functions, and ``link``, which
    puts the problem's entry points into the run's ``ProblemData``."""

    def __init__(self, mod, problem, shape):
        self._mod, self._problem, self._shape = mod, problem, shape
        self.__name__ = f"{mod.__name__}:{problem.key}"      # compile_seconds: the problem's entry points too
        self.described = f"every problem (float64, {shape_text(generic_shape(shape))})"
        self.invariant_index = invariant_index(problem)

    def __getattr__(self, name):
        return getattr(self._mod, name)

    def sibling(self, mode):
        return linked_loop(self._problem, self._shape._replace(mode=int(mode)))

    def link(self, data: ProblemData, rescue: bool = False) -> ProblemData:
        """``data`` with ``c`` the :class:`~.linked.Linked` record: the constants and the addresses of the
        entry points this loop can call (:func:`~.linked.slots_needed`; ``rescue``: the Jacobian too,
        for :func:`~.stepcore.rescue_step`); 0 for the others."""
        from .linked import SLOTS, slots_needed
        nc = len(data.c)
        wanted = slots_needed(self._shape.mode, len(data.proj) > 0, len(data.track) > 0, rescue)
        return linked_data(data, [_entry(self._problem, slot, nc) if slot in wanted else 0 for slot in SLOTS])


def linked_data(data: ProblemData, addresses=None) -> ProblemData:
    """``data`` as a linked loop takes it: ``c`` the :class:`~.linked.Linked` record of the constants and
    the entry points' ``addresses`` (in the order of :data:`~.linked.SLOTS`; None: every one 0 — the
    argument types a linked loop compiles for, with nothing to call: :mod:`.background`'s build, which
    calls ``run`` with no step)."""
    from .linked import SLOTS, Linked
    fn = np.zeros(len(SLOTS), dtype=np.int64) if addresses is None else np.array(addresses, dtype=np.int64)
    return data._replace(c=Linked(np.ascontiguousarray(data.c, dtype=float), fn))


def _entry(problem, slot: str, nc: int) -> int:
    """The address of the C entry point of ``problem``'s function ``slot`` for ``nc`` constants
    (:func:`linked.entry_source`): generated, written and compiled (or loaded from numba's cache)
    once."""
    key = (str(cache_dir()), problem.key, "entry", slot, nc)
    if key not in _BY_KEY:
        pname, ppath = _problem_files(problem, "f64")
        load_module(pname, ppath)
        name, path = _write("tableau_lab_entry", _entry_text(problem, slot, nc, pname))
        if _disk_state(cache_dir(), name, "entry") == "cold" and problem.key not in _ANNOUNCED:
            _ANNOUNCED.add(problem.key)
            notice(f"compiling the functions of {getattr(problem, 'name', 'this problem')} for the loops shared by "
                   f"every problem — {cached_in(cache_dir())} (about {L.LINKED_PROBLEM_SECONDS:.0f} s a function) ...")
        _BY_KEY[key] = load_module(name, path).ADDRESS
    return _BY_KEY[key]


_ANNOUNCED: set = set()    # problem keys whose entry points' compile was announced in this process


@functools.lru_cache(maxsize=1)
def _linked_stamp() -> str:
    return _stamp(["linked.py", "jit.py"])


def _entry_text(problem, slot: str, nc: int, pname: str) -> str:
    """The text of the entry-point module of ``problem``'s ``slot`` (:func:`linked.entry_source`)."""
    from .linked import entry_source
    return entry_source(slot, pname, problem.dimension, nc, problem.separable, _linked_stamp())


def entries_state(problem, shape, nc: int, tracks: bool) -> str:
    """"loaded", "cached" or "cold" (:func:`compile_state`'s words) for the entry points of
    ``problem`` (``nc`` constants) that a linked run of ``shape`` calls (:func:`~.linked.slots_needed`;
    ``tracks``: invariants tracked).  Writes nothing."""
    from .linked import slots_needed
    wanted = slots_needed(shape.mode, bool(shape.projects), tracks)
    if all((str(cache_dir()), problem.key, "entry", slot, nc) in _BY_KEY for slot in wanted):
        return "loaded"
    pname = _problem_name(problem, "f64")
    names = [_module_name("tableau_lab_entry", _entry_text(problem, slot, nc, pname)) for slot in wanted]
    return "cached" if all(_disk_state(cache_dir(), n, "entry") == "cached" for n in names) else "cold"


def shared_dir() -> Path:
    """The folder of the modules that serve every problem (the linked loops, :func:`linked_loop`):
    ``$TABLEAU_LAB_SHARED_CACHE``, else ``~/.cache/tableau_lab/shared`` — apart from the problems'
    cache (:func:`cache_dir`), as an installation's compiled parts: built once
    (``tableau-lab warm-up``, :func:`tableau_lab.warm_up`), kept when the problems' cache is emptied."""
    given = os.environ.get("TABLEAU_LAB_SHARED_CACHE")
    return Path(given) if given else _user_cache() / "shared"


def _linked_texts(shape) -> tuple:
    """(prefix, text) of the linked loop's problem module and of its loop module for the stage
    iteration and projection of ``shape``."""
    from .linked import PROBLEM_TEXT
    ltext = PROBLEM_TEXT.format(stamp=_linked_stamp())
    lname = _module_name("tableau_lab_linked", ltext)
    loop = module_source("f64", generic_shape(shape), lname, True)
    return ("tableau_lab_linked", ltext), ("tableau_lab_kernel", loop)


def linked_files(shape) -> tuple:
    """(its problem module's name, path, loop module's name, path) of the linked loop for the
    stage iteration and projection of ``shape``, written in :func:`shared_dir` if not there."""
    (lprefix, ltext), (prefix, text) = _linked_texts(shape)
    folder = shared_dir()
    return (*_write(lprefix, ltext, folder), *_write(prefix, text, folder))


def generic_shape(shape) -> Shape:
    """The :class:`Shape` a linked loop is compiled for: ``shape``'s stage iteration and projection,
    any method shape (s = r = d = 0).

    >>> shape_text(generic_shape(Shape(2, 1, 2, L.SPLIT, 1, (1, 1, 1, 1))))
    'any shape, SPLIT, projection'
    """
    return Shape(0, 0, 0, shape.mode, shape.projects)


def linked_state(shape) -> str:
    """"loaded", "cached" or "cold" (:func:`compile_state`'s words) for the linked loop of
    ``shape``'s stage iteration and projection; its problem's entry points not counted (about
    ``limits.LINKED_PROBLEM_SECONDS`` when they compile).  Writes nothing."""
    name = _module_name(*_linked_texts(shape)[1])
    if any(entry == "run" and loop.split(":")[0] == name for loop, entry in _COMPILE):   # any problem's
        return "loaded"
    return _disk_state(shared_dir(), name)


def linked_loop(problem, shape):
    """The float64 loop for ``shape``'s stage iteration and projection that serves every problem and
    method shape (:mod:`linked`; the cost rule's quick compiled loop when built, and every float64
    loop with TABLEAU_LAB_SPECIALISE=linked), bound to ``problem``: the module is compiled once
    (in :func:`shared_dir`), each problem adds its entry points only (in :func:`cache_dir`)."""
    key = (str(cache_dir()), problem.key, "linked", shape)
    if key in _BY_KEY:
        return _BY_KEY[key]
    lname, lpath, name, path = linked_files(shape)
    load_module(lname, lpath)
    _BY_KEY[key] = _LinkedLoop(load_module(name, path), problem, shape)
    return _BY_KEY[key]


def compile_state(problem, kind: str = "f64", shape=None, disk: bool = True):
    """What the first call of :func:`compiled_loop`'s loop will cost: "loaded" (compiled or
    loaded in this process: nothing), "cached" (numba's machine code of its ``run`` is in the
    disk cache beside the module: a load) or "cold" (a compile); None when not loaded and
    ``disk`` is False.  Looking at the disk generates the module texts (as the loop itself
    would, and kept for it: the outer solar system's take 5 s) but writes nothing."""
    key = (str(cache_dir()), problem.key, kind, shape)
    if key in _BY_KEY and (_BY_KEY[key].__name__, "run") in _COMPILE:
        return "loaded"
    if not disk:
        return None
    pname = _problem_name(problem, kind)
    name = _module_name("tableau_lab_kernel", module_source(kind, shape, pname, problem.separable))
    return _disk_state(cache_dir(), name)


def _disk_state(folder: Path, name: str, entry: str = "run") -> str:
    """"cached" when numba's index of the loop module ``name``'s ``entry`` is in ``folder``'s
    cache, else "cold"."""
    if not path_exists(folder / f"{name}.py"):
        return "cold"
    return "cached" if any((folder / "__pycache__").glob(f"{name}.{entry}-*.nbi")) else "cold"


class _Namespace:
    """A pure loop: stepcore's functions executed with an arithmetic and a problem."""

    def __init__(self, ns: dict, prob):
        self.__dict__.update(ns)
        self.invariant_index = invariant_index(prob)
        self.__name__ = "pure"


def pure_loop(prob, arith_name: str):
    """:data:`stepcore.LOOP <.stepcore.LOOP>`'s functions run in Python, bound to :mod:`ops_f64`
    (float64) or :mod:`ops_mp` (mpmath) and the functions of ``prob`` (a compiled or frozen
    problem): the same function objects, with a namespace of their own for their globals (float64:
    elements read as Python floats, :data:`~.ops_f64.PURE_READS`; a generated problem's code
    called as it is, inside the run's ``np.errstate``)."""
    from . import ops_f64, ops_mp, stepcore
    ops = ops_f64 if arith_name == "float64" else ops_mp
    ns = {k: v for k, v in vars(L).items() if not k.startswith("_")}
    ns.update(stepcore.SPECIALISED, np=np, math=math, __name__="tableau_lab.numeric.pure_loop",
              __builtins__=__builtins__)
    ns.update({r.__name__: r for r in stepcore.RECORDS})
    ns.update({name: getattr(ops, name) for name in ops_f64.OPERATIONS})
    if ops is ops_f64:
        ns.update(ops_f64.PURE_READS)
    operations = {name: ns[name] for name in ops_f64.OPERATIONS if isinstance(ns[name], FunctionType)}
    inline_functions(stepcore.LOOP, operations, ns, ns, code_dir())   # one-line operations written in place
    P = getattr(prob, "problem", None)        # a bare object with f (and jac) will do too
    names = tuple(P.invariants) if P is not None else ()
    k = len(P.q) if P is not None and P.kind == "hamiltonian" else 0
    if arith_name == "float64" and getattr(prob, "backend", None) == "numpy" and hasattr(prob, "generated"):
        ns.update(_direct_functions(prob, names, k))
    else:
        ns.update(_wrapped_functions(prob, names, k))
    return _Namespace(ns, prob)


def _direct_functions(prob, names: tuple, k: int) -> dict:
    """The problem's functions for the float64 pure loop: its generated code called as it is
    (:meth:`~.problem_functions.ProblemFunctions.generated`, looked up by name; Jacobian,
    invariants and gradients generated on first use), inside the run's ``np.errstate``."""
    code, c, f = prob.generated, prob.constants, prob.generated("f")

    def f_(y, _c, out, i):
        out[i] = f(y, c)

    def jac_(y, _c, out):
        out[:, :] = code("jac")(y, c)

    def fq_(y, _c, out, i):
        out[i, :k] = f(y, c)[:k]

    def fp_(y, _c, out, i):
        out[i, k:] = f(y, c)[k:]

    def inv_(j, y, _c, out):
        out[0] = code(("invariant", names[j]))(y, c)

    def grad_(j, y, _c, out, i):
        out[i] = code(("gradient", names[j]))(y, c)

    return dict(f_=f_, jac_=jac_, fq_=fq_, fp_=fp_, inv_=inv_, grad_=grad_)


def _wrapped_functions(prob, names: tuple, k: int) -> dict:
    """The problem's functions through ``prob.f`` … (mpmath at its precision, bare objects)."""

    def f_(y, c, out, i):
        out[i] = prob.f(y)

    def jac_(y, c, out):
        out[:, :] = prob.jac(y)

    def fq_(y, c, out, i):
        out[i, :k] = prob.f(y)[:k]

    def fp_(y, c, out, i):
        out[i, k:] = prob.f(y)[k:]

    def inv_(j, y, c, out):
        out[0] = prob.invariant(names[j], y)

    def grad_(j, y, c, out, i):
        out[i] = prob.gradient(names[j], y)

    return dict(f_=f_, jac_=jac_, fq_=fq_, fp_=fp_, inv_=inv_, grad_=grad_)


# -- the loop's arrays ---------------------------------------------------------------------------

class Pack:
    """The method, problem and run constants as the loop's arrays at the working precision:
    float64, double-double (trailing axis hi, lo, rounded from the multiprecision values) or
    mpmath (object arrays)."""

    def __init__(self, nm, prob, h, masks, *, mode, compensated=True, predict=True, project=(), track=(),
                 targets=None, index=None):
        """``compensated``: Kahan summation of the principal value where V's first row is e₁ᵀ
        (not in double-double, which carries it); ``predict``: the predicted stage start."""
        a = nm.arith
        targets, index = targets or {}, index or {}
        self.kind = {"float64": "f64", "dd": "dd"}.get(a.name, "mp")
        num = self.num
        mq = np.array([float(x) for x in masks[0]])
        mp_ = np.array([float(x) for x in masks[1]])
        if not np.all(mq + mp_ == 1) or not np.all((mq == 0) | (mq == 1)):
            raise ValueError("the step loop needs complementary 0/1 component masks")
        self.cls = np.ascontiguousarray((mq == 0).astype(np.int64))
        self.h, self.hinv = self.scalar(h), self.scalar(1 / h)
        self.A = num(np.array([nm.Aq, nm.Ap]))
        self.B = num(np.array([nm.Bq, nm.Bp]))
        self.U, self.V = num(nm.U), num(nm.V)
        zero = nm.Aq * 0
        invertible = nm.Aq_inv is not None and nm.Ap_inv is not None
        self.Ainv = num(np.array([nm.Aq_inv, nm.Ap_inv]) if invertible else np.array([zero, zero]))
        self.E = num(nm.E if nm.E is not None else zero)
        first_is_increment = bool(nm.V[0, 0] == 1 and all(nm.V[0, k] == 0 for k in range(1, nm.r)))
        compensate = compensated and first_is_increment and self.kind != "dd"
        self.flags = np.zeros(L.N_FLAGS, dtype=np.int64)
        self.flags[[L.F_EXPLICIT, L.F_HAS_E, L.F_HAS_INV, L.F_COMPENSATE, L.F_MODE, L.F_HAS_JAC, L.F_PREDICT,
                    L.F_LOWER]] = (int(nm.explicit), int(nm.E is not None), int(invertible), int(compensate), mode, 1,
                                   int(predict), int(nm.lower))
        self.c = num(list(getattr(prob, "constants", ()))) if self.kind != "mp" else np.zeros(0)
        self.eps, self.tol = a.loop_tolerances()
        self.hA = nm.stage_scale(h)
        self.proj = np.array([index[k] for k in project], dtype=np.int64)
        self.target = num([targets[k] for k in project]) if project else self.empty()
        self.track = np.array([index[k] for k in track], dtype=np.int64)
        self.ttarget = num([targets[k] for k in track]) if track else self.empty()
        self.track_names = tuple(track)
        self.coefficients = Coefficients(self.A, self.U, self.B, self.V, self.cls, self.E, self.Ainv)
        self.controls = Controls(self.h, self.hinv, self.eps, self.tol, self.hA)
        self.problem_data = ProblemData(self.c, self.proj, self.target, self.track, self.ttarget)

    def num(self, x):
        if self.kind == "f64":
            return np.ascontiguousarray(np.asarray(x, dtype=float))
        if self.kind == "dd":
            from .ddmath import to_dd_array
            return to_dd_array(np.asarray(x, dtype=object))
        return np.asarray(x, dtype=object).copy()

    def scalar(self, x):
        if self.kind == "f64":
            return float(x)
        if self.kind == "dd":
            from .ddmath import to_dd
            return to_dd(x)
        return x

    def back(self, x):
        """Loop values → the working precision's numpy values (dd → mpmath at 32 digits)."""
        if self.kind == "dd":
            from .ddmath import from_dd_array
            return from_dd_array(x)
        return x.copy()

    def empty(self):
        return np.zeros((0, 2)) if self.kind == "dd" else np.zeros(0, dtype=object if self.kind == "mp" else float)

    def zeros(self, *shape):
        if self.kind == "mp":
            import mpmath
            return np.full(shape, mpmath.mpf(0), dtype=object)
        return np.zeros(shape + ((2,) if self.kind == "dd" else ()))


@dataclass
class Outcome:
    """What a loop did: status (stepcore.run's), the step it stopped at (failures), the final
    input vector at the working precision, counters and the tracked invariant errors."""
    status: int = 0
    step: int = 0
    Y: object = None
    nfev: int = 0
    nvel: int = 0
    sweeps: int = 0
    projection_iterations: int = 0
    fallbacks: int = 0
    completed: int = 0
    tracked: dict = field(default_factory=dict)
    projection_residual: float = 0.0
    last_correction: float = 0.0
    compile_seconds: float = 0.0
    switched_at: int | None = None      # the step after which a run went on another loop (drive's switch; the last)
    switched_to: str = ""               # … the loop specialised to it ("compiled") or the shared one ("linked")


class LoopState:
    """The arrays one run of a loop works on (input vector, Kahan carry, the ring of stage
    derivatives, counters, tracked maxima, records, the :func:`~.stepcore.workspace`) and the
    argument list of ``run`` and ``rescue_step``, written here once.  The flags are the pack's,
    copied: the loop changes them (history, mode)."""

    def __init__(self, loop, pk: Pack, Y, steps: int, every: int, track_every: int = 1, chunk: int | None = None):
        self.pk, self.steps, self.every, self.track_every = pk, steps, every, track_every
        self.Y = pk.num(Y).copy()              # the loop writes it: never the caller's array
        r, d = self.Y.shape[:2]
        s = pk.A.shape[1]
        self.flags = pk.flags.copy()
        self.comp, self.Fh = pk.zeros(d), pk.zeros(L.HISTORY, s, d)
        self.stats, self.tmax = np.zeros(L.N_STATS), np.zeros(len(pk.track))
        self.stages, self.work = loop.workspace(s, r, d, len(pk.proj))
        self.link(loop)
        self.records_for(chunk or steps)

    def link(self, loop, rescue: bool = False) -> None:
        """The problem's data for ``loop``: a linked loop takes its entry points as data (for a
        rescue step, the Jacobian's too)."""
        link = getattr(loop, "link", None)
        if link is not None:
            self.problem_data = link(self.pk.problem_data, rescue=rescue)
        elif not rescue:
            self.problem_data = self.pk.problem_data

    def records_for(self, chunk: int) -> None:
        """Room for the records of ``chunk`` steps per call (the records of the last call
        handed over: a switch to the compiled loop's longer chunks)."""
        slots = min(chunk, self.steps) // self.every + 2
        r, d = self.Y.shape[:2]
        self.rec, self.recn = self.pk.zeros(slots, r, d), np.zeros(slots, dtype=np.int64)
        self.state = State(self.Y, self.comp, self.Fh, self.flags, self.stats, self.tmax, self.rec, self.recn)

    def args(self, n0: int, n1: int) -> tuple:
        """The arguments of ``run`` and ``rescue_step`` over steps n0+1 … n1: the records of
        :mod:`stepcore` (:class:`~.stepcore.Span`, :class:`~.stepcore.State` …)."""
        return (Span(n0, n1, self.steps, self.every, self.track_every), self.state, self.pk.coefficients,
                self.pk.controls, self.problem_data, self.stages, self.work)


_NOTICED: set = set()          # loop modules whose compile was announced in this process


def notice(text: str) -> None:
    """One line on stderr, at once: the compile notices (here, :mod:`.background`)."""
    print(f"tableau-lab: {text}", file=sys.stderr, flush=True)


def cached_in(folder) -> str:
    """"one-off, cached in FOLDER" of a compile notice, the folder printable (it may come from
    the environment)."""
    from ..inputs import printable
    return f"one-off, cached in {printable(str(folder))}"


def _first_call_state(loop, entry: str):
    """"cold" or "cached" (:func:`compile_state`'s words) for the first call of ``loop.entry``
    in this process, read from numba's disk cache beside the loop's module; None when that is
    not known (a module without a file)."""
    path = getattr(loop, "__file__", None)
    return None if path is None else _disk_state(Path(path).parent, Path(path).stem, entry)


@contextlib.contextmanager
def _compile_notice(loop, entry: str = "run"):
    """Around the first call of ``loop.entry`` in this process: when numba's disk cache does
    not have it (:func:`_first_call_state` "cold"), one line on stderr before the compile, on a
    terminal or not — what is compiled (problem, arithmetic, shape), that it is once, where it is
    cached and about how long it takes (``COMPILE_COLD_SECONDS``) — once per loop per process,
    and on a terminal its time after it.  Nothing for a cache load.  When the state is not
    known, on a terminal only, a line after ``limits.COMPILE_NOTICE_SECONDS`` if it is still going."""
    state = _first_call_state(loop, entry)
    if state == "cached":
        yield
        return
    if state == "cold":
        if loop.__name__ not in _NOTICED:
            _NOTICED.add(loop.__name__)
            notice(f"compiling the step loop for {getattr(loop, 'described', loop.__name__)} — "
                   f"{cached_in(Path(loop.__file__).parent)} (about {L.COMPILE_COLD_SECONDS:.0f} s) ...")
        t0 = time.perf_counter()
        yield
        if sys.stderr.isatty():
            print(f"tableau-lab: compiled in {time.perf_counter() - t0:.1f} s", file=sys.stderr, flush=True)
        return
    with _late_notice():
        yield


@contextlib.contextmanager
def _late_notice():
    """On a terminal, a line once a compile of unknown state has taken ``COMPILE_NOTICE_SECONDS``,
    and its time at the end."""
    if not sys.stderr.isatty():
        yield
        return
    t0, said = time.perf_counter(), threading.Event()

    def notice():
        said.set()
        print("tableau-lab: compiling the step loop for this problem and method shape "
              "(once: it is cached on disk) ...", file=sys.stderr, flush=True)
    timer = threading.Timer(L.COMPILE_NOTICE_SECONDS, notice)
    timer.daemon = True
    timer.start()
    try:
        yield
    finally:
        timer.cancel()
        if said.is_set():
            print(f"tableau-lab: compiled in {time.perf_counter() - t0:.1f} s", file=sys.stderr, flush=True)


def drive(loop, pk: Pack, Y, steps: int, every: int, *, record, progress=None, track_every: int = 1,
          chunk: int | None = None, switch=None) -> Outcome:
    """Steps 1..steps of ``loop`` (a compiled module or a pure loop) from the input vector Y
    (r × d, working precision); ``record(n, Y)`` at the record steps, ``progress(n)`` after
    each chunk.  ``switch``: a function asked after each chunk, returning the compiled loop to go on
    with once it is ready (:mod:`.background`: a pure run onto a compiled loop, a linked run onto its
    specialised loop), else None.  Returns the
    :class:`Outcome`; an exception raised by ``record`` or Ctrl-C carries the outcome so far as
    ``exc.outcome``."""
    compiled = pk.kind != "mp" and loop.__name__ != "pure"
    chunk = chunk or (L.CHUNK if compiled else L.PURE_CHUNK)
    out = Outcome()
    t0 = time.perf_counter()
    st = LoopState(loop, pk, Y, steps, every, track_every, chunk)     # the workspace: compiled (or loaded) once
    stats = st.stats
    done = [0, False]                          # records of the current call handed over; inside record()

    def records():
        for k in range(done[0], int(stats[L.S_NREC])):
            done[0], done[1] = k + 1, True
            record(int(st.recn[k]), pk.back(st.rec[k]))
            done[1] = False

    def call(loop, entry, n0, n1):
        """loop.entry over steps n0+1 … n1; its first call in this process (numba compiles it
        or loads its cache; a rescue step is compiled only when one is needed) is counted in
        compile_seconds."""
        key = (loop.__name__, entry)
        fresh = compiled and key not in _COMPILE
        if fresh:
            t = time.perf_counter()
            with _compile_notice(loop, entry):
                if entry == "run":
                    loop.run(*st.args(n0, n0))          # no step: compiles
                else:
                    import numba
                    loop.rescue_step.compile(tuple(numba.typeof(x) for x in st.args(n0, n1)))
            _COMPILE[key] = time.perf_counter() - (t0 if entry == "run" and n0 == 0 else t)
            out.compile_seconds += _COMPILE[key]
        done[0] = 0
        status = int(getattr(loop, entry)(*st.args(n0, n1)))
        if status == L.MISFIT:                 # stepcore.fits: a bug here, not the user's input
            raise RuntimeError(f"{loop.__name__}.{entry}: the arrays do not fit the shape the loop was compiled for "
                               "(stepcore.fits)")
        records()
        return status

    n = 0
    try:
        while n < steps:
            n1 = min(steps, n + chunk)
            status = call(loop, "run", n, n1)
            if status == 4:                    # the stage iteration failed: the fallbacks, once
                n = int(stats[L.S_STEP])
                st.link(loop, rescue=True)     # a linked loop: the Jacobian's entry point too
                status = call(loop, "rescue_step", n - 1, n)
                if compiled and getattr(loop, "LOOP_MODE", L.ANY) not in (L.ANY, int(st.flags[L.F_MODE])):
                    loop = loop.sibling(int(st.flags[L.F_MODE]))   # the run switched to Newton
                if status == 0:
                    out.completed = n
                    _count(out, st)
                    continue
            out.completed = n1 if status == 0 else int(stats[L.S_STEP]) - 1
            n = out.completed
            _count(out, st)
            if status != 0:
                out.status, out.step = status, int(stats[L.S_STEP])
                break
            if progress is not None:
                progress(n)
            if switch is not None and n < steps and (ready := _switched(switch, st, out, n)) is not None:
                loop, compiled, chunk = ready, True, L.CHUNK
    except BaseException as exc:
        _stopped(out, st, done, records)
        exc.outcome = out
        raise
    out.Y = pk.back(st.Y)
    return out


def _switched(switch, st: LoopState, out: Outcome, n: int):
    """The compiled loop a pure run goes on with after step ``n`` (``switch()`` of :func:`drive`,
    None: stay), its problem data linked and room made for its longer chunks' records."""
    ready = switch() if switch is not None else None
    if ready is not None:
        out.switched_at, out.switched_to = n, ("linked" if hasattr(ready, "link") else "compiled")
        st.link(ready)
        st.records_for(L.CHUNK)
    return ready


def _stopped(out: Outcome, st: LoopState, done: list, records) -> None:
    """The outcome of a run stopped by an exception: raised by ``record`` (``done[1]``), it
    stops at that record; Ctrl-C in the pure loop or between calls keeps the records so far
    and the last step finished."""
    if done[1]:
        out.completed = int(st.recn[done[0] - 1])
    else:
        out.completed = max(out.completed, int(st.stats[L.S_DONE]))
        with contextlib.suppress(BaseException):
            records()
    _count(out, st)


def _count(out, st: LoopState):
    stats, tmax, pk = st.stats, st.tmax, st.pk
    out.nfev, out.nvel, out.sweeps = int(stats[L.S_NFEV]), int(stats[L.S_NVEL]), int(stats[L.S_SWEEPS])
    out.projection_iterations, out.fallbacks = int(stats[L.S_PROJ]), int(stats[L.S_FALLBACKS])
    out.projection_residual, out.last_correction = float(stats[L.S_PROJ_RES]), float(stats[L.S_LAST])
    out.tracked = {k: float(v) for k, v in zip(pk.track_names, tmax, strict=False)}
