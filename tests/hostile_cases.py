"""The hostile-input corpus of the command line (issue 16): each case a command, the files it
reads and what must happen — the exit code and a fragment of the message (the file, entry or
option named).  Read by tests/test_hostile_cli.py (every case, in process) and by
benchmarks/hostile_table.py (every case as a user runs it, each in a forked child with its peak memory:
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
    env: dict | None = None     # environment variables set for the case ({d}: its folder)


def run_case(case, main) -> dict:
    """Run ``case`` through ``main`` (tableau_lab.cli.main) in this process, in a fresh folder that
    is also the working directory: exit code, stderr, seconds, the time budget, the files added
    beside the inputs, and whether an injection created its marker file."""
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        for name, text in case.files.items():
            (d / name).parent.mkdir(parents=True, exist_ok=True)
            if isinstance(text, bytes):
                (d / name).write_bytes(text)
            else:
                (d / name).write_text(text, encoding="utf-8", errors="surrogatepass")
        before = set(d.rglob("*"))
        argv = [a.replace("{d}", str(d)) for a in case.argv]
        env = {k: v.replace("{d}", str(d)) for k, v in (case.env or {}).items()}
        saved = {k: os.environ.get(k) for k in env}
        os.environ.update(env)
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
            for k, v in saved.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v
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
CASES += [_entry_case(f"inject-stability-{i}", "injection", e, "m.json", "stability")
          for i, e in enumerate(INJECTION[:5])]

# the shape and kind of a method file
SHAPES = {
    "ragged": rk([["0", "0"], ["1"]]), "b-short": rk([["0", "0"], ["1", "0"]], b=["1"]),
    "kind": json.dumps({"format": "tableau_lab/1", "name": "x", "kind": "rocket",
                        "A": [["0"]], "b": ["1"], "c": ["0"]}),
    "format": json.dumps({"format": "tableau_lab/99", "name": "x", "kind": "rk", "A": [["0"]], "b": ["1"], "c": ["0"]}),
    "no-A": json.dumps({"format": "tableau_lab/1", "name": "x", "kind": "rk", "b": ["1"], "c": ["0"]}),
    "A-number": rk([[0.5]]), "A-string": json.dumps({"format": "tableau_lab/1", "name": "x", "kind": "rk", "A": "0",
                                                    "b": ["1"], "c": ["0"]}),
    "A-null": rk([[None]]), "A-bool": rk([[True]]), "A-nested": rk([[["0"]]]), "empty-A": rk([]),
    "list": "[1, 2]", "string": '"rk"', "empty": "", "not-json": "{'A': 1}", "truncated": rk([["0"]])[:-5],
    "claims-bad": rk([["0"]], claims={"order": "four"}), "claims-unknown": rk([["0"]], claims={"fast": True}),
    "name-number": json.dumps({"format": "tableau_lab/1", "name": 5, "kind": "rk",
                               "A": [["0"]], "b": ["1"], "c": ["0"]}),
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
          Case("problem-unknown", "cli number", "range",
               ("run", "--method", "{d}/m.json", "--problem", "../../etc/passwd", "--h", "1/10", "--steps", "10"),
               {"m.json": GOOD}, 2, "problem")]

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
               {"m.json": rk([["a11", "a12", "a13"], ["a21", "a22", "a23"], ["a31", "a32", "a33"]],
                             b=["b1", "b2", "b3"], c=["c1", "c2", "c3"])}, 2, "time budget")]

# where outputs go: names from input never leave --out; --out naming a file is refused
CASES += [Case("report-dotdot", "output path", "path", ("report", "{d}/..json", "--out", "{d}/o/proofs"),
               {"..json": GOOD}, 2, "safe file name"),
          Case("report-dot", "output path", "path", ("report", "{d}/.json", "--out", "{d}/o"), {".json": GOOD}, 2,
               "safe file name"),
          Case("report-out-file", "output path", "path", ("report", "{d}/m.json", "--out", "{d}/afile"),
               {"m.json": GOOD, "afile": "x"}, 2, "afile"),
          Case("stability-plot-file", "output path", "path", ("stability", "{d}/m.json", "--plot", "{d}/afile"),
               {"m.json": GOOD, "afile": "x"}, 2, "afile"),
          Case("run-free-parameter", "method file", "shape",
               ("run", "--method", "{d}/m.json", "--problem", "pendulum", "--h", "1/10", "--steps", "10"),
               {"m.json": FREE}, 2, "m.json")]

# a run whose state overflows ends with exit 1 and the step, at every precision (mpmath has no overflow: limits.HUGE)
RK4 = rk([["0", "0", "0", "0"], ["1/2", "0", "0", "0"], ["0", "1/2", "0", "0"], ["0", "0", "1", "0"]],
         b=["1/6", "1/3", "1/3", "1/6"], c=["0", "1/2", "1/2", "1"])
CASES += [Case(f"overflow-{prec}", "run", "overflow",
               ("run", "--method", "{d}/m.json", "--problem", "harmonic", "--h", "3", "--steps", "3000",
                "--precision", prec), {"m.json": RK4}, 1,
               "step 1")
          for prec in ("float64", "mp:20")]

# scenes through `run SCENE --out`: refused before any run, nothing under --out
# (tests/test_hostile_scenes.py has 154 more)
SCENE = {"format": "tableau_lab/scene/1", "name": "s", "problem": "pendulum", "h": "1/10", "steps": 10,
         "runs": [{"method": "m.json"}]}
BAD_SCENES = {
    "name-dotdot": {"name": ".."}, "name-dot": {"name": "."}, "name-slash": {"name": "a/b"},
    "name-hidden": {"name": ".x"},
    "name-arabic": {"name": "١"}, "method-null": {"runs": [{"method": None}]}, "plots-number": {"plots": 5},
    "project-nested": {"runs": [{"method": "m.json", "project": [["H"]]}]}, "precision-list": {"precision": ["dd"]},
    "title-number": {"title": 5}, "steps-huge": {"steps": 10 ** 30},
    "T-bypass": {"steps": None, "T": "1e300", "h": "1"},
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
CASES += [Case(f"entry-limit-{i}", "cli number", "range", ("verify", "{d}/m.json", "--entry-limit", v),
               {"m.json": GOOD}, 2, "--entry-limit")
          for i, v in enumerate(("bogus=3", "depth=x", "depth=0", "depth=999999", "depth", "=5", "depth=١٠"))]

# issue 29: exact core
# a JSON number too large for a float is refused when read (it was expanded to 10**99999999 for the
# hint of the message: a hang until the budget); JSON-level refusals name tableau entries one-based
# (they were JSON paths: A[0][0]); 8th roots and nested square roots in GLMs analyse exactly
_HUGE = '{"format": "tableau_lab/1", "name": "h", "kind": "rk", "A": [[1e99999999]], "b": ["1"], "c": ["0"]}'
_ROOT8 = rk([["2**(1/8)/4", "0"], ["root(x**8 - 2, 1)/2", "1/4"]], b=["1/2", "1/2"],
            c=["2**(1/8)/4", "root(x**8 - 2, 1)/2 + 1/4"])
_NESTED_GLM = json.dumps({"format": "tableau_lab/1", "name": "nested", "kind": "glm",
                          "A": [["sqrt(2 + sqrt(3))/4", "0"], ["1/2", "sqrt(2 - sqrt(3))/4"]],
                          "U": [["1", "sqrt(2 + sqrt(3)) - sqrt(6)/2"], ["1", "sqrt(2)/2"]],
                          "B": [["1/2", "1/2"], ["sqrt(3)/2", "-sqrt(3)/2"]], "V": [["1", "0"], ["0", "-1"]]})
CASES += [Case("json-number-1e99999999", "method file", "size", ("--timeout", "20", "verify", "{d}/m.json"),
               {"m.json": _HUGE}, 2, "A row 1, column 1: 1e99999999 is a floating-point number"),
          Case("json-number-1e99999999-order", "method file", "size", ("--timeout", "20", "order", "{d}/m.json"),
               {"m.json": _HUGE}, 2, "m.json: entry A row 1, column 1"),
          Case("json-surrogate-one-based", "method file", "unicode", ("verify", "{d}/m.json"),
               {"m.json": rk([["1", "0"], ["0", "\\ud800"]]).replace("\\\\ud800", "\\ud800")}, 2,
               "entry A row 2, column 2: a lone surrogate"),
          Case("json-duplicate-key-one-based", "method file", "shape", ("verify", "{d}/m.json"),
               {"m.json": rk([["1"]]).replace('"b": ["1"]', '"b": [{"x": 1, "x": 2}]')}, 2,
               "entry b[1].x: duplicate key"),
          Case("json-nan-number-one-based", "method file", "not a number", ("verify", "{d}/m.json"),
               {"m.json": rk([["1"]]).replace('"b": ["1"]', '"b": [NaN]')}, 2, "entry b[1]: NaN")]
CASES += [Case(f"root8-{cmd}", "entry", "size", ("--timeout", "60", cmd, "{d}/m.json"), {"m.json": _ROOT8}, 0, "")
          for cmd in ("verify", "order", "stability")]
CASES += [Case(f"nested-glm-{cmd}", "entry", "size", ("--timeout", "60", cmd, "{d}/m.json"), {"m.json": _NESTED_GLM},
               code, "") for cmd, code in (("verify", 0), ("order", 0), ("stability", 0))]

# issue 29: files ---------------------------------------------------------------------------------------------------
# outputs stay where the user said and never replace an input; every read back bounded and checked against the
# schema of its writer (tests/test_files_guard.py: the cases that need links, FIFOs, sparse files, zip bombs)
def _npz_truncated() -> bytes:
    import io as _io

    import numpy as _np
    buf = _io.BytesIO()
    _np.savez_compressed(buf, run0_t=_np.linspace(0, 1, 101))
    return buf.getvalue()[:200]


_WP = {"name": "wp", "title": "t", "problem": "harmonic", "T": 1.0, "invariant": "H", "reference_error_bound": 1e-30,
       "speedup": {}, "series": {"RK4": [{"cpu": 0.01, "nfev": 40, "error": 1e-3, "invariant_error": 1e-4}]}}
_ROUNDOFF = {"method": "m.json", "problem": "pendulum", "h": "1/10", "n": [0, 10], "plain": [0.0, 1e-16],
             "compensated": [0.0, 1e-17], "slope_plain": 0.5, "slope_compensated": 0.1}
_META = {"scene": "s.json", "name": "s", "title": "s", "complete": True,
         "runs": [{"label": "RK4", "status": "completed", "max_invariant_error": {}}]}
_FILES29 = [
    ("long-file-name", ("verify", "{d}/" + "a" * 300 + ".json"), {}, "longer than"),
    ("long-family-size", ("modified", "bdf:" + "9" * 5000), {}, "bdf:"),
    ("long-folder-name", ("order", "{d}/" + "b" * 256 + "/m.json"), {}, "longer than"),
    ("solve-save-over-input", ("solve", "{d}/f.json", "--require", "order=1", "--save", "{d}/f.json"),
     {"f.json": FREE}, "would overwrite the input"),
    ("solve-save-over-stranger", ("solve", "{d}/f.json", "--require", "order=1", "--save", "{d}/m.json"),
     {"f.json": FREE, "m.json": GOOD}, "not made by this command"),
    ("solve-name-escape",
     ("solve", "{d}/f.json", "--require", "order=1", "--save", "{d}/o.json", "--name", "a\x1b[2Jb"),
     {"f.json": FREE}, "--name"),
    ("design-save-over-input", ("design", "{d}/f.json", "--maximize", "imaginary-interval", "--save", "{d}/f.json"),
     {"f.json": FREE}, "would overwrite the input"),
    ("design-checkpoint-over-tableau", ("design", "{d}/f.json", "--maximize", "imaginary-interval", "--checkpoint",
                                        "{d}/m.json"), {"f.json": FREE, "m.json": GOOD}, "not made by this command"),
    ("design-checkpoint-folder", ("design", "{d}/f.json", "--maximize", "imaginary-interval", "--checkpoint", "{d}"),
     {"f.json": FREE}, "a directory"),
    ("design-name-control", ("design", "{d}/f.json", "--maximize", "imaginary-interval", "--save", "{d}/o.json",
                             "--name", "x\x07"), {"f.json": FREE}, "--name"),
    ("replot-name-dotdot", ("replot", "{d}/wp"), {"wp/data.json": json.dumps({**_WP, "name": "../../x"})}, "name"),
    ("replot-name-absolute", ("replot", "{d}/wp"), {"wp/data.json": json.dumps({**_WP, "name": "/tmp/x"})}, "name"),
    ("replot-name-empty", ("replot", "{d}/wp"), {"wp/data.json": json.dumps({**_WP, "name": ""})}, "name"),
    ("replot-3000-series", ("replot", "{d}/wp"), {"wp/data.json": json.dumps(
        {**_WP, "series": {f"m{i}": _WP["series"]["RK4"] for i in range(3000)}})}, "series"),
    ("replot-roundoff-no-slope", ("replot", "{d}/roundoff_m.json"),
     {"roundoff_m.json": json.dumps({k: v for k, v in _ROUNDOFF.items() if k != "slope_plain"})}, "slope_plain"),
    ("replot-roundoff-no-problem", ("replot", "{d}/roundoff_m.json"),
     {"roundoff_m.json": json.dumps({k: v for k, v in _ROUNDOFF.items() if k != "problem"})}, "problem"),
    ("replot-convergence-empty", ("replot", "{d}/convergence_x.json"), {"convergence_x.json": "[]"}, "convergence_x"),
    ("replot-runs-empty", ("replot", "{d}/out/s"), {"out/s/meta.json": json.dumps({**_META, "runs": []}),
                                                    "out/s/data.npz": _npz_truncated()}, "runs"),
    ("replot-npz-truncated", ("replot", "{d}/out/s"), {"out/s/meta.json": json.dumps(_META),
                                                       "out/s/data.npz": _npz_truncated()}, "data.npz"),
    ("replot-nothing-drawable", ("replot", "{d}"), {"other.json": "{}"}, "holds no saved output"),
    ("report-over-input", ("report", "{d}/m.tex", "--out", "{d}"), {"m.tex": GOOD}, "would overwrite the input"),
]
CASES += [Case(f"files-{cid}", "output path", "files", argv, files, 2, fragment)
          for cid, argv, files, fragment in _FILES29]
CASES += [Case(f"files-lock-timeout-{v}", "environment", "files", ("report", "{d}/m.json", "--out", "{d}/out"),
               {"m.json": GOOD}, 2, "TABLEAU_LAB_LOCK_TIMEOUT", {"TABLEAU_LAB_LOCK_TIMEOUT": v})
          for v in ("nan", "inf", "-1", "x")]
CASES += [Case("files-cache-is-a-file", "environment", "files",
               ("run", "--method", "{d}/m.json", "--problem", "harmonic", "--h", "1/10", "--steps", "10"),
               {"m.json": GOOD}, 2, "TABLEAU_LAB_CACHE", {"TABLEAU_LAB_CACHE": "{d}/m.json"})]
# end of issue 29: files ---------------------------------------------------------------------------------------------
# issue 29: runs ----------------------------------------------------------------------------------
# work-precision scenes within a run's step budget, known peers only, one-based entry names;
# budgets on user problems and on the exact stage of a run; starts out of float64's range; a
# JSON float no tableau can hold refused at once by `run --method` too
WP = {"format": "tableau_lab/workprecision/1", "name": "w", "problem": "harmonic", "T": 1,
      "methods": [{"method": "m.json", "steps": [10]}]}
BAD_WP = {
    "steps-1e12": ({"methods": [{"method": "m.json", "steps": [10 ** 12]}]}, "methods[1].steps[1]"),
    "steps-second-bad": ({"methods": [{"method": "m.json", "steps": [10, 0]}]}, "methods[1].steps[2]"),
    "steps-too-many": ({"methods": [{"method": "m.json", "steps": list(range(1, 200))}]}, "methods[1].steps"),
    "T-1e300": ({"T": "1e300"}, "MAX_STEPS"),
    "T-zero": ({"T": "0"}, "T must be positive"),
    "T-float-overflow": ({"T": "1e999"}, "rounds to inf"),
    "peer-lsoda": ({"peers": [{"method": "LSODA", "rtol": ["1e-6"]}]}, "known peers"),
    "peer-unknown-key": ({"peers": [{"method": "RK45", "rtol": ["1e-6"], "colour": 1}]}, "peers[1]: unknown keys"),
    "atol-text": ({"peers": [{"method": "RK45", "rtol": ["1e-6"], "atol_factor": "x"}]}, "peers[1].atol_factor"),
    "atol-negative": ({"peers": [{"method": "RK45", "rtol": ["1e-6"], "atol_factor": "-1"}]}, "atol_factor"),
    "rtol-one": ({"peers": [{"method": "RK45", "rtol": ["1e-6", "1"]}]}, "peers[1].rtol[2]"),
    "method-label-number": ({"methods": [{"method": "m.json", "steps": [10], "label": 5}]}, "methods[1].label"),
    "method-missing": ({"methods": [{"method": "nothing.json", "steps": [10]}]}, "methods[1].method"),
    "methods-object": ({"methods": {"method": "m.json"}}, "methods must be a list"),
}
CASES += [Case(f"wp-{k}", "workprecision scene", "budget", ("workprecision", "{d}/wp.json", "--out", "{d}/out",
                                                            "--workers", "1"),
               {"wp.json": json.dumps({**WP, **v}), "m.json": GOOD}, 2, frag) for k, (v, frag) in BAD_WP.items()]


def _nested_exp(depth=45):
    e = "x"
    for _ in range(depth):
        e = f"exp({e})"
    return e


_WIDE = 200
USER_PROBLEMS = {   # legal, costly: the run's exact stage (problem checked, code generated) stops at the budget
    "nested-exp45": {"name": "nest", "q": ["x"], "p": ["v"], "H": _nested_exp() + " + v^2", "q0": ["0"], "p0": ["0"]},
    "200-variables": {"name": "wide", "q": [f"x{i}" for i in range(_WIDE)], "p": [f"v{i}" for i in range(_WIDE)],
                      "H": "v0^2/2 + x0^2/2 + v199^2/2 - cos(x199)", "q0": ["1/10"] * _WIDE, "p0": ["0"] * _WIDE},
}
CASES += [Case(f"user-problem-{k}", "budget", "hang", ("--timeout", "3", "run", "{d}/scene.json", "--out", "{d}/out"),
               {"scene.json": _scene({"problem": {"define": v}}), "m.json": GOOD}, 2, "time budget of 3 s")
          for k, v in USER_PROBLEMS.items()]
CASES += [Case("user-problem-wp-nested-exp45", "budget", "hang",
               ("--timeout", "3", "workprecision", "{d}/wp.json", "--out", "{d}/out", "--workers", "1"),
               {"wp.json": json.dumps({**WP, "problem": {"define": USER_PROBLEMS["nested-exp45"]}}), "m.json": GOOD}, 2,
               "time budget of 3 s")]
CASES += [Case(f"convergence-T-{k}", "cli number", "range",
               ("convergence", "{d}/m.json", "--problem", "harmonic", "--T", T, "--workers", "1", "--out", "{d}/out"),
               {"m.json": RK4}, 2, f"--T {T}") for k, T in (("zero", "0"), ("negative", "-1"), ("overflow", "1e400"))]
CASES += [Case(f"q0-overflow-{p}", "run", "overflow", ("run", "--method", "{d}/m.json", "--problem", p, "--h", "1/10",
                                                       "--steps", "10", "--q0", q0), {"m.json": GOOD}, 1, "step 0")
          for p, q0 in (("harmonic", "1e200"), ("kepler", "1e200,0"))]
CASES += [Case("run-method-json-float-1e99999999", "method file", "size",
               ("run", "--method", "{d}/m.json", "--problem", "harmonic", "--h", "1/10", "--steps", "3"),
               {"m.json": rk([["0"]]).replace('"b": ["1"]', '"b": [1e99999999]')}, 2, "b[1]"),
          Case("run-project-unknown", "run", "range", ("run", "--method", "{d}/m.json", "--problem", "kepler", "--h",
                                                      "1/10", "--steps", "3", "--project", "H,Q"), {"m.json": RK4}, 2,
               "projection onto Q"),
          Case("scene-project-constant", "scene", "schema", ("run", "{d}/scene.json", "--out", "{d}/out"),
               {"scene.json": _scene({"problem": {"define": {"name": "c", "q": ["x"], "p": ["v"], "H": "v^2/2 + x^2/2",
                                                             "invariants": {"C": "1"}, "q0": ["1"], "p0": ["0"]}},
                                      "runs": [{"method": "m.json", "project": ["C"]}]}), "m.json": GOOD}, 2,
               "runs[1].project: problem 'c': projection onto C: C = 1 is constant"),
          Case("scene-runs-one-based", "scene", "schema", ("run", "{d}/scene.json", "--out", "{d}/out"),
               {"scene.json": _scene({"runs": [{"method": "m.json"}, {"method": "nothing.json"}]}), "m.json": GOOD}, 2,
               "runs[2].method"),
          Case("scene-set-one-based", "scene", "schema", ("run", "{d}/scene.json", "--out", "{d}/out"),
               {"scene.json": _scene({"problem": {"name": "pendulum", "set": {"q0": ["x"]}}}), "m.json": GOOD}, 2,
               "problem.set.q0[1]"),
          Case("scene-json-path-one-based", "scene", "json", ("run", "{d}/scene.json", "--out", "{d}/out"),
               {"scene.json": _scene({"runs": [{"method": "m.json", "label": "a\u0001"}]}), "m.json": GOOD}, 2,
               "runs[1].label"),
          Case("scene-invariants-plot-without-invariants", "scene", "schema",
               ("run", "{d}/scene.json", "--out", "{d}/out"),
               {"scene.json": _scene({"problem": {"define": {"name": "d", "y": ["x"], "f": ["-x"], "y0": ["1"]}},
                                      "plots": ["invariants"]}), "m.json": GOOD}, 2, "no invariants to plot")]
# issue 29: runs (end) ----------------------------------------------------------------------------
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
