"""The hostile-input corpus of the command line (issue 16): each case a command, the files it
reads and what must happen — the exit code and a fragment of the message (the file, entry or
option named).  Read by tests/test_hostile_cli.py (every case, in process) and by
benchmarks/hostile_table.py (every case as a user runs it, in a subprocess with a time limit:
the table of docs/reliability.md).  ``{d}`` in an argument is the case's own folder."""
from __future__ import annotations

import contextlib
import io
import json
import os
import tempfile
import time
from pathlib import Path
from typing import NamedTuple

SLACK = 5.0          # seconds a case may take beyond its --timeout (issue 16: budget + 5 s)


class Case(NamedTuple):
    id: str
    surface: str            # what is attacked: entry, method file, cli number, require, repair, budget
    category: str           # injection, not a number, unicode, size, shape, range, hang
    argv: tuple
    files: dict             # name -> text
    exit: int
    fragment: str           # in stderr (case-insensitive)


def run_case(case, main) -> dict:
    """Run ``case`` through ``main`` (tableau_lab.cli.main) in this process, in a fresh folder that
    is also the working directory: exit code, stderr, seconds, the time budget, the files added
    beside the inputs, and whether an injection created its marker file."""
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        for name, text in case.files.items():
            (d / name).write_text(text, encoding="utf-8", errors="surrogatepass")
        before = set(d.rglob("*"))
        argv = [a.replace("{d}", str(d)) for a in case.argv]
        budget = float(argv[argv.index("--timeout") + 1]) if "--timeout" in argv[:2] else 60.0
        err, cwd = io.StringIO(), os.getcwd()
        os.chdir(d)
        t0 = time.perf_counter()
        try:
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                try:
                    code = main(argv)
                except SystemExit as exc:            # argparse's refusals
                    code = exc.code
        finally:
            os.chdir(cwd)
        return {"code": code, "err": err.getvalue(), "seconds": time.perf_counter() - t0, "budget": budget,
                "added": sorted(str(p.relative_to(d)) for p in set(d.rglob("*")) - before),
                "executed": (d / "PWNED").exists() or Path("PWNED").exists()}


def rk(A, b=None, c=None, **extra) -> str:
    s = len(A)
    return json.dumps({"format": "tableau_lab/1", "name": extra.pop("name", "hostile"), "kind": "rk", "A": A,
                       "b": b or ["1"] + ["0"] * (s - 1), "c": c or ["0"] * s, **extra}, ensure_ascii=False)


def _entry_case(cid, category, entry, fragment, command="verify", exit=2):
    """A 1-stage RK whose only A entry (and c, equal to it when it parses) is ``entry``."""
    return Case(cid, "entry", category, (command, "{d}/m.json"), {"m.json": rk([[entry]], c=[entry])}, exit, fragment)


INJECTION = ["__import__('os').system('touch PWNED')", "exec('1')", "eval('1')", "open('x').read()",
             "lambda: 0", "sp.pi", "a.b", "x[0]", "{}", "`ls`", "$(ls)", "1;2", "1 if 1 else 0", "import os",
             "globals()", "getattr(1, 'real')", "__builtins__", "x = 1", "S.One", "Symbol('x')",
             "Integer(1)", "1 # comment", "'1'", '"1"', "1 and 2", "not 1", "[1]", "(1, 2)", "1 @ 2", "~1", "1 % 2",
             "1 // 2", "1 << 2", "1 & 2", "1 | 2", "1 == 1", "x.__class__", "Rational(1, 2)", "sympify('1')",
             "N(1)"]
NOT_NUMBERS = ["nan", "NaN", "inf", "-inf", "Infinity", "oo", "zoo", "E", "I", "j", "None", "True", "1/0",
               "0**-1", "(-1)**(1/2)", "sqrt(-2)", "1e999999", "0.5", "1e-3", "", " ", "+", "1/", "(1", "1)",
               "sqrt()", "sqrt(1, 2)", "cos(1)", "cos(pi/1000)", "sin(pi*x)", "pi", "root(x**2 + 1, 1)",
               "root(x**2 - 2, 3)", "root(x**100 - 2, 1)", "root(x - 1, 0)", "root(2, 1)", "foo(1)"]
UNICODE = ["١/٢", "１/2", "½", "²", "1\u00a0/2", "x\u200b", "1\u202e/2", "\u0661", "1\x1b[2J", "1\x00", "𝟏",
           "ⅰ", "x\u0301", "ｘ"]
SIZE = ["9" * 5000, "1" + "+1" * 6000, "(" * 100 + "1" + ")" * 100, "-" * 200 + "1", "2**100000",
        "(2**64)**(2**64)", "sqrt(2+sqrt(2+sqrt(2+sqrt(2+sqrt(2+sqrt(2))))))", "x" * 10001,
        "sqrt(" * 70 + "2" + ")" * 70, "1/" + "9" * 200, "10**(10**10)"]

CASES = []
CASES += [_entry_case(f"inject-{i}", "injection", e, "m.json") for i, e in enumerate(INJECTION)]
CASES += [_entry_case(f"notnum-{i}", "not a number", e, "m.json") for i, e in enumerate(NOT_NUMBERS)]
CASES += [_entry_case(f"unicode-{i}", "unicode", e, "m.json") for i, e in enumerate(UNICODE)]
CASES += [_entry_case(f"size-{i}", "size", e, "m.json") for i, e in enumerate(SIZE)]
CASES += [_entry_case(f"inject-order-{i}", "injection", e, "m.json", "order") for i, e in enumerate(INJECTION[:5])]
CASES += [_entry_case(f"inject-stability-{i}", "injection", e, "m.json", "stability") for i, e in enumerate(INJECTION[:5])]

# the shape and kind of a method file
SHAPES = {
    "ragged": rk([["0", "0"], ["1"]]), "b-short": rk([["0", "0"], ["1", "0"]], b=["1"]),
    "kind": json.dumps({"format": "tableau_lab/1", "name": "x", "kind": "rocket", "A": [["0"]], "b": ["1"], "c": ["0"]}),
    "format": json.dumps({"format": "tableau_lab/99", "name": "x", "kind": "rk", "A": [["0"]], "b": ["1"], "c": ["0"]}),
    "no-A": json.dumps({"format": "tableau_lab/1", "name": "x", "kind": "rk", "b": ["1"], "c": ["0"]}),
    "A-number": rk([[0.5]]), "A-string": json.dumps({"format": "tableau_lab/1", "name": "x", "kind": "rk", "A": "0",
                                                    "b": ["1"], "c": ["0"]}),
    "A-null": rk([[None]]), "A-bool": rk([[True]]), "A-nested": rk([[["0"]]]), "empty-A": rk([]),
    "list": "[1, 2]", "string": '"rk"', "empty": "", "not-json": "{'A': 1}", "truncated": rk([["0"]])[:-5],
    "claims-bad": rk([["0"]], claims={"order": "four"}), "claims-unknown": rk([["0"]], claims={"fast": True}),
    "name-number": json.dumps({"format": "tableau_lab/1", "name": 5, "kind": "rk", "A": [["0"]], "b": ["1"], "c": ["0"]}),
    "glm-shapes": json.dumps({"format": "tableau_lab/1", "name": "x", "kind": "glm", "A": [["0"]], "U": [["1", "0"]],
                              "B": [["1"]], "V": [["1"]]}),
    "constants-bad": rk([["a"]], c=["a"], constants={"a": "nan"}),
    "constants-loop": rk([["a"]], c=["a"], constants={"a": "b", "b": "a"}),
}
CASES += [Case(f"shape-{k}", "method file", "shape", ("verify", "{d}/m.json"), {"m.json": v}, 2, "m.json")
          for k, v in SHAPES.items()]
CASES += [Case(f"shape-order-{k}", "method file", "shape", ("order", "{d}/m.json"), {"m.json": v}, 2, "m.json")
          for k, v in list(SHAPES.items())[:8]]
CASES += [Case("missing-file", "method file", "path", ("verify", "{d}/nothing.json"), {}, 2, "nothing.json"),
          Case("directory", "method file", "path", ("verify", "{d}"), {}, 2, "tableau-lab: error"),
          Case("dev-null", "method file", "path", ("verify", "/dev/null"), {}, 2, "/dev/null")]

# command-line numbers and options: argparse refuses them (exit 2, the option named)
GOOD = rk([["1/2"]], c=["1/2"])
NUMBERS = [("order", "--max-order", v) for v in ("0", "-5", "10**30", "1e3", "١٢", "99999999999999", "x")] + \
          [("run", "--steps", v) for v in ("0", "-1", "10**30", "1e9", "١٠", "99999999999999")] + \
          [("solve", "--solution", v) for v in ("0", "-1", "x")] + \
          [("bench", "--reps", v) for v in ("0", "-3")] + \
          [("roundoff", "--digits", v) for v in ("0", "5", "100000")]
for i, (cmd, opt, v) in enumerate(NUMBERS):
    argv = {"order": ("order", "{d}/m.json", opt, v),
            "run": ("run", "--method", "{d}/m.json", "--problem", "pendulum", "--h", "1/100", opt, v),
            "solve": ("solve", "{d}/m.json", "--require", "order=1", opt, v),
            "bench": ("bench", opt, v),
            "roundoff": ("roundoff", "--method", "{d}/m.json", "--problem", "pendulum", "--h", "1/10", "--steps", "10",
                         opt, v)}[cmd]
    CASES.append(Case(f"number-{cmd}-{i}", "cli number", "range", argv, {"m.json": GOOD}, 2, opt))
for i, h in enumerate(("0", "-1/100", "1e-999", "1/0", "nan", "inf", "x", "١/١٠٠", "10**400", "1e400")):
    CASES.append(Case(f"h-{i}", "cli number", "range", ("run", "--method", "{d}/m.json", "--problem", "pendulum",
                                                        "--h", h, "--steps", "10"), {"m.json": GOOD}, 2, "--h"))
CASES += [Case("timeout-bad", "cli number", "range", ("verify", "{d}/m.json", "--timeout", "-1"), {"m.json": GOOD}, 2,
               "--timeout"),
          Case("problem-unknown", "cli number", "range", ("run", "--method", "{d}/m.json", "--problem", "../../etc/passwd",
                                                          "--h", "1/10", "--steps", "10"), {"m.json": GOOD}, 2, "problem")]

# solve --require strings and --repair lists
FREE = rk([["a"]], c=["a"])
REQUIRE = ["order=", "order=x", "order=-1", "order=10**9", "order=99", "symplectic=1", "__import__('os')", "a = ",
           "= 1", "a = nan", "a == 1", "a = 1 = 2", "fast", "a**(1/2) = 1", "b9 = 1", "order=1;rm -rf /"]
CASES += [Case(f"require-{i}", "require", "injection", ("solve", "{d}/m.json", "--require", r), {"m.json": FREE}, 2, "")
          for i, r in enumerate(REQUIRE)]
REPAIR = ["A[5000,1]", "A[" + "9" * 5000 + ",1]", "A[0,0]", "A[-1,1]", "Z[1,1]", "A[2,1]", "A[x,1]", "A[1,1", "b[9]",
          "A[1,1],b[7]", "__import__('os')"]
CASES += [Case(f"repair-{i}", "repair", "range", ("solve", "{d}/m.json", "--require", "order=1", "--repair", r),
               {"m.json": GOOD}, 2, "") for i, r in enumerate(REPAIR)]

# budgets: legal input that would run for a long time (the time budget of the test, a few seconds)
def _primes(n):
    out, k = [], 2
    while len(out) < n:
        if all(k % p for p in out):
            out.append(k)
        k += 1
    return out


TWELVE = [f"sqrt({p})" for p in _primes(12)]
BIG = 60
HANGS = {
    "twelve-primes": rk([[e if i == j else "0" for j in range(12)] for i, e in enumerate(TWELVE)],
                        b=["1/12"] * 12, c=TWELVE),
    "field-degree": rk([["2**(1/63)", "0", "0"], ["0", "3**(1/61)", "0"], ["0", "0", "5**(1/59)"]],
                       b=["1/3"] * 3, c=["2**(1/63)", "3**(1/61)", "5**(1/59)"]),
    "dense-60": rk([[f"1/{i + j + 2}" for j in range(BIG)] for i in range(BIG)], b=[f"1/{BIG}"] * BIG,
                   c=[" + ".join(f"1/{i + j + 2}" for j in range(BIG)) for i in range(BIG)]),
}
CASES += [Case(f"hang-{k}", "budget", "hang", ("--timeout", "3", "stability", "{d}/m.json"), {"m.json": v}, 2, "")
          for k, v in HANGS.items()]
CASES += [Case("hang-solve-order12", "budget", "hang",
               ("--timeout", "3", "solve", "{d}/m.json", "--require", "order=12"),
               {"m.json": rk([["a", "b"], ["c", "d"]], b=["e", "f"], c=["a + b", "c + d"])}, 2, ""),
          Case("hang-solve-symplectic3", "budget", "hang",
               ("--timeout", "3", "solve", "{d}/m.json", "--require", "order=5,symplectic"),
               {"m.json": rk([["a11", "a12", "a13"], ["a21", "a22", "a23"], ["a31", "a32", "a33"]], b=["b1", "b2", "b3"],
                             c=["c1", "c2", "c3"])}, 2, "time budget")]

# where outputs go: names from input never leave --out; --out naming a file is refused
CASES += [Case("report-dotdot", "output path", "path", ("report", "{d}/..json", "--out", "{d}/o/proofs"),
               {"..json": GOOD}, 2, "safe file name"),
          Case("report-dot", "output path", "path", ("report", "{d}/.json", "--out", "{d}/o"), {".json": GOOD}, 2,
               "safe file name"),
          Case("report-out-file", "output path", "path", ("report", "{d}/m.json", "--out", "{d}/afile"),
               {"m.json": GOOD, "afile": "x"}, 2, "afile"),
          Case("stability-plot-file", "output path", "path", ("stability", "{d}/m.json", "--plot", "{d}/afile"),
               {"m.json": GOOD, "afile": "x"}, 2, "afile"),
          Case("run-free-parameter", "method file", "shape", ("run", "--method", "{d}/m.json", "--problem", "pendulum",
                                                             "--h", "1/10", "--steps", "10"), {"m.json": FREE}, 2, "m.json")]

# a run whose state overflows ends with exit 1 and the step, at every precision (mpmath has no overflow: limits.HUGE)
RK4 = rk([["0", "0", "0", "0"], ["1/2", "0", "0", "0"], ["0", "1/2", "0", "0"], ["0", "0", "1", "0"]],
         b=["1/6", "1/3", "1/3", "1/6"], c=["0", "1/2", "1/2", "1"])
CASES += [Case(f"overflow-{prec}", "run", "overflow", ("run", "--method", "{d}/m.json", "--problem", "harmonic", "--h", "3",
                                                       "--steps", "3000", "--precision", prec), {"m.json": RK4}, 1,
               "step 1")
          for prec in ("float64", "mp:20")]

# scenes through `run SCENE --out`: refused before any run, nothing under --out (tests/test_hostile_scenes.py has 154 more)
SCENE = {"format": "tableau_lab/scene/1", "name": "s", "problem": "pendulum", "h": "1/10", "steps": 10,
         "runs": [{"method": "m.json"}]}
BAD_SCENES = {
    "name-dotdot": {"name": ".."}, "name-dot": {"name": "."}, "name-slash": {"name": "a/b"}, "name-hidden": {"name": ".x"},
    "name-arabic": {"name": "١"}, "method-null": {"runs": [{"method": None}]}, "plots-number": {"plots": 5},
    "project-nested": {"runs": [{"method": "m.json", "project": [["H"]]}]}, "precision-list": {"precision": ["dd"]},
    "title-number": {"title": 5}, "steps-huge": {"steps": 10 ** 30}, "T-bypass": {"steps": None, "T": "1e300", "h": "1"},
    "h-tiny": {"h": "1e-999"}, "h-nan": {"h": "nan"}, "runs-empty": {"runs": []}, "unknown-key": {"colour": "red"},
    "problem-unknown": {"problem": "../../etc/passwd"}, "method-missing": {"runs": [{"method": "nothing.json"}]},
    "monitor-negative": {"monitor": "-1"}, "record-zero": {"record_every": 0},
}


def _scene(change):
    d = {**SCENE, **change}
    return json.dumps({k: v for k, v in d.items() if v is not None}, ensure_ascii=False)


CASES += [Case(f"scene-{k}", "scene", "schema", ("run", "{d}/scene.json", "--out", "{d}/out"),
               {"scene.json": _scene(v), "m.json": GOOD}, 2, "scene.json") for k, v in BAD_SCENES.items()]
CASES += [Case("scene-duplicate-key", "scene", "json", ("run", "{d}/scene.json", "--out", "{d}/out"),
               {"scene.json": _scene({})[:-1] + ', "steps": 20}', "m.json": GOOD}, 2, "steps"),
          Case("scene-nested", "scene", "json", ("run", "{d}/scene.json", "--out", "{d}/out"),
               {"scene.json": "[" * 100000 + "]" * 100000}, 2, "scene.json"),
          Case("scene-nan-literal", "scene", "json", ("run", "{d}/scene.json", "--out", "{d}/out"),
               {"scene.json": _scene({})[:-1] + ', "monitor": NaN}', "m.json": GOOD}, 2, "NaN"),
          Case("scene-dev-zero", "scene", "path", ("run", "/dev/zero", "--out", "{d}/out"), {}, 2, "/dev/zero"),
          Case("scene-directory", "scene", "path", ("run", "{d}", "--out", "{d}/out"), {}, 2, "directory")]

# raising a limit: only the named ones, within 100 times their default
CASES += [Case(f"entry-limit-{i}", "cli number", "range", ("verify", "{d}/m.json", "--entry-limit", v), {"m.json": GOOD}, 2,
               "--entry-limit") for i, v in enumerate(("bogus=3", "depth=x", "depth=0", "depth=999999", "depth", "=5",
                                                        "depth=١٠"))]

# issue 29: design — option values refused before any search (exit 2, the option and value named),
# an unreachable or unusable scheduler refused within its connect timeout
DESIGN = ("design", "{d}/m.json", "--maximize", "imaginary-interval", "--samples", "8", "--starts", "1")
FAMILY = rk([["0", "0"], ["1/2", "0"]], b=["1 - b2", "b2"], c=["0", "1/2"])       # free b2
DESIGN_BAD = [("constrain-order-x", ("--constrain", "order=x"), "order=x"),
              ("constrain-order-negative", ("--constrain", "order=-3"), "order=-3"),
              ("constrain-order-zero", ("--constrain", "order=0"), "order=0"),
              ("constrain-order-huge", ("--constrain", "order=99"), "order=99"),
              ("constrain-order-power", ("--constrain", "order=10**9"), "order=10**9"),
              ("constrain-order-empty", ("--constrain", "order="), "order="),
              ("constrain-order-arabic", ("--constrain", "order=٤"), "order="),
              ("constrain-value", ("--constrain", "parasitism-free=2"), "parasitism-free=2"),
              ("constrain-unknown", ("--constrain", "fast"), "fast"),
              ("constrain-inject", ("--constrain", "__import__('os').system('touch PWNED')"), "__import__"),
              ("constrain-empty", ("--constrain", ""), "--constrain"),
              ("constrain-commas", ("--constrain", ",,"), "--constrain"),
              ("require-empty", ("--require", ""), "--require"),
              ("require-comma", ("--require", ","), "--require"),
              ("require-order-x", ("--require", "order=x"), "order=x"),
              ("require-order-negative", ("--require", "order=-3"), "order=-3"),
              ("scheduler-tls", ("--scheduler", "tls://127.0.0.1:1"), "tls://127.0.0.1:1"),
              ("scheduler-closed-port", ("--scheduler", "tcp://127.0.0.1:1"), "tcp://127.0.0.1:1"),
              ("scheduler-ucx", ("--scheduler", "ucx://127.0.0.1:1"), "ucx://127.0.0.1:1"),
              ("scheduler-no-port", ("--scheduler", "tcp://127.0.0.1"), "scheduler"),
              ("scheduler-garbage", ("--scheduler", "::::"), "scheduler")]
CASES += [Case(f"design-{k}", "design", "range", DESIGN + extra, {"m.json": FAMILY}, 2, fragment)
          for k, extra, fragment in DESIGN_BAD]
# /issue 29: design
