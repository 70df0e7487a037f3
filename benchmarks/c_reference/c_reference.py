"""The C reference of the float64 step loop: glm_loop.c, plain C99 compiled with gcc (CFLAGS), the
same algorithm as ``tableau_lab/numeric/stepcore.py`` (explicit stages; the stage iteration
SPLIT, NEWTON or FIXED with the history predictor; Kahan summation; the same counters), to
measure the numba loop against and to check that the two compute the same thing.  A benchmark
fixture, not part of the package (``tableau-lab bench`` loads it from a source checkout).

What both loops get is what ``integrate`` gives the compiled loop: the arrays of
``kernels.Pack`` (the method, h, the component classes, the flags with the stage-iteration mode
of ``integrate.stage_iteration`` and the Kahan switch), and y^[0] = ``integrate.start_values``.
The C program is specialised like the numba loop: the shape (s, r, d) is compile-time
(``-DS -DR -DD``), stepcore's limits (``limits.py``) and the problem's f, Jacobian and (for a
separable problem) q- and p-rates are C headers generated here, the latter printed from the
problem's sympy expressions (the same CSE and the same powers-as-products as the numba code of
``problem_code.py``), so every built-in problem runs.  glm_loop.c is built twice from the same
source, flags and headers: as a shared library (``-shared -fPIC -DGLM_LIBRARY``) whose entry
``glm_run`` :func:`run_c` calls IN PROCESS through ctypes (the numpy arrays passed by
``ndarray.ctypes``; the default, ``inprocess=True``), and as an executable whose main() reads
the arrays from a text file and calls the same ``glm_run`` (``inprocess=False``, and
:func:`c_functions`).  One library and one executable per (problem, shape, sources, flags) under
build/, each built once (atomic rename); a library is loaded once per process and keeps no
state between calls (glm_run zeroes all its static work at every call).  Not in C: projection, invariant
tracking, records and the fallbacks of a failed stage iteration (the C loop stops with
status 4 where the Python driver would redo the step).

    run_c(method_path, problem, h, steps, reps=5, *, solver="auto", start="exact",
          compensated=True, check_status=True, mode=None, cflags=None, inprocess=True, cc="gcc")
        -> dict(us_per_step, us_per_step_min, final, nfev, sweeps, seconds, seconds_all,
                status, completed, nvel, mode, shape)
    run_numba(...)        the same, from the compiled numba loop's ``run`` called directly
    c_functions(problem, points) -> dict(f, jac[, fq, fp]) of the generated C functions

``final`` is the raw input vector y^[steps] (r × d), not passed through the finishing method.
nfev counts f-evaluations (in SPLIT: force evaluations fp; nvel the velocity evaluations fq),
sweeps the stage-iteration sweeps.  Timings: the median (and min) over ``reps`` whole runs of
the step loop alone — C: CLOCK_MONOTONIC inside glm_run around the loop (in process through
ctypes, or in the executable: the same code, comparable µs/step); numba: perf_counter around
the ``run`` call, compiled before (not timed).

Run: python benchmarks/c_reference/c_reference.py [--steps N] [--reps R] [--no-numba] [--cflags "-O3 -march=native ..."]
"""
from __future__ import annotations

import argparse
import ctypes
import hashlib
import importlib.util
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import sympy as sp
from sympy.printing.c import C99CodePrinter

from tableau_lab.exact.tableau_json import load
from tableau_lab.numeric import limits
from tableau_lab.numeric.codegen import compile_problem
from tableau_lab.numeric.export import to_numeric
from tableau_lab.numeric.integrate import component_masks, stage_iteration, start_values
from tableau_lab.numeric.kernels import DENSE, LoopState, Pack, compiled_loop, dense_matrices, run_shape
from tableau_lab.numeric.problem_code import cse_entries
from tableau_lab.numeric.problems import get_problem

__all__ = ["run_c", "run_numba", "c_functions", "build", "library", "prepare", "problem_header", "limits_header",
           "CASES", "CFLAGS"]

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
SOURCE = HERE / "glm_loop.c"
BUILD = HERE / "build"
CFLAGS = ("-O3", "-march=native", "-std=c99", "-ffp-contract=off")   # the fastest; no FMA contraction: numba has none
MODE_NAMES = {limits.NEWTON: "newton", limits.FIXED: "fixed", limits.SPLIT: "split"}

# (method, problem, h, steps or None for --steps): the table of main() and the cases of check.py
CASES = tuple([(m, p, 0.01, 500 if (m, p) == ("example4_glm", "kepler") else None)
               for m in ("gauss2", "gauss3", "implicit_midpoint", "rk4", "example4_glm", "glm43")
               for p in ("pendulum", "kepler")]
              + [("gauss2", "fpu", 0.001, None), ("gauss2", "outer_solar_system", 10.0, None)])
NOTES = {("example4_glm", "kepler"): "parasitism: blows up after some hundred steps; 500 steps only"}


# -- generated C ------------------------------------------------------------------------------------

class _CPrinter(C99CodePrinter):
    """C with the powers of problem_code._Printer (the numba code): integer powers 1..8 as
    products, half-integer powers as products of square roots, larger integer powers by
    squaring as numba's ``x**k`` (tl_ipow), every other power pow() (never cbrt)."""

    def _print_Pow(self, e, rational=False):
        b, x = e.base, e.exp
        if x.is_Integer and 1 <= abs(int(x)) <= 8:
            prod = "(" + "*".join([self.parenthesize(b, 100)] * abs(int(x))) + ")"
            return prod if x > 0 else f"(1.0/{prod})"
        if x.is_Integer and x != 0:
            return f"tl_ipow({self._print(b)}, {int(x)})"
        if x.is_Rational and x.q == 2:
            root = f"sqrt({self._print(b)})"
            k = abs(int(x.p))
            prod = "(" + ("*".join([root] * k) if k <= 8 else f"tl_ipow({root}, {k})") + ")"
            return prod if x > 0 else f"(1.0/{prod})"
        return f"pow({self._print(b)}, {self._print(x)})"


_IPOW = """\
/* x**k as numba computes a float to a literal integer power: by squaring, then 1/r if k < 0 */
static inline double tl_ipow(double a, int k)
{
    int e = k < 0 ? -k : k;
    double r = 1.0;
    while (e != 0) {
        if (e & 1)
            r *= a;
        e >>= 1;
        a *= a;
    }
    return k < 0 ? 1.0 / r : r;
}
"""


def _c_function(name, state, params, exprs, at=None) -> str:
    """``static inline void name(y, c, out)``: problem_code.function_source in C — the same
    symbols, the same CSE — writing out[at[k]] (a list) or out[i*d + j] (rows, row-major)."""
    temps, reduced, width = cse_entries(state, params, exprs)
    p = _CPrinter()
    lines = [f"static inline void {name}(const double *restrict y, const double *restrict c, double *restrict out)",
             "{", "    (void)y;", "    (void)c;"]
    lines += [f"    const double {t} = {p.doprint(v)};" for t, v in temps]
    for k, v in enumerate(reduced):
        where = k if width else (at[k] if at else k)
        lines.append(f"    out[{where}] = {p.doprint(v)};")
    return "\n".join(lines + ["}"]) + "\n"


_HEADERS: dict = {}


def problem_header(problem) -> str:
    """The C header of a problem (a name or a Problem): f_(y, c, out) (out: row i of F),
    jac_(y, c, out) (d × d row-major) and, if separable, fq_ / fp_ (their components of the
    row only), from the sympy expressions; TL_PROBLEM_D, TL_PROBLEM_NC, TL_PROBLEM_SEPARABLE."""
    P = get_problem(problem)
    if P.key in _HEADERS:
        return _HEADERS[P.key]
    state, params = list(P.state), list(P.parameter_symbols.values())
    f = list(P.f_expr)
    parts = [f"/* generated by benchmarks/c_reference/c_reference.py from the sympy expressions of problem "
             f"{P.name!r}: do not edit */",
             "/* needs <math.h>: glm_loop.c includes it first */",
             f"#define TL_PROBLEM_D {len(state)}", f"#define TL_PROBLEM_NC {len(params)}",
             f"#define TL_PROBLEM_SEPARABLE {int(bool(P.separable))}",
             _IPOW,
             _c_function("f_", state, params, f),
             _c_function("jac_", state, params, sp.Matrix(f).jacobian(state).tolist())]
    if P.separable:
        k = len(P.q)
        parts += [_c_function("fq_", state, params, f[:k], list(range(k))),
                  _c_function("fp_", state, params, f[k:], list(range(k, 2 * k)))]
    _HEADERS[P.key] = "\n".join(parts) + "\n"
    return _HEADERS[P.key]


def _c_number(v) -> str:
    return repr(float(v)) if isinstance(v, float) else str(int(v))


def limits_header() -> str:
    """stepcore's constants (tableau_lab/numeric/limits.py) as C: every upper-case number, and
    the tuples of numbers as static const double arrays."""
    lines = ["/* generated by benchmarks/c_reference/c_reference.py from tableau_lab/numeric/limits.py: "
             "do not edit */", "#define TL_LIMITS_H 1"]
    for name in limits.__all__:
        v = getattr(limits, name, None)
        if isinstance(v, bool) or not name.isupper():
            continue
        if isinstance(v, (int, float)):
            lines.append(f"#define {name} ({_c_number(v)})")
        elif isinstance(v, tuple) and v and all(isinstance(x, (int, float)) for x in v):
            lines.append(f"static const double {name}[{len(v)}] = {{{', '.join(repr(float(x)) for x in v)}}};")
    return "\n".join(lines) + "\n"


# -- build --------------------------------------------------------------------------------------------

_CC: dict = {}
COMPILERS = ("gcc", "clang")               # gcc: the reference; clang: the same C through LLVM (numba's backend)


def _compiler(cc="gcc") -> tuple:
    """(command as a list, first line of its --version) of ``cc``: ``gcc``, or ``clang`` (on PATH,
    else the clang of the ``ziglang`` wheel: ``pip install ziglang``, ``python -m ziglang cc``)."""
    if cc not in COMPILERS:
        raise ValueError(f"compiler {cc!r}: one of {', '.join(COMPILERS)}")
    if cc not in _CC:
        exe = shutil.which(cc)
        if exe is not None:
            cmd = [exe]
        elif cc == "clang" and importlib.util.find_spec("ziglang") is not None:
            cmd = [sys.executable, "-m", "ziglang", "cc"]
        else:
            raise RuntimeError(f"{cc} not found" + (" (nor the ziglang package)" if cc == "clang" else ""))
        version = subprocess.run([*cmd, "--version"], check=True, capture_output=True, text=True).stdout
        _CC[cc] = (cmd, version.splitlines()[0] if version else "")
    return _CC[cc]


def _write_atomic(path: Path, text: str):
    if path.exists():
        return
    tmp = path.with_name(f".{path.name}.{os.getpid()}")
    tmp.write_text(text)
    os.replace(tmp, path)


def build(problem="pendulum", shape=(1, 1, 2), cflags=None, shared=False, cc="gcc", dense=()) -> Path:
    """The glm_loop executable (``shared=True``: the shared library, ``-shared -fPIC
    -DGLM_LIBRARY``, for ctypes) of ``problem`` for the method shape (s, r, d) and, as the numba
    loop, which of the method's matrices have no zero (``kernels.dense_matrices``:
    ``-DDENSE_A=..`` …; () for none known), compiled with ``cc`` (:data:`COMPILERS`) and ``cflags``
    (default CFLAGS) once, cached under build/ by a hash of glm_loop.c, the generated headers, the
    shape, the dense flags, the flags, the kind and the compiler's version.  (Without arguments: the pendulum at s = r =
    1, a check that gcc works.)"""
    P = get_problem(problem)
    s, r, d = (int(x) for x in shape)
    if d != P.dimension:
        raise ValueError(f"problem {P.name!r} has dimension {P.dimension}, not d = {d}")
    compiler, version = _compiler(cc)
    flags = tuple(CFLAGS if cflags is None else cflags)
    lim, prob = limits_header(), problem_header(P)
    kind = ("-shared", "-fPIC", "-DGLM_LIBRARY") if shared else ()
    if dense and len(dense) != len(DENSE):
        raise ValueError(f"dense: {len(DENSE)} flags, not {len(dense)}")
    known = tuple(f"-D{name}={int(dense)}" for name, dense in zip(DENSE, dense, strict=False))
    digest = hashlib.sha256(b"\0".join([SOURCE.read_bytes(), lim.encode(), prob.encode(),
                                        f"{s} {r} {d} {' '.join(flags)} {version} {cc}".encode()]
                                       + ([" ".join(known).encode()] if known else [])
                                       + ([" ".join(kind).encode()] if shared else []))).hexdigest()[:16]
    tag = "".join(ch if ch.isalnum() or ch in "_-" else "_" for ch in P.name)
    cct = "" if cc == "gcc" else f"{cc}_"
    stem = f"glm_loop_{cct}{tag}_{s}x{r}x{d}_{digest}"
    exe = BUILD / (f"lib{stem}.so" if shared else stem)
    if exe.exists():
        return exe
    BUILD.mkdir(parents=True, exist_ok=True)
    lim_h = BUILD / f"limits_{hashlib.sha256(lim.encode()).hexdigest()[:12]}.h"
    prob_h = BUILD / f"problem_{tag}_{hashlib.sha256(prob.encode()).hexdigest()[:12]}.h"
    _write_atomic(lim_h, lim)
    _write_atomic(prob_h, prob)
    tmp = BUILD / f".{exe.name}.{os.getpid()}"
    cmd = [*compiler, *flags, *kind, f"-DS={s}", f"-DR={r}", f"-DD={d}", *known, f'-DTL_LIMITS_HEADER="{lim_h}"',
           f'-DTL_PROBLEM_HEADER="{prob_h}"',
           "-o", str(tmp), str(SOURCE), "-lm"]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        raise RuntimeError(f"{cc} failed ({' '.join(cmd)}):\n{res.stderr}")
    os.replace(tmp, exe)                   # atomic: concurrent builds do not see a half-written file
    return exe


_LIBS: dict = {}
_NSTATS = 6                                # glm_run's stats: status, completed, step, nfev, sweeps, nvel


def library(problem="pendulum", shape=(1, 1, 2), cflags=None, cc="gcc", dense=()) -> ctypes.CDLL:
    """The shared library of :func:`build` (``shared=True``) loaded by ctypes, once per path and
    process, with the argument types of glm_run / glm_functions / glm_shape set, its compiled
    shape checked.  Each (problem, shape, flags) is its own file, loaded RTLD_LOCAL: the
    libraries' equal symbol names do not clash."""
    path = build(problem, shape, cflags, shared=True, cc=cc, dense=dense)
    key = str(path)
    if key not in _LIBS:
        lib = ctypes.CDLL(key)
        f64 = np.ctypeslib.ndpointer(dtype=np.float64, flags="C_CONTIGUOUS")
        i64 = np.ctypeslib.ndpointer(dtype=np.int64, flags="C_CONTIGUOUS")
        lib.glm_shape.argtypes, lib.glm_shape.restype = [i64], None
        lib.glm_run.argtypes = [f64, i64, f64, f64, f64, f64, f64, i64, f64, f64, ctypes.c_int64, ctypes.c_int64,
                                f64, i64, f64]
        lib.glm_run.restype = ctypes.c_int
        lib.glm_functions.argtypes, lib.glm_functions.restype = [f64] * 6, None
        got = np.zeros(6, dtype=np.int64)
        lib.glm_shape(got)
        s, r, d = (int(x) for x in shape)
        if tuple(got[:4]) != (s, r, d, limits.N_FLAGS) or int(got[5]) != _NSTATS:
            raise RuntimeError(f"{path.name}: compiled shape {tuple(got)} is not ({s}, {r}, {d}, {limits.N_FLAGS})")
        _LIBS[key] = lib
    return _LIBS[key]


# -- the arrays both loops get ------------------------------------------------------------------------

def _method_path(method_path) -> Path:
    p = Path(method_path)
    if p.exists():
        return p
    for cand in (ROOT / p, ROOT / "methods" / f"{p}.json", ROOT / "methods" / p):
        if cand.exists():
            return cand
    raise FileNotFoundError(f"method {method_path!r}: no such file (nor under {ROOT / 'methods'})")


_NUMERIC: dict = {}


class Prepared:
    """The numeric method, the compiled problem, the Pack arrays (as integrate makes them for
    the compiled loop, without projection or tracking), y^[0] and the shape."""

    def __init__(self, method_path, problem, h, solver="auto", start="exact", compensated=True, mode=None):
        path = _method_path(method_path).resolve()
        if path not in _NUMERIC:
            _NUMERIC[path] = to_numeric(load(str(path)))
        self.nm = nm = _NUMERIC[path]
        self.cp = cp = compile_problem(problem)
        self.h = h = float(h)
        d = len(cp.y0)
        self.shape = (nm.s, nm.r, d)
        a = nm.arith
        with a.context():
            masks = component_masks(cp, d)
            # mode=None: integrate's choice; else forced (check.py: FIXED, which no separable problem gets)
            self.mode = stage_iteration(solver, nm, cp, cp.y0, h, d) if mode is None else int(mode)
            self.pk = Pack(nm, cp, h, masks, mode=self.mode, compensated=compensated)
            self.dense = dense_matrices(self.pk)       # the numba loop's (kernels.run_shape)
            self.Y0 = np.ascontiguousarray(np.asarray(start_values(nm, cp, cp.y0, h, start), dtype=float))


def prepare(method_path, problem, h, solver="auto", start="exact", compensated=True, mode=None) -> Prepared:
    return Prepared(method_path, problem, h, solver, start, compensated, mode)


def _line(key, values) -> str:
    values = np.asarray(values, dtype=float).reshape(-1)
    return f"{key} {values.size} " + " ".join(f"{float(x):.17g}" for x in values)


def _input_text(pr: Prepared, steps, reps) -> str:
    pk = pr.pk
    return "\n".join([
        _line("shape", pr.shape), _line("mode", [0]), _line("reps", [reps]), _line("steps", [steps]),
        _line("h", [pk.h]), _line("hinv", [pk.hinv]), _line("eps", [pk.eps]), _line("hA", [pk.hA]),
        _line("flags", pk.flags), _line("c", pk.c), _line("A", pk.A), _line("U", pk.U), _line("B", pk.B),
        _line("V", pk.V), _line("cls", pk.cls), _line("E", pk.E), _line("Ainv", pk.Ainv), _line("Y", pr.Y0)]) + "\n"


def _run_exe(exe: Path, text: str) -> dict:
    with tempfile.NamedTemporaryFile("w", suffix=".txt", prefix="glm_input_", delete=False) as fh:
        fh.write(text)
        path = fh.name
    try:
        res = subprocess.run([str(exe), path], capture_output=True, text=True)
    finally:
        os.unlink(path)
    if res.returncode != 0:
        raise RuntimeError(f"{exe.name} failed (exit {res.returncode}): {res.stderr.strip()}")
    parsed: dict = {}
    for ln in res.stdout.splitlines():
        key, *rest = ln.split()
        parsed.setdefault(key, []).append(rest)
    return parsed


_WHY = {1: "the stage equations were not solved", 2: "the state is not finite",
        4: "the stage iteration failed (the Python driver would redo the step by its fallbacks)"}


def _result(times, steps, final, stats, status, completed, pr) -> dict:
    seconds = float(np.median(times))
    return dict(us_per_step=seconds / steps * 1e6, us_per_step_min=min(times) / steps * 1e6, final=final,
                nfev=int(stats[0]), sweeps=int(stats[1]), nvel=int(stats[2]), seconds=seconds,
                seconds_all=list(times), status=int(status), completed=int(completed),
                mode=MODE_NAMES.get(pr.mode, str(pr.mode)) if not pr.nm.explicit else "explicit", shape=pr.shape)


def _check(status, completed, what, method_path, problem, check_status):
    if status != 0 and check_status:
        raise RuntimeError(f"{method_path} on {problem}: the {what} loop stopped at step {completed + 1}: "
                           f"{_WHY.get(status, f'status {status}')}")


def _run_lib(pr: Prepared, steps, reps, cflags, cc="gcc") -> tuple:
    """glm_run of the problem's shared library, in this process: (status, completed, final,
    [nfev, sweeps, nvel], seconds of each rep)."""
    (s, r, d), pk = pr.shape, pr.pk
    lib = library(pr.cp.problem, pr.shape, cflags, cc, pr.dense)

    def f64(x):
        return np.ascontiguousarray(x, dtype=np.float64).reshape(-1)

    def i64(x):
        return np.ascontiguousarray(x, dtype=np.int64).reshape(-1)

    args = dict(consts=f64([pk.h, pk.hinv, pk.eps, pk.hA]), flags=i64(pk.flags), c=f64(pk.c), A=f64(pk.A),
                U=f64(pk.U), B=f64(pk.B), V=f64(pk.V), cls=i64(pk.cls), E=f64(pk.E), Ainv=f64(pk.Ainv))
    want = dict(consts=4, flags=limits.N_FLAGS, c=len(pr.cp.constants), A=2 * s * s, U=s * r, B=2 * r * s, V=r * r,
                cls=d, E=s * s, Ainv=2 * s * s)
    for k, n in want.items():              # C reads exactly these counts: never past an array's end
        if args[k].size != n:
            raise ValueError(f"{k}: {args[k].size} values, the library of shape {pr.shape} reads {n}")
    Y = f64(pr.Y0).copy()
    if Y.size != r * d:
        raise ValueError(f"Y: {Y.size} values, expected {r * d}")
    stats, seconds = np.zeros(_NSTATS, dtype=np.int64), np.zeros(reps)
    status = lib.glm_run(*args.values(), steps, reps, Y, stats, seconds)
    if status < 0:
        raise RuntimeError(f"glm_run: bad arguments ({pr.cp.problem}, shape {pr.shape})")
    return int(stats[0]), int(stats[1]), Y.reshape(r, d), [int(x) for x in stats[3:6]], [float(x) for x in seconds]


def run_c(method_path, problem, h, steps, reps=5, *, solver="auto", start="exact", compensated=True,
          check_status=True, mode=None, cflags=None, inprocess=True, cc="gcc") -> dict:
    """The C loop: ``reps`` whole runs of ``steps`` steps from y^[0]; the median time.  By
    default in this process: glm_run of the shared library (:func:`library`) through ctypes;
    ``inprocess=False``: the executable, the arrays through a text file (the same glm_run, the
    same timing inside C around the step loop alone; bit-identical results).  A stopped run
    (status 2: not finite, 4: the stage iteration failed) raises RuntimeError unless
    ``check_status=False``.  ``mode``: force a stage-iteration mode (limits.NEWTON, FIXED,
    SPLIT) instead of integrate's choice; ``cflags``: compiler flags instead of CFLAGS; ``cc``: the
    compiler (:data:`COMPILERS`; gcc, the reference)."""
    steps, reps = int(steps), int(reps)
    if steps < 1:
        raise ValueError("steps must be positive")
    if reps < 1:
        raise ValueError("reps must be positive")
    pr = prepare(method_path, problem, h, solver, start, compensated, mode)
    if inprocess:
        status, completed, final, stats, times = _run_lib(pr, steps, reps, cflags, cc)
        _check(status, completed, "C", method_path, problem, check_status)
        return _result(times, steps, final, stats, status, completed, pr)
    out = _run_exe(build(pr.cp.problem, pr.shape, cflags, cc=cc, dense=pr.dense), _input_text(pr, steps, reps))
    status, completed = int(out["status"][0][0]), int(out["completed"][0][0])
    _check(status, completed, "C", method_path, problem, check_status)
    final = np.array([float(x) for x in out["final"][0][1:]]).reshape(pr.shape[1], pr.shape[2])
    stats = [int(out[k][0][0]) for k in ("nfev", "sweeps", "nvel")]
    return _result([float(x) for x in out["seconds_all"][0][1:]], steps, final, stats, status, completed, pr)


def run_numba(method_path, problem, h, steps, reps=5, *, solver="auto", start="exact", compensated=True,
              check_status=True, mode=None) -> dict:
    """The compiled numba loop's ``run`` called directly with the same arrays, as kernels.drive
    calls it, in one chunk (n0 = 0, n1 = every = steps; no projection, no tracking; the
    workspace allocated once); compiled first (not timed).  The same dict as :func:`run_c`."""
    steps = int(steps)
    if steps < 1:
        raise ValueError("steps must be positive")
    pr = prepare(method_path, problem, h, solver, start, compensated, mode)
    pk = pr.pk
    loop = compiled_loop(pr.cp.problem, "f64", run_shape(pk))

    def call(n1):
        st = LoopState(loop, pk, pr.Y0, steps, steps)       # kernels.drive's arrays and argument list
        t0 = time.perf_counter()
        status = loop.run(*st.args(0, n1))
        return time.perf_counter() - t0, int(status), st.Y, st.stats

    call(0)                                 # compile, or load numba's cache: not timed
    times = []
    for _ in range(int(reps)):
        seconds, status, Y, stats = call(steps)
        times.append(seconds)
    completed = steps if status == 0 else int(stats[limits.S_STEP]) - 1
    _check(status, completed, "numba", method_path, problem, check_status)
    counts = [stats[limits.S_NFEV], stats[limits.S_SWEEPS], stats[limits.S_NVEL]]
    return _result(times, steps, Y, counts, status, completed, pr)


def c_functions(problem, points, cflags=None) -> dict:
    """The generated C functions at each point (k × d): dict(f, jac (k × d × d), and for a
    separable problem fq, fp: their own components, NaN elsewhere)."""
    P = get_problem(problem)
    cp = compile_problem(P)
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    d = P.dimension
    exe = build(P, (1, 1, d), cflags)
    text = "\n".join([_line("shape", [1, 1, d]), _line("mode", [1]), _line("c", cp.constants),
                      _line("points", pts)]) + "\n"
    out = _run_exe(exe, text)
    res = {k: np.array([[float(x) for x in row[1:]] for row in out[k]]) for k in ("f", "jac", "fq", "fp") if k in out}
    res["jac"] = res["jac"].reshape(-1, d, d)
    return res


# -- the table ----------------------------------------------------------------------------------------

def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, default=100000)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--no-numba", action="store_true", help="the C columns only")
    ap.add_argument("--cflags", default=" ".join(CFLAGS), help=f"gcc flags (default: {' '.join(CFLAGS)})")
    args = ap.parse_args(argv)
    cflags = tuple(args.cflags.split())
    print(f"{args.steps} steps (h as listed), median of {args.reps} runs of the step loop alone; C: gcc "
          f"{' '.join(cflags)}; numba/C: ratio of the medians; nfev/step: f-evaluations (split: force "
          f"evaluations); max|dY|: raw final input vectors.  Indicative timings: other processes share the cores.")
    head = (f"{'method':<18} {'problem':<19} {'h':>6} {'steps':>7} {'mode':>8} {'C us/step':>10} "
            f"{'nfev/st C':>9}")
    if not args.no_numba:
        head += f" {'numba us/step':>13} {'numba/C':>7} {'nfev/st nb':>10} {'max|dY|':>9}"
    print(head)
    for method, problem, h, n in CASES:
        steps = min(args.steps, n) if n else args.steps
        path = ROOT / "methods" / f"{method}.json"
        c = run_c(path, problem, h, steps, args.reps, check_status=False, cflags=cflags)
        row = (f"{method:<18} {problem:<19} {h:>6g} {steps:>7} {c['mode']:>8} {c['us_per_step']:>10.3f} "
               f"{c['nfev'] / steps:>9.2f}")
        if not args.no_numba:
            nb = run_numba(path, problem, h, steps, args.reps, check_status=False)
            diff = float(np.max(np.abs(nb["final"] - c["final"])))
            row += (f" {nb['us_per_step']:>13.3f} {nb['us_per_step'] / c['us_per_step']:>7.2f} "
                    f"{nb['nfev'] / steps:>10.2f} {diff:>9.2e}")
        notes = [NOTES[method, problem]] if (method, problem) in NOTES else []
        if c["status"]:
            notes.append(f"C stopped at step {c['completed'] + 1}: {_WHY.get(c['status'], c['status'])}")
        print(row + ("  (" + "; ".join(notes) + ")" if notes else ""), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
