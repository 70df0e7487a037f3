"""The ``tableau-lab`` command line.

Exit codes (tableau_lab/errors.py): 0 every file read and every claim holds; 1 a claim fails or a
run stops (step and time named); 2 bad input or a budget hit (file, entry or option named;
nothing written); 3 an internal error (a bug: one line, the traceback with ``--debug``); 4 every
run went to its end but one is degraded (an invariant error or a parasitic component of
relative size 1e-2 or more: numeric/limits.DEGRADED); 130 interrupted. Everything printed passes
through ``inputs.printable``: no terminal escapes from file contents reach the terminal.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import re
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from . import __version__
from .budget import MODIFIED_ORDER as MODIFIED_MAX_ORDER
from .errors import (
    EXIT_BUG,
    EXIT_CLAIM,
    EXIT_DEGRADED,
    EXIT_INPUT,
    EXIT_INTERRUPTED,
    EXIT_OK,
    EXIT_TERMINATED,
    InputError,
    Terminated,
)
from .files import derived_name
from .inputs import MAX_STEPS, SAFE_NAME, printable  # --steps, --max-steps

# within --timeout
EXACT_COMMANDS = ("verify", "reconstruct", "order", "stability", "solve", "report", "modified", "design")
# their exact stage (problem, method, generated code) within --timeout
BUILT_WITHIN = ("run", "workprecision", "convergence")
MAX_ORDER = 20                # --max-order
MAX_DIGITS = 10 ** 4          # --digits
MAX_REPEATS = 10 ** 4         # --starts, --reps, --solution, --workers
MAX_FIELD_DEGREE = 4096       # --max-field-degree (beyond: days of primitive-element arithmetic)


def _each_method(args, analyse, decimal: bool = False) -> int:
    """Load each file, run ``analyse(method, path) -> (result, failed)`` and print it (text or JSON).
    Unreadable files are reported on stderr and give exit code 2; a failed claim gives 1.
    ``decimal``: a decimal tableau is read too (:func:`~tableau_lab.exact.tableau_json.load_any`)."""
    from .budget import computing
    from .exact.tableau_json import TableauError, load, load_any

    status = EXIT_OK
    for i, path in enumerate(args.files):
        try:
            with computing(f"{args.command} of {path}"):
                method = (load_any if decimal else load)(path)
                result, failed = analyse(method, path)
        except TableauError as exc:
            print(f"tableau-lab: error: {exc}", file=sys.stderr)
            status = EXIT_INPUT
            continue
        if args.json:
            print(json.dumps({"file": path, "name": method.name, **result.to_json()}, ensure_ascii=False), flush=True)
        else:
            print(("\n" if i else "") + f"== {path}\n{result}", flush=True)
        if failed and status == EXIT_OK:
            status = EXIT_CLAIM
    return status


def _verify(args) -> int:
    from .analysis.verify import verify

    def analyse(method, path):
        res = verify(method)
        return res, res.failed
    return _each_method(args, analyse, decimal=True)


def _reconstruct(args) -> int:
    """The exact tableau behind a decimal one (analysis/reconstruct.py), re-proven; --save it."""
    from dataclasses import replace

    from .analysis.reconstruct import reconstruct
    from .budget import computing
    from .exact.tableau_json import save, saved_by_tableau_lab
    from .files import refuse_outputs
    if args.save:
        refuse_outputs([args.save], [args.file], mine=saved_by_tableau_lab, what="--save")
    limits = {k: v for k, v in (("degree", args.degree), ("digits", args.digits)) if v is not None}
    with computing(f"reconstruct of {args.file}"):
        res = reconstruct(args.file, **limits)
    print(json.dumps({"file": args.file, **res.to_json()}, ensure_ascii=False) if args.json else str(res))
    failed = res.method is None or bool(res.verified is not None and res.verified.failed)
    if args.save and res.method is not None:
        save(replace(res.method, notes=tuple(res.method.notes) + (
            f"Reconstructed by tableau-lab reconstruct from {args.file}: {res.proven()}",)), args.save)
        print(f"saved the exact candidate to {args.save}", file=sys.stderr)
    return EXIT_CLAIM if failed else EXIT_OK


def _order(args) -> int:
    from .analysis.order import order
    from .exact.tableau_json import TableauError

    def analyse(method, path):
        try:
            return order(method, max_order=args.max_order), ()
        except ValueError as exc:          # e.g. a GLM that is not preconsistent: no order theory applies
            raise TableauError(path, str(exc)) from None
    return _each_method(args, analyse)


def _modified(args) -> int:
    from .analysis.modified import modified_equation
    from .analysis.results import Combined
    from .exact.tableau_json import TableauError

    def analyse(method, path):
        try:
            res = modified_equation(method, args.order, "modifying" if args.modifying else "modified")
            if args.structure:
                from .analysis.method_series import method_series
                from .analysis.series_structure import structure
                res = Combined((res, structure(method_series(method, args.order).phi)), ("", "structure"))
        except ValueError as exc:          # a GLM without a simple eigenvalue 1 of V
            raise TableauError(path, str(exc)) from None
        return res, ()
    return _each_method(args, analyse)


def _stability(args) -> int:
    from .analysis.stability_report import stability_report
    from .exact.tableau_json import TableauError

    def analyse(method, path):
        if args.plot:                      # before the analysis: no figure over an input
            from .experiments.figure_style import siblings
            from .experiments.stability_plots import figure_paths
            from .files import refuse_outputs
            refuse_outputs([f for png in figure_paths(args.plot, path).values() for f in siblings(png)], [path])
        try:
            rep = stability_report(method)
        except ValueError as exc:          # e.g. free parameters: no numeric stability analysis
            raise TableauError(path, str(exc)) from None
        if args.plot:
            from .experiments.stability_plots import draw_stability
            for png in draw_stability(rep, args.plot, path, window_=args.window):
                print(f"wrote {png}", file=sys.stderr)
        return rep, ()
    return _each_method(args, analyse)


CLAIM_OF = {"symplectic": ("symplectic", True), "g-symplectic": ("g_symplectic", True),
            "parasitism-free": ("parasitism_free", True)}


def _solve(args) -> int:
    from .analysis.design import DesignError
    from .exact.methods import MethodError
    from .exact.tableau_json import TableauError, save

    if args.save:
        _guard_save(args)                        # before any work: not over the input, not over a stranger's file
    try:
        rep, res = _solve_file(args)
    except (TableauError, DesignError, MethodError) as exc:
        print(f"tableau-lab: error: {args.file}: {exc}" if not str(exc).startswith(str(args.file)) else
              f"tableau-lab: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    if args.json:
        print(json.dumps({"file": args.file, "name": rep.name, **rep.to_json()}, ensure_ascii=False), flush=True)
    else:
        print(f"== {args.file}\n{rep}", flush=True)
    if res is None and getattr(rep, "located", ()):
        return 0                          # --locate found the entries to repair: its answer, not a failure
    if res is None or res.status != "solved":
        return EXIT_CLAIM
    if args.save:
        k = args.solution
        if k is None and len(res.solutions) > 1:
            print(f"tableau-lab: error: {len(res.solutions)} solutions: choose one with --solution K", file=sys.stderr)
            return EXIT_INPUT
        k = k or 1
        if not 1 <= k <= len(res.solutions):
            print(f"tableau-lab: error: --solution {k}: there are {len(res.solutions)} solutions", file=sys.stderr)
            return EXIT_INPUT
        sol = res.solutions[k - 1]
        claims = dict(sol.method.claims)
        for r in res.requirements:
            if r.name in CLAIM_OF:
                key, val = CLAIM_OF[r.name]
            elif r.name in ("order", "stage-order", "effective-order"):
                key, val = r.name.replace("-", "_"), r.value
            else:
                continue
            if sol.method.kind in _claim_kinds(key):
                claims[key] = val
        from dataclasses import replace
        meth = replace(sol.method, name=args.name or sol.method.name, claims=tuple(sorted(claims.items())),
                       notes=tuple(sol.method.notes) + ("Solved by tableau-lab solve for "
                                                        f"{', '.join(map(str, res.requirements))}"
                                                        f" ({sol.label}).",))
        save(meth, args.save)
        print(f"saved solution {k} to {args.save}", file=sys.stderr)
    return EXIT_OK


def _guard_save(args) -> None:
    """--save OUT and --name N of solve and design, checked before any work: OUT is not the
    input, not a device, folder or link, and not a file tableau-lab did not save
    (:func:`tableau_json.saved_by_tableau_lab`); N holds no control characters."""
    from .exact.tableau_json import saved_by_tableau_lab
    from .files import refuse_outputs
    if args.name is not None and (printable(args.name) != args.name or not args.name.strip()):
        raise InputError(f"--name {printable(repr(args.name))[:80]}: a method name is text without control characters "
                         "(and not empty)")
    refuse_outputs([args.save], [args.file], mine=saved_by_tableau_lab, what="--save")


def _solve_file(args):
    """(report, design result) of solve: design, or repair with --repair/--locate."""
    from .analysis.design import repair, solve_file
    from .budget import computing
    from .exact.tableau_json import load
    with computing(f"solve of {args.file}"):
        if args.repair or args.locate:
            rep = repair(load(args.file), args.require, _split(args.repair), args.locate, _split(args.within))
            return rep, rep.design
        rep = solve_file(args.file, args.require)
        return rep, rep


def _design(args) -> int:
    """Search a solution family for its best member and certify it (experiments/design_search.py)."""
    from .analysis.family import FamilyError, families_of
    from .budget import computing
    from .exact.tableau_json import TableauError, save
    from .experiments.design_search import search
    from .experiments.executor import SchedulerError

    box, requirements, constraints = _design_request(args)
    if args.save:
        _guard_save(args)                        # before any work
    if args.checkpoint:
        from .experiments.design_search import is_checkpoint
        from .files import refuse_outputs
        refuse_outputs([args.checkpoint], [args.file] + ([args.save] if args.save else []), mine=is_checkpoint,
                       what="--checkpoint")
    try:
        with computing(f"design search of {args.file}"):
            fams = [f for f in families_of(args.file, requirements) if f.free]
            if not fams:
                raise FamilyError(f"{args.file}: no family with free parameters for {', '.join(requirements)}")
            results = [search(f, maximize=args.maximize, minimize=args.minimize, constraints=constraints, box=box,
                              samples=args.samples, starts=args.starts, seed=args.seed, scheduler=args.scheduler,
                              workers=None if args.scheduler else args.workers,
                              checkpoint=None if not args.checkpoint else
                              (args.checkpoint if len(fams) == 1 else f"{args.checkpoint}.{i + 1}"))
                       for i, f in enumerate(fams)]
    except (TableauError, FamilyError, ValueError, SchedulerError) as exc:
        print(f"tableau-lab: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    for res in results:
        print(json.dumps({"file": args.file, **res.to_json()}, ensure_ascii=False) if args.json
              else f"== {args.file}\n{res}", flush=True)
    best = next((c for res in results for c in res.candidates if c.certified is not None), None)
    if best is None:
        return EXIT_CLAIM
    if args.save:
        from dataclasses import replace
        goals = ", ".join((args.maximize or []) + (args.minimize or []))
        meth = replace(best.certified, name=args.name or best.certified.name,
                       claims=tuple(sorted(_design_claims(best, requirements).items())),
                       notes=(f"Found by tableau-lab design ({goals}; "
                              f"{', '.join(constraints) or 'no constraints'}) and re-verified exactly.",))
        save(meth, args.save)
        print(f"saved the best certified member to {args.save}", file=sys.stderr)
    return EXIT_OK


def _design_request(args) -> tuple:
    """(box, requirements, constraints) of design from --box, --require and --constrain, checked
    before any work (InputError naming the option)."""
    from .experiments.design_search import SearchError, check_constraints
    lo, _, hi = args.box.partition(":")
    try:
        box = (float(lo), float(hi))
    except ValueError:
        raise InputError(f"--box {args.box!r}: write LO:HI, e.g. -3:3") from None
    if not all(abs(v) < 1e6 for v in box):
        raise InputError(f"--box {args.box!r}: bounds within ±1e6")
    for opt, items in (("--require", args.require), ("--constrain", args.constrain)):
        empty = next((item for item in items or () if not _split([item])), None)
        if empty is not None:
            raise InputError(f"{opt} {empty!r}: no condition given")
    try:
        constraints = check_constraints(_split(args.constrain))
    except SearchError as exc:
        raise InputError(f"--constrain: {exc}") from None
    return box, _split(args.require), constraints


def _design_claims(best, requirements) -> dict:
    """The claims design saves with its best certified member: what its re-verification showed."""
    claims = {"order": best.verified["order"]} if "order" in best.verified else {}
    if "g-symplectic" in requirements or best.verified.get("G-symplectic"):
        claims["g_symplectic"] = True
    if "order with θ ≡ 0" in best.verified and best.certified.kind == "glm":
        claims["identity_start_order"] = best.verified["order with θ ≡ 0"]
    if best.verified.get("mu") is not None and all(mu == 0 for mu in best.verified["mu"]):
        claims["parasitism_free"] = True
    return claims


def _family_options(parser, require_help: str, required: bool = True):
    """FILE and --require, shared by solve and design."""
    parser.add_argument("file", metavar="FILE", help="JSON tableau with unknowns (names) in its entries")
    parser.add_argument("--require", action="append", required=required, metavar="CONDITIONS", help=require_help)


def _split(items):
    """'A[2,1],U[2,2]' → ['A[2,1]', 'U[2,2]'] (commas inside brackets kept), over repeated options."""
    return [p.strip() for item in (items or []) for p in re.split(r";|,(?![^\[]*\])", item) if p.strip()]


def _quick_job(args, frozen=False):
    """The exact stage of a quick run (parse the options exactly, load, round, generate):
    a RunJob, frozen when it goes to another process."""
    from .experiments.runs import prepare_quick, step_size

    _entry_limits(args)
    overrides = {}
    for item in args.set or []:
        k, _, v = item.partition("=")
        if not k or not v:
            raise ValueError(f"--set {item!r}: write NAME=VALUE, e.g. e=0.6")
        overrides[k.strip()] = _exact_number(v.strip(), f"--set {k}")
    for key in ("q0", "p0", "y0"):
        vals = getattr(args, key)
        if vals is not None:
            overrides[key] = tuple(_exact_number(v, f"--{key}") for v in vals.split(","))
    h = step_size(args.h, "--h")
    project = [p.strip() for p in args.project.split(",")] if args.project else []
    monitor = float(_exact_number(args.monitor, "--monitor")) if args.monitor else None
    if monitor is not None and not monitor > 0:
        raise ValueError(f"--monitor {args.monitor}: the bound must be positive")
    from .budget import computing, time_limit
    with time_limit(args.timeout), computing(f"building the run of {args.method} on {args.problem}"):
        return prepare_quick(args.method, args.problem, h, args.steps, precision=args.precision, project=project,
                             start=args.start, overrides=overrides, monitor=monitor, frozen=frozen)


def _run(args) -> int:
    from .experiments.job import BuildError, run_job
    from .numeric.integrate import IntegrationError

    if args.scenes:
        if args.method or args.problem:
            print("tableau-lab: error: give scene files or --method/--problem, not both", file=sys.stderr)
            return EXIT_INPUT
        return _run_scenes(args)
    if not args.method or not args.problem:
        print("tableau-lab: error: run needs scene files, or --method FILE and --problem NAME", file=sys.stderr)
        return EXIT_INPUT
    if args.h is None or args.steps is None:
        print("tableau-lab: error: a quick run needs --h and --steps", file=sys.stderr)
        return EXIT_INPUT
    try:
        # the exact stage here for a short run, else in a child when this process can stay without
        # sympy (experiments/job.py)
        res = run_job(_quick_job, args, precision=args.precision, method=args.method, steps=args.steps)
    except ValueError as exc:                  # TableauError, ProblemError: bad input
        print(f"tableau-lab: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except (IntegrationError, BuildError) as exc:
        print(f"tableau-lab: error: {args.method} on {args.problem}: {exc}", file=sys.stderr)
        return EXIT_CLAIM
    if args.json:
        print(json.dumps(res, ensure_ascii=False))
    else:
        fin = ", ".join(f"{k} = [{', '.join(x if isinstance(x, str) else f'{x:.16g}' for x in v)}]"
                        for k, v in res["final"].items())
        print(f"{res['method']} on {res['problem']}: h = {res['h']:g}, {res['steps']} steps, {res['precision']}, "
              f"start {res['start']}"
              + (f", projection onto {', '.join(res['projection'])}" if res["projection"] else ""))
        print(f"  final: {fin}")
        print("  " + _invariant_errors(res["max_invariant_error"], "max |I − I(0)|"))
        print(f"  f evaluations {res['nfev']}, stage-iteration sweeps {res['newton_iterations']}, "
              f"projection iterations {res['projection_iterations']}, {res['seconds']:.3f} s, {res['loop']} loop"
              + (f", compile {res['compile_seconds']:.1f} s" if res["compile_seconds"] >= 0.05 else ""))
    if res.get("degraded"):
        print(f"tableau-lab: {args.method} on {args.problem}: DEGRADED: {res['degraded']}", file=sys.stderr)
        return EXIT_DEGRADED
    return EXIT_OK


def _run_scenes(args) -> int:
    from .exact.tableau_json import TableauError
    from .experiments.scene import SceneError, run_scene

    status = EXIT_OK
    for path in args.scenes:
        try:
            meta = run_scene(path, out_root=args.out, timeout=args.timeout)
        except (SceneError, TableauError, ValueError) as exc:       # BudgetError: an InputError, a ValueError
            print(f"tableau-lab: error: {exc}", file=sys.stderr)
            status = EXIT_INPUT
            continue
        where = f"{args.out}/{meta['name']}"
        print(f"== {path} → {where}/ ({'complete' if meta['complete'] else 'INCOMPLETE'})")
        for r in meta["runs"]:
            print(f"  {r['label']}: {r['status'].upper() if r['status'] == 'degraded' else r['status']}, "
                  f"{r['completed_steps']} steps, {_invariant_errors(r['max_invariant_error'], 'max |ΔI|', '.2e')}, "
                  f"{r['seconds']:.2f} s" + (f"\n    {r['message']}" if r["message"] else ""))
        print("  plots: " + ", ".join(meta["plots"]))
        if not meta["complete"] and status in (EXIT_OK, EXIT_DEGRADED):
            status = EXIT_CLAIM
        elif any(r["status"] == "degraded" for r in meta["runs"]) and status == EXIT_OK:
            status = EXIT_DEGRADED
    return status


def _invariant_errors(errors: dict, head: str, fmt: str = ".3e") -> str:
    """"max |ΔI|: H 1.2e-10, L 3.0e-12", or that the problem has none (no empty list)."""
    if not errors:
        return f"{head}: none (the problem has no invariants)"
    return f"{head}: " + ", ".join(f"{k} {v:{fmt}}" for k, v in errors.items())


def _roundoff(args) -> int:
    from .exact.tableau_json import TableauError
    from .experiments.plots import draw_roundoff, roundoff_title
    from .experiments.runs import roundoff, step_size
    from .numeric.problems import ProblemError

    name = derived_name("roundoff", Path(args.method).stem, args.problem)
    _guard_json_and_plot(args.out, name, [args.method])            # before any run
    try:
        h = step_size(args.h, "--h")
        res = roundoff(args.method, args.problem, h, args.steps, starts=args.starts, dps=args.digits)
    except (TableauError, ProblemError, ValueError) as exc:
        print(f"tableau-lab: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    data = {"method": args.method, "problem": args.problem, "h": str(h), "steps": args.steps,
            "starts": args.starts, "digits": args.digits, **res}
    where = _json_and_plot(args.out, name, data,
                           lambda png: draw_roundoff(res, png, roundoff_title(data)))
    def exponent(key):
        s = res[f"slope_{key}"]
        return "exponent —: too few nonzero records to fit" if s is None else f"exponent {s:.2f}"
    print(f"round-off after {args.steps} steps (RMS over {args.starts} starts): plain {res['plain'][-1]:.2e} "
          f"({exponent('plain')}), compensated {res['compensated'][-1]:.2e} "
          f"({exponent('compensated')}); wrote {where}.json and its figure (.png, .pdf, .svg)")
    return EXIT_OK


def _json_and_plot_paths(out, name) -> tuple:
    """(out/name.json, out/name.png): what :func:`_json_and_plot` writes (the figure's other
    formats are the PNG's siblings)."""
    base = Path(out) / name
    return base.with_name(name + ".json"), base.with_name(name + ".png")


def _guard_json_and_plot(out, name, inputs) -> None:
    """Before any run: out/name.json and its figure are not one of ``inputs`` (files.py)."""
    from .experiments.figure_style import siblings
    from .files import refuse_outputs
    data, png = _json_and_plot_paths(out, name)
    refuse_outputs([data, *siblings(png)], inputs)


def _json_and_plot(out, name, data, draw):
    """Write out/name.json (atomically) and out/name.png (by ``draw(png_path)``); returns out/name."""
    from .files import atomic_write_text, output_phase
    target, png = _json_and_plot_paths(out, name)
    with output_phase(out):                    # both or neither; the folder's lock; Ctrl-C deferred
        atomic_write_text(target, json.dumps(data, indent=1))
        draw(png)
    return Path(out) / name


def _with_executor(args, body) -> int:
    """``body(args, ex)`` with one executor (pool or cluster, from --scheduler/--workers) for every
    file; a bad scheduler or worker count is bad input, reported before any work."""
    from contextlib import ExitStack

    from .experiments.executor import SchedulerError, executor

    with ExitStack() as stack:
        try:
            ex = stack.enter_context(executor(args.scheduler, args.workers))
        except (SchedulerError, ValueError) as exc:
            print(f"tableau-lab: error: {exc}", file=sys.stderr)
            return EXIT_INPUT
        return body(args, ex)


def _convergence(args) -> int:
    return _with_executor(args, _convergence_runs)


def _convergence_runs(args, ex) -> int:
    from .exact.tableau_json import TableauError
    from .experiments.plots import convergence_title, draw_convergence
    from .experiments.runs import convergence, final_time
    from .numeric.problems import ProblemError
    try:
        T = float(final_time(_exact_number(args.T, "--T"), f"--T {args.T}"))
    except ValueError as exc:
        print(f"tableau-lab: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    name = derived_name("convergence", args.problem, args.precision.replace(":", ""))
    _guard_json_and_plot(args.out, name, args.files)               # before any run
    results, status = [], EXIT_OK
    for path in args.files:
        try:
            c = convergence(path, args.problem, T=T, precision=args.precision,
                            max_steps=args.max_steps, start=args.start, scheduler=ex, timeout=args.timeout)
        except (TableauError, ProblemError, ValueError) as exc:
            print(f"tableau-lab: error: {exc}", file=sys.stderr)
            status = EXIT_INPUT
            continue
        results.append(c.to_json())
        slope = "—" if c.slope is None else f"{c.slope:5.2f}"
        print(f"{c.method[:44]:44s} p = {c.order}  slope {slope}  n ≤ {int(c.T / min(c.hs)):6d}  {c.verdict[:70]}",
              flush=True)
        if not c.verdict.startswith(("order confirmed", "destroyed")) and status == EXIT_OK:
            status = EXIT_CLAIM
    if results:
        where = _json_and_plot(args.out, name, results,
                               lambda png: draw_convergence(results, png, convergence_title(results)))
        print(f"wrote {where}.json and its figure (.png, .pdf, .svg)")
    return status


def _warm_up(args) -> int:
    from .experiments.shared_loops import warm_up
    warm_up(print, workers=args.workers)
    return EXIT_OK


def _warm_up_options(p) -> None:
    p.add_argument("--workers", type=_count(1, 64), default=None, help="processes (default: the cores, at most 2)")


def _bench(args) -> int:
    from .experiments import bench
    if args.method or args.problem:
        if not (args.method and args.problem):
            print("tableau-lab: error: give both --method and --problem (or neither, for the standard set)",
                  file=sys.stderr)
            return EXIT_INPUT
        hs = [h.strip() for h in args.h.split(",")]
        try:
            if len(hs) == 1:
                res = bench.bench_case(args.method, args.problem, args.steps or 10 ** 5, h=hs[0],
                                       precision=args.precision, reps=args.reps)
            else:
                res = bench.step_sizes(args.method, args.problem, args.steps or 10 ** 5, hs,
                                       precision=args.precision, reps=args.reps)
        except (OSError, ValueError, TypeError) as exc:
            print(f"tableau-lab: error: {exc}", file=sys.stderr)
            return EXIT_INPUT
        if args.json:
            print(json.dumps(res, default=float))
        elif len(hs) == 1:
            for k, v in res.items():
                print(f"{k}: {v}")
        else:
            print(bench.step_size_table(res))
        return EXIT_CLAIM if "failed" in res else EXIT_OK
    res = bench.standard(steps=args.steps or 10 ** 5, reps=args.reps, memory=not args.no_memory)
    out = bench.save(res, args.out)
    print(json.dumps(res, default=float) if args.json else bench.table(res) + f"\n\nsaved in {out}/")
    return EXIT_OK


def _workprecision(args) -> int:
    return _with_executor(args, _workprecision_runs)


def _workprecision_runs(args, ex) -> int:
    from .experiments.executor import SchedulerError
    from .experiments.workprecision import load_wp_scene, run_wp
    code = EXIT_OK
    for path in args.scenes:
        try:
            scene = load_wp_scene(path, timeout=args.timeout)
            data = run_wp(scene, out_root=args.out, scheduler=ex)
        except (InputError, SchedulerError) as exc:      # SceneError, a budget
            print(f"tableau-lab: error: {exc}", file=sys.stderr)
            code = EXIT_INPUT
            continue
        print(f"{scene.name}: {Path(args.out) / scene.name / (scene.name + '.png')}")
        for label, pts in data["series"].items():
            for p in pts:
                what = f"n = {p['steps']}" if "rtol" not in p else f"rtol = {p['rtol']:g}"
                if "failed" in p:
                    print(f"  {label:32s} {what:16s} failed: {p['failed'][:80]}")
                else:
                    inv = scene.invariant
                    print(f"  {label:32s} {what:16s} cpu {p['cpu']:8.3f} s  nfev {p['nfev']:9d}  "
                          f"error {p['error']:.2e}  max|{inv}-{inv}0| {p['invariant_error']:.2e}")
        from .experiments.workprecision import versus
        for level, v in data["speedup"].items():
            print(f"  max|{scene.invariant}-{scene.invariant}0| <= {level}: {versus(v)}")
    return code


def _suite(args) -> int:
    from .experiments.suite import main_suite
    return main_suite(args)


def _replot(args) -> int:
    from .experiments.replot import main_replot
    return main_replot(args)


def _report(args) -> int:
    from .exact.tableau_json import TableauError, load
    from .proofs.latex import ReportError, compile_pdf, library_document, method_document, write_report

    methods, status = [], EXIT_OK
    for path in args.files:
        try:
            methods.append((path, load(path)))
        except TableauError as exc:
            print(f"tableau-lab: error: {exc}", file=sys.stderr)
            status = EXIT_INPUT
    if not methods:
        return status
    out = Path(args.out)
    for path, _ in methods:
        if not SAFE_NAME.fullmatch(Path(path).stem):
            raise InputError(f"{path}: the report would be named {Path(path).stem!r}, not a safe file name "
                             "(ASCII letters, digits, - _ . starting with a letter or digit): rename the file")
    from .files import refuse_outputs
    from .proofs.latex import report_paths
    targets = [out / "library"] if args.library else [out / Path(p).stem for p, _ in methods]
    refuse_outputs([f for t in targets for f in report_paths(t).values()], [p for p, _ in methods])   # before work
    jobs = ([(out / "library", library_document([m for _, m in methods]))] if args.library else
            [(out / Path(p).stem, method_document(m, _figures_of(p, out), stability=args.stability))
             for p, m in methods])
    for target, (tex, facts) in jobs:
        tex_path = write_report(tex, facts, target)
        try:
            pdf = compile_pdf(tex_path, required=args.pdf)
        except ReportError as exc:
            print(f"tableau-lab: error: {exc}", file=sys.stderr)
            return EXIT_INPUT
        print(f"wrote {tex_path}" + (f" and {pdf}" if pdf else " (no pdflatex: .tex only)"))
    return status


def _audit(args) -> int:
    from .proofs.audit import audit
    from .proofs.latex import ReportError
    try:
        result = audit(args.paths, args.out, seconds=args.seconds, workers=args.jobs, scheduler=args.scheduler,
                       pdf=True if args.pdf else None)
    except ReportError as exc:
        print(f"tableau-lab: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    if args.json:
        print(json.dumps(result.to_json(), ensure_ascii=False))
    else:
        print(result)
    for b in result.bad:
        print(f"tableau-lab: error: {b.message}", file=sys.stderr)
    if args.out:
        print(f"wrote {Path(args.out) / 'audit.json'}, audit.md, audit.tex"
              + (", audit.pdf" if (Path(args.out) / "audit.pdf").exists() else " (no pdflatex: no PDF)"))
    return result.exit_code


def _figures_of(method_path, out, reports="reports", most=2):
    """Invariant plots of scenes (under reports/) that ran this method file, as vector PDF where
    the figure style wrote one, else PNG: (path relative to the report's directory, caption)."""
    import os
    found = []
    from .inputs import read_json
    for meta in sorted(Path(reports).glob("*/meta.json")):
        try:
            data = read_json(meta, ValueError, "scene's metadata")      # bounded, strict
        except ValueError:
            continue
        if not isinstance(data, dict) or not isinstance(data.get("runs", []), list):
            continue
        labels = [str(r.get("label")) for r in data.get("runs", [])
                  if isinstance(r, dict) and Path(str(r.get("file", ""))).name == Path(method_path).name]
        png = meta.parent / f"{data.get('name')}_invariants.png"
        figure = png.with_suffix(".pdf") if png.with_suffix(".pdf").exists() else png     # vector where drawn
        if labels and figure.exists():
            found.append((os.path.relpath(figure, out), f"{data.get('title', '')} ({', '.join(labels)}; scene "
                                                          f"{data.get('scene', '')})"))
    return found[:most]


def _exact_number(text, what):
    from .exact.grammar import EntryError, parse_number
    try:
        return parse_number(text)
    except EntryError as exc:
        raise ValueError(f"{what}: {exc}") from None


def _claim_kinds(key):
    from .exact.tableau_json import CLAIMS
    return CLAIMS[key][1]


def _executor_options(parser):
    """--scheduler and --workers of the sweeps (experiments/executor.py)."""
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="run the independent runs on the Dask cluster whose scheduler is at ADDRESS "
                             "(tcp://HOST:8786), or 'serial' (in this process); default: a process pool here")
    parser.add_argument("--workers", type=_count(1, MAX_REPEATS), metavar="N",
                        help="processes of the local pool (default: every core; 1: in this process)")


# what a shell completes for an argument that names a file or a folder (shtab's FILE and
# DIRECTORY, written out: building the parser does not import shtab)
_FILES = {"bash": "_shtab_compgen_files", "zsh": "_files", "tcsh": "f"}
_DIRS = {"bash": "_shtab_compgen_dirs", "zsh": "_files -/", "tcsh": "d"}


def _mark_paths(parser) -> None:
    """File-name completion for the FILE/SCENE arguments (and --method), folder-name completion
    for --out and SUITE_DIR, in one command's parser (shtab reads ``action.complete``)."""
    for action in parser._actions:       # argparse keeps no public list of a parser's arguments
        if action.metavar in ("FILE", "SCENE") or action.dest == "method":
            action.complete = _FILES
        elif action.dest in ("out", "suite_dir") or action.metavar in ("DIR", "SUITE_DIR"):
            action.complete = _DIRS


def _list(args) -> int:
    from .analysis.catalog import list_methods
    rows = list_methods()
    print(json.dumps(rows.to_json(), ensure_ascii=False) if args.json else
          rows.markdown() if args.markdown else str(rows))
    return EXIT_OK


def _completion(args) -> int:
    import shtab
    print(shtab.complete(build_parser(), shell=args.shell))
    return 0


# -- each command's own arguments: one function per command, named in COMMANDS below --------------

def _verify_options(p) -> None:
    p.add_argument("files", nargs="+", metavar="FILE", help="JSON tableau files")
    p.add_argument("--json", action="store_true", help="one JSON object per file, one per line")


def _reconstruct_options(p) -> None:
    p.add_argument("file", metavar="FILE", help='a decimal tableau ("numbers": "decimal")')
    p.add_argument("--save", metavar="OUT", help="write the exact candidate here (not over the input)")
    p.add_argument("--degree", type=_reconstruct_limit("degree", 1), default=None, metavar="N",
                   help="largest degree of an algebraic entry looked for (default 4)")
    p.add_argument("--digits", type=_reconstruct_limit("digits", 10), default=None, metavar="N",
                   help="most digits of a ball used (default 200)")
    p.add_argument("--json", action="store_true", help="the report as one JSON object")


def _reconstruct_limit(name: str, least: int):
    """An argparse type: an integer from ``least`` to the limit's ceiling (recognise.CEILINGS, imported
    only when the option is given: the parser is built for every command)."""
    def read(text: str) -> int:
        from .exact.recognise import CEILINGS
        return int(_count(least, CEILINGS[name])(text))
    read.__name__ = "integer"
    return read


def _order_options(p) -> None:
    p.add_argument("files", nargs="+", metavar="FILE")
    p.add_argument("--max-order", type=_count(1, MAX_ORDER), default=None, metavar="N",
                   help="highest order examined (default: 2s for RK methods, s if explicit; 8 for GLMs)")
    p.add_argument("--json", action="store_true", help="one JSON object per file, one per line")


def _modified_options(p) -> None:
    p.add_argument("files", nargs="+", metavar="FILE")
    p.add_argument("--order", type=_count(1, MODIFIED_MAX_ORDER), default=5, metavar="N",
                   help=f"trees of order ≤ N, terms up to h^(N−1) (default 5, at most {MODIFIED_MAX_ORDER})")
    p.add_argument("--modifying", action="store_true",
                   help="the modifying integrator: the field whose numerical flow is the exact flow of f")
    p.add_argument("--structure", action="store_true",
                   help="also: symplectic, conjugate-symplectic, symmetric, energy-preserving to which order "
                        "(partitioned methods: the modified energy's order)")
    p.add_argument("--json", action="store_true", help="one JSON object per file, one per line")


def _stability_options(p) -> None:
    p.add_argument("files", nargs="+", metavar="FILE")
    p.add_argument("--json", action="store_true", help="one JSON object per file, one per line")
    p.add_argument("--plot", metavar="DIR", help="write the stability region and the root moduli on the axis "
                                                 "as PNG files into DIR, named after the file or family "
                                                 "(bdf:4 -> bdf-4_region.png); the region's window encloses "
                                                 "the boundary locus, the real interval, +-iY* and the A(alpha) "
                                                 "sector when computed")
    p.add_argument("--window", type=_window, metavar="XMIN,XMAX,YMIN,YMAX",
                   help="with --plot: the region's window instead of the one from the analysis, "
                        "e.g. --window=-12,3,-8,8 (with =, as the value starts with a minus sign)")


def _solve_options(p) -> None:
    _family_options(p, "comma-separated conditions, e.g. 'symplectic,order=4' (repeatable)")
    p.add_argument("--json", action="store_true", help="one JSON object: status, solutions, obstruction")
    p.add_argument("--save", metavar="OUT", help="write the solution as a tableau file with the conditions as claims")
    p.add_argument("--solution", type=_count(1, MAX_REPEATS), metavar="K",
                   help="which solution --save writes (1-based)")
    p.add_argument("--name", help="name of the saved method")
    p.add_argument("--repair", action="append", metavar="ENTRIES",
                   help="repair a printed (numeric) tableau: these entries, e.g. 'A[2,1],U[2,2]', become unknowns; "
                        "the output names each changed entry with its printed and correct value")
    p.add_argument("--locate", action="store_true",
                   help="try every single entry as the unknown (beside --repair ones) and report those that make "
                        "the requirements solvable; a unique one is then repaired")
    p.add_argument("--within", action="append", metavar="MATRICES",
                   help="with --locate: search only these matrices, e.g. 'A,B'")


def _design_options(p) -> None:
    _family_options(p, "the family's exact conditions, as for solve (e.g. g-symplectic); none: the tableau's "
                       "unknowns are the free parameters", required=False)
    p.add_argument("--maximize", action="append", metavar="OBJECTIVE",
                   help="imaginary-interval or real-interval; with a --minimize too: the Pareto front of both")
    p.add_argument("--minimize", action="append", metavar="OBJECTIVE", help="error-norm or mu")
    p.add_argument("--constrain", action="append", metavar="CONSTRAINTS",
                   help="comma-separated: order=P, parasitism-free, explicit-first-stage")
    p.add_argument("--box", default="-2:2", metavar="LO:HI", help="search box of every free parameter (default -2:2)")
    p.add_argument("--samples", type=_count(8, 100_000), default=256, metavar="N", help="Sobol points (default 256)")
    p.add_argument("--starts", type=_count(1, 64), default=8, metavar="K", help="local searches (default 8)")
    p.add_argument("--seed", type=_count(0, 2 ** 31), default=0, metavar="S")
    p.add_argument("--workers", type=_count(1, 1024), default=1, metavar="N",
                   help="processes for the sample and the local searches (default 1: this process)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="a Dask scheduler (tcp://HOST:PORT) instead of local processes")
    p.add_argument("--checkpoint", metavar="FILE",
                   help="keep the finished tasks in FILE (JSON); a rerun of the same request resumes from it")
    p.add_argument("--json", action="store_true", help="one JSON object per family")
    p.add_argument("--save", metavar="OUT", help="write the best certified member with its verified claims")
    p.add_argument("--name", help="name of the saved method")


def _run_options(p) -> None:
    p.add_argument("scenes", nargs="*", metavar="SCENE", help="scene files (JSON); see reports/scenes/")
    p.add_argument("--out", default="reports", help="where scene outputs go (default reports/)")
    p.add_argument("--method", metavar="FILE", help="JSON tableau (no free parameters)")
    p.add_argument("--problem", metavar="NAME",
                   help="harmonic, pendulum, kepler, kepler_unperturbed, henon_heiles, fpu, outer_solar_system")
    p.add_argument("--set", action="append", metavar="NAME=VALUE", help="problem parameter, e.g. e=0.9 (exact)")
    p.add_argument("--q0", help="initial q, comma-separated")
    p.add_argument("--p0", help="initial p")
    p.add_argument("--y0", help="initial y (general problems)")
    p.add_argument("--h", help="step size, read exactly (0.01 is 1/100)")
    p.add_argument("--steps", type=_count(1, MAX_STEPS), help="number of steps")
    p.add_argument("--project", metavar="H,L", help="project onto these invariants after every step")
    p.add_argument("--precision", default="float64",
                   help="float64 (default), dd (double-double: about 32 digits, compiled) or mp:DIGITS (mpmath), "
                        "e.g. mp:32")
    p.add_argument("--start", choices=("exact", "naive"), default="exact",
                   help="GLM starting method: the computed one (default) or y^[0] = u y0")
    p.add_argument("--monitor", metavar="BOUND", help="stop when a parasitic component of a GLM's input vector "
                                                      "exceeds BOUND (checked at the records)")
    p.add_argument("--json", action="store_true", help="one JSON object")


def _roundoff_options(p) -> None:
    p.add_argument("--method", required=True, metavar="FILE")
    p.add_argument("--problem", required=True, metavar="NAME")
    p.add_argument("--h", required=True)
    p.add_argument("--steps", type=_count(1, MAX_STEPS), required=True)
    p.add_argument("--starts", type=_count(1, MAX_REPEATS), default=4)
    p.add_argument("--digits", type=_count(16, MAX_DIGITS), default=32)
    p.add_argument("--out", default="reports/roundoff")


def _convergence_options(p) -> None:
    p.add_argument("files", nargs="+", metavar="FILE")
    p.add_argument("--problem", required=True)
    p.add_argument("--T", default="10")
    p.add_argument("--precision", default="float64")
    p.add_argument("--max-steps", type=_count(1, MAX_STEPS), default=1 << 15)
    p.add_argument("--start", choices=("exact", "naive"), default="exact")
    _executor_options(p)
    p.add_argument("--out", default="reports/convergence")


def _bench_options(p) -> None:
    p.add_argument("--method", help="one case: a method file")
    p.add_argument("--problem", help="one case: a problem name")
    p.add_argument("--steps", type=_count(1, MAX_STEPS), help="steps per run (default 10^5)")
    p.add_argument("--h", default="1/100", help="step size, exact (default 1/100); several, comma-separated "
                   "(1/100,1/25), are timed interleaved and their costs printed as ratios to the first")
    p.add_argument("--precision", default="float64", help="float64, dd or mp:DIGITS (one case)")
    p.add_argument("--reps", type=_count(1, MAX_REPEATS), default=5,
                   help="runs per case; the median is reported (default 5)")
    p.add_argument("--out", default="reports/bench", help="where the standard set is saved (default reports/bench)")
    p.add_argument("--no-memory", action="store_true", help="skip the 10^7-step memory probe")
    p.add_argument("--json", action="store_true", help="print JSON")


def _workprecision_options(p) -> None:
    p.add_argument("scenes", nargs="+", metavar="SCENE", help="work-precision scene files (JSON)")
    p.add_argument("--out", default="reports/workprecision", help="output folder (default reports/workprecision)")
    _executor_options(p)


def _suite_options(p) -> None:
    p.add_argument("suite_dir", nargs="?", default="reports/suite", metavar="SUITE_DIR",
                   help="folder with scenes/*.json (default reports/suite)")
    p.add_argument("--out", help="output folder (default SUITE_DIR)")
    p.add_argument("--steps", type=_count(1, MAX_STEPS), metavar="N",
                   help="N steps for every scene (default: each scene's own)")
    p.add_argument("--only", metavar="NAMES", help="comma-separated scene names")
    _executor_options(p)
    p.add_argument("--json", action="store_true", help="print the summary as one JSON object")


def _replot_options(p) -> None:
    p.add_argument("paths", nargs="+", metavar="PATH", help="saved outputs or folders to search")


def _report_options(p) -> None:
    p.add_argument("files", nargs="+", metavar="FILE")
    p.add_argument("--out", default="reports/proofs")
    p.add_argument("--pdf", action="store_true", help="fail if pdflatex is missing")
    p.add_argument("--library", action="store_true", help="one document for all files, with a summary table")
    p.add_argument("--stability", action="store_true",
                   help="add the exact imaginary-axis stability interval Y* (seconds to minutes per method)")


def _audit_options(p) -> None:
    from .budget import AUDIT_SECONDS
    p.add_argument("paths", nargs="+", metavar="PATH", help="tableau files, and folders searched for *.json")
    p.add_argument("--out", metavar="DIR", help="write audit.json, audit.md, audit.tex (and audit.pdf with pdflatex)")
    p.add_argument("--jobs", type=_count(1, MAX_REPEATS), metavar="N",
                   help="processes of the local pool (default: every core; 1: in this process)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="a Dask scheduler (tcp://HOST:8786), or 'serial'")
    p.add_argument("--seconds", type=_seconds, default=AUDIT_SECONDS, metavar="S",
                   help=f"time budget of one method (default {AUDIT_SECONDS:g}); a method over it is undecided")
    p.add_argument("--pdf", action="store_true", help="fail if pdflatex is missing")
    p.add_argument("--json", action="store_true", help="print the audit as one JSON object")


def _list_options(p) -> None:
    fmt = p.add_mutually_exclusive_group()
    fmt.add_argument("--json", action="store_true", help="one JSON object")
    fmt.add_argument("--markdown", action="store_true", help="a Markdown table")


def _completion_options(p) -> None:
    p.add_argument("shell", choices=("bash", "zsh", "tcsh"))


@dataclass(frozen=True)
class Command:
    """One command of the table :data:`COMMANDS`: its name, its handler (``args -> exit code``),
    the function adding its own arguments to its parser, and its help texts.  The options every
    command shares come from the parent parsers of :func:`_parents`."""
    name: str
    run: Callable[[argparse.Namespace], int]
    options: Callable[[argparse.ArgumentParser], None]
    help: str
    description: str | None = None


def _global_options(p) -> None:
    """The options before the command: --version, --debug, --entry-limit, --timeout, --max-field-degree."""
    from .budget import DEFAULT_SECONDS, FIELD_DEGREE as FIELD_DEGREE_LIMIT
    p.add_argument("--version", action="version", version=f"tableau-lab {__version__}")
    p.add_argument("--debug", action="store_true", help="print the traceback of an internal error")
    p.add_argument("--entry-limit", action="append", default=[], metavar="KEY=N",
                   help="raise a limit of tableau entries, e.g. depth=100 (repeatable; docs/reliability.md)")
    p.add_argument("--timeout", type=_seconds, default=DEFAULT_SECONDS, metavar="S",
                   help=f"time budget of the exact commands ({', '.join(EXACT_COMMANDS)}), and of the exact stage "
                        f"of {' and '.join(BUILT_WITHIN)} (a user-defined problem, the method, the generated code), "
                        f"in seconds; 0: none (default {DEFAULT_SECONDS:g})")
    p.add_argument("--max-field-degree", type=_count(1, MAX_FIELD_DEGREE), default=FIELD_DEGREE_LIMIT, metavar="N",
                   help="largest degree of a method's number field in the exact commands "
                        f"(default {FIELD_DEGREE_LIMIT})")


def _parents() -> dict:
    """The shared options after the command, as argparse parents: "debug" (--debug, --entry-limit:
    every command) and "timeout" (--timeout, --max-field-degree: the exact commands and the exact
    stage of the runs).  Their defaults are SUPPRESS: given before the command, an option keeps
    its value."""
    from .budget import DEFAULT_SECONDS, FIELD_DEGREE as FIELD_DEGREE_LIMIT
    debug = argparse.ArgumentParser(add_help=False)
    debug.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help=argparse.SUPPRESS)
    debug.add_argument("--entry-limit", action="append", default=argparse.SUPPRESS, metavar="KEY=N",
                       help="raise a limit of tableau entries, e.g. depth=100 (docs/reliability.md)")
    timeout = argparse.ArgumentParser(add_help=False)
    timeout.add_argument("--timeout", type=_seconds, default=argparse.SUPPRESS, metavar="S",
                         help=f"time budget in seconds, 0: none (default {DEFAULT_SECONDS:g})")
    timeout.add_argument("--max-field-degree", type=_count(1, MAX_FIELD_DEGREE), default=argparse.SUPPRESS,
                         metavar="N", help=f"largest degree of a method's number field (default {FIELD_DEGREE_LIMIT})")
    return {"debug": debug, "timeout": timeout}


#: the commands, in the order of ``tableau-lab --help``
COMMANDS = (
    Command("verify", _verify, _verify_options,
            help="check symplecticity / G-symplecticity and the claims of tableau files",
            description="Read JSON tableau files, solve the (G-)symplecticity conditions exactly and check each "
                        "file's claims. A decimal tableau (\"numbers\": \"decimal\") is analysed in ball arithmetic "
                        "instead: each property certified, refuted or undecided (to the stated precision where a "
                        "ball contains 0). Exit 0: no claim fails (a decimal tableau's undecided claims are listed as "
                        "UNDECIDED); 1: a claim fails (is refuted); 2: a file could not be read."),
    Command("reconstruct", _reconstruct, _reconstruct_options,
            help="the exact tableau behind a decimal one (rationals, algebraic numbers), re-proven exactly",
            description="Each decimal entry of a \"numbers\": \"decimal\" tableau is a ball; the simplest rational "
                        "inside it, or an algebraic number of small height found by an integer relation (LLL), "
                        "alone or in the number field the entries share, is certified to lie in the ball; the exact "
                        "candidate is then analysed exactly (order, stage order, symplecticity, the file's claims). "
                        "An entry recognised from too few digits is flagged WEAK (docs/reconstruction.md). Exit 0: "
                        "a candidate whose claims hold; 1: no candidate, or a claim fails; 2: bad input."),
    Command("order", _order, _order_options,
            help="order, stage order, starting and finishing methods (GLM theory)",
            description="RK methods: classical order by elementary weights (pinned at p + 1), principal error "
                        "coefficients, B(p), C(q), D(r), effective order. Partitioned RK: bicoloured trees. GLMs: "
                        "order relative to the best starting method (Butcher's algebraic theory), the order for θ ≡ "
                        "0, the stage order, the starting method ξ(t), the finishing method and the error terms."),
    Command("modified", _modified, _modified_options,
            help="modified equation (backward error analysis) or modifying integrator, exactly; for GLMs that of the "
                 "underlying one-step method",
            description="The numerical solution is the exact flow of ỹ′ = Σ h^(|t|−1) b(t)/σ(t) F(t)(ỹ) (Hairer, "
                        "Lubich & Wanner, Geometric Numerical Integration, IX). Prints the coefficients b(t)/σ(t) by "
                        "powers of h for every tree of order ≤ N. --structure adds the orders to which the series is "
                        "symplectic, conjugate-symplectic, symmetric and energy-preserving (for a partitioned "
                        "method, a P-series: the order to which a modified energy exists, and which of the B-series "
                        "checks do not apply)."),
    Command("stability", _stability, _stability_options,
            help="linear stability (A-stability, imaginary-axis interval, and for GLMs zero-stability and A(alpha)), "
                 "algebraic stability and parasitism, exactly",
            description="The characteristic polynomial P(w, z) = det[[I - zA, -U], [-zB, wI - V]] exactly; R(z) and "
                        "E(y) for RK methods; A-stability; the interval |y| < Y* of the imaginary axis z = iy where "
                        "every root has |w| = 1 ((G-)symplectic methods) or |w| <= 1 (others), Y* exact; for GLMs "
                        "(and so linear multistep methods, e.g. bdf:5) zero-stability (V power-bounded; roots "
                        "outside the circle certified) and, when P has degree 1 in z, the A(alpha) angle (certified "
                        "to 30 digits); algebraic stability; parasitic growth parameters of GLMs. Partitioned "
                        "methods: the harmonic oscillator, x = h*omega. Exit 0: done; 2: a file could not be read."),
    Command("solve", _solve, _solve_options,
            help="solve a tableau's unknowns for required properties (design, repair)",
            description="Treat the named unknowns of a tableau as parameters and find every solution family "
                        "(exactly: Gröbner bases, radicals) of the required conditions; each solution is "
                        "re-verified. Conditions: g-symplectic, symplectic, order=P, identity-start-order=P (GLM: θ "
                        "≡ 0), effective-order=P, stage-order=Q, parasitism-free, symmetric, or an equation 'LHS = "
                        "RHS'. Exit 0: solved (with --locate: entries located); 1: no (real, radical) solution "
                        "(nothing located); 2: bad input."),
    Command("design", _design, _design_options,
            help="search a solution family for its best member, then certify it exactly",
            description="The families of `solve FILE --require …` are searched numerically (a Sobol sample, then "
                        "Nelder–Mead) for one objective under constraints; each optimum is snapped to exact values "
                        "(the rationals of smallest height within the objective tolerance, or the exact solutions of "
                        "the constraints on the family) and re-verified by the ordinary analyses. Objectives: "
                        "imaginary-interval, real-interval (maximise); error-norm, mu (minimise). Constraints: "
                        "order=P, parasitism-free, explicit-first-stage. Without --require, the tableau's unknowns "
                        "are the free parameters. An optimum that a face of --box keeps within tolerance is flagged "
                        "box-bound; a member several optima certify to is printed once, with its height. Exit 0: a "
                        "certified member; 1: none; 2: bad input (also an unreachable --scheduler)."),
    Command("run", _run, _run_options,
            help="run scenes, or a method on a problem (float64 or mpmath)",
            description="Run scene files (data, metadata and plots under reports/<name>/), or integrate a built-in "
                        "problem with a method file: the final state (through the finishing method for GLMs), max "
                        "|invariant − initial value|, f evaluations, Newton and projection iterations, wall time. "
                        "Exit 0: done; 1: the run failed (message names step and time); 2: bad input; 4: a run went "
                        "to its end degraded (an invariant error or a parasitic component of relative size 1e-2 or "
                        "more)."),
    Command("roundoff", _roundoff, _roundoff_options,
            help="separate round-off from method error (float64 vs the same method at high precision), with and "
                 "without compensated summation",
            description="Runs the float64 method and the same float64 coefficients, step and initial values at "
                        "--digits digits; the difference is round-off alone. RMS over --starts perturbed initial "
                        "values; fitted growth exponents (Brouwer: 1/2)."),
    Command("convergence", _convergence, _convergence_options,
            help="measured order: global error at T against h, least-squares slope",
            description="For each method file: the global error at T against a high-precision reference, for n = 50, "
                        "100, 200, ... steps until the local slopes settle or round-off is reached; the "
                        "least-squares slope is compared with the computed order. Failed runs are kept as evidence. "
                        "Exit 1 if an order is not confirmed."),
    Command("warm-up", _warm_up, _warm_up_options,
            help="build the compiled loops shared by every problem (once per installation: a first run on a new "
                 "problem then compiles only its own functions, about a second)"),
    Command("bench", _bench, _bench_options,
            help="speed of the compiled loops: the standard set against a gcc -O2 C loop, scipy DOP853 and plain "
                 "mpmath; or one case (--method, --problem)"),
    Command("workprecision", _workprecision, _workprecision_options,
            help="work-precision diagrams: error and invariant error against CPU time and f-evaluations, our methods "
                 "(compiled) against scipy's DOP853 / RK45"),
    Command("suite", _suite, _suite_options,
            help="the hard-case suite: every symplectic and G-symplectic method on the hard problems, with and "
                 "without projection, parasitism monitor; one table",
            description="Runs SUITE_DIR/scenes/*.json (one independent run per method x problem x projection, "
                        "through a process pool or a Dask cluster), writes each scene's data and plots, "
                        "summary.json, summary.md and summary plots, and prints the table: status (completed / "
                        "stopped by the monitor / failed, at t), max |H - H0|, max parasitic component, measured "
                        "against predicted parasitic log-growth, seconds. Exit 0: the claims hold; 1: a claim fails; "
                        "2: bad input."),
    Command("replot", _replot, _replot_options,
            help="redraw figures (PNG, PDF, SVG) from the data a run saved, without running anything again",
            description="Redraw the figures of saved outputs in the current figure style: scene folders (meta.json, "
                        "data.npz and the scene file named there), work-precision folders (data.json), convergence "
                        "and round-off JSON files, a suite's summary.json; any other folder is searched (e.g. "
                        "reports). Data files are read, never written. Exit 0: done; 2: a path holds nothing to draw "
                        "from."),
    Command("report", _report, _report_options,
            help="LaTeX proof reports (compiled to PDF when pdflatex is present)",
            description="For each method: the tableau, the G-symplecticity proof step by step, the symplecticity "
                        "matrix, the order conditions and starting method, parasitism; NAME.tex, NAME.report.json "
                        "(the facts stated) and NAME.pdf under --out; never over an input (exit 2)."),
    Command("audit", _audit, _audit_options,
            help="audit tableau files: every claim checked by the exact or the certified analyses, one line per method",
            description="Every tableau file (exact, or decimal: \"numbers\": \"decimal\") of the PATHs (folders "
                        "searched for *.json; INDEX.json, *_reference.json and JSON that is no tableau skipped, "
                        "counted) through the exact analyses or the certified ones in ball arithmetic, on a process "
                        "pool or a Dask cluster, each method within --seconds; every claim of its \"claims\" "
                        "checked: claimed against found, the verdict (agrees / DISAGREES / undecided) and the "
                        "evidence of each disagreement (the failing condition, its tree and residual). --out DIR "
                        "writes audit.json, audit.md, audit.tex (and audit.pdf with pdflatex). Exit 0: every "
                        "claim agrees or is undecided; 1: a disagreement; 2: a bad file (the others are audited); "
                        "3: an internal error in some file."),
    Command("list", _list, _list_options,
            help="the method library: shipped tableaux and families, with kind, size, order, source",
            description="Every method name the commands take besides a file: the shipped tableaux (e.g. rk4, gauss2) "
                        "and the generated families (gauss:3, bdf:4), with kind, size, order and source (the same "
                        "rows as tableau_lab.list_methods())."),
    Command("completion", _completion, _completion_options,
            help="print a shell completion script (bash, zsh, tcsh)",
            description="Print the completion script of tableau-lab for SHELL (made by shtab from this command "
                        "line): commands, options, and file names where a file is expected. Install, e.g.: "
                        "tableau-lab completion bash > ~/.local/share/bash-completion/completions/tableau-lab "
                        "(bash), tableau-lab completion zsh > ~/.zfunc/_tableau-lab (zsh, with ~/.zfunc in fpath)."),
)


def build_parser() -> argparse.ArgumentParser:
    """The parser of ``tableau-lab``: the global options, then one subparser per entry of
    :data:`COMMANDS` (its arguments from ``options``, the shared ones from :func:`_parents`),
    file and folder arguments marked for shell completion.

    >>> build_parser().parse_args(["verify", "a.json", "--json"]).run is _verify
    True
    """
    p = argparse.ArgumentParser(prog="tableau-lab", description=(
        "Exact verification of Runge-Kutta, partitioned RK and general linear methods."))
    _global_options(p)
    parents = _parents()
    sub = p.add_subparsers(dest="command", required=True)
    for cmd in COMMANDS:
        shared = [parents["debug"]] + ([parents["timeout"]] if cmd.name in EXACT_COMMANDS + BUILT_WITHIN else [])
        extra = {} if cmd.description is None else {"description": cmd.description}
        parser = sub.add_parser(cmd.name, parents=shared, help=cmd.help, **extra)
        cmd.options(parser)
        parser.set_defaults(run=cmd.run)
        _mark_paths(parser)
    return p


class _Printable:
    """A text stream whose writes go through :func:`inputs.printable` (terminal escapes, lone
    surrogates and bidirectional overrides of a file's text shown escaped, never sent)."""

    def __init__(self, stream):
        self._stream = stream

    def write(self, text):
        return self._stream.write(printable(text))

    def __getattr__(self, name):
        return getattr(self._stream, name)


def _count(lo: int, hi: int):
    """An argparse type: an integer of ASCII digits in [lo, hi]."""
    def read(text: str) -> int:
        if not re.fullmatch(r"[+-]?[0-9]{1,12}", text.strip()):
            raise argparse.ArgumentTypeError(f"{text[:40]!r} is not an integer of at most 12 ASCII digits")
        n = int(text)
        if not lo <= n <= hi:
            raise argparse.ArgumentTypeError(f"{n} is not in {lo} … {hi}")
        return n
    read.__name__ = "integer"
    return read


def _window(text):
    """--window XMIN,XMAX,YMIN,YMAX (experiments.stability_plots.parse_window)."""
    from .experiments.stability_plots import parse_window
    try:
        return parse_window(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _seconds(text: str) -> float:
    """--timeout: seconds, 0 for no limit."""
    if not re.fullmatch(r"[0-9]{1,7}(\.[0-9]{1,3})?", text.strip()):
        raise argparse.ArgumentTypeError(f"{text[:40]!r} is not a number of seconds (0 … 9999999; 0: no limit)")
    return float(text)


def main(argv=None) -> int:
    """The command line.  Called as the program (``argv`` None) an exact command runs in a child
    process under a hard deadline (:func:`run_with_hard_deadline`); with ``argv`` given (tests, other
    programs) everything runs in this process, under the time budget's alarm only."""
    out, err = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = _Printable(out), _Printable(err)
    if argv is None:
        import gc
        gc.set_threshold(GC_YOUNG_THRESHOLD)
    try:
        args = build_parser().parse_args(argv)
        if argv is None:
            import signal
            signal.signal(signal.SIGTERM, _terminate)
            if args.command in EXACT_COMMANDS and args.timeout:
                return run_with_hard_deadline(args)
        return dispatch(args)
    finally:
        sys.stdout, sys.stderr = out, err


def _terminate(signum, frame):
    raise Terminated()


# allocations between two collections of the young generation in the program (CPython: 700).
# sympy's import and a run's build allocate millions of objects that live to the end: at 700 the
# collector walks them again and again (a quick run: about 0.3 s of 1.4, docs/speed.md "First run")
GC_YOUNG_THRESHOLD = 50_000
HARD_GRACE = 5.0              # seconds past --timeout after which an uninterruptible computation is killed


def run_with_hard_deadline(args) -> int:
    """Run the command in a forked child; kill it HARD_GRACE s after its time budget.  The alarm
    of the budget stops Python code, but not one long call into FLINT or GMP: this makes every
    budget end within HARD_GRACE s.  Ctrl-C reaches the child (same process group), which reports it."""
    import os
    import signal
    import time
    if not hasattr(os, "fork"):
        return dispatch(args)
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:                                  # the child: the command, then its exit code
        from .process import die_with_parent
        die_with_parent()
        code = EXIT_BUG
        try:
            code = dispatch(args)
        finally:
            with contextlib.suppress(Exception):
                sys.stdout.flush()
                sys.stderr.flush()
            os._exit(code if isinstance(code, int) else EXIT_BUG)
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    deadline = time.monotonic() + args.timeout + HARD_GRACE
    try:
        while True:
            done, status = os.waitpid(pid, os.WNOHANG)
            if done:
                code = os.waitstatus_to_exitcode(status)
                return code if code >= 0 else 128 - code
            if time.monotonic() > deadline:
                os.kill(pid, signal.SIGKILL)
                os.waitpid(pid, 0)
                print(f"tableau-lab: error: {_command_of(args)}: time budget of {args.timeout:g} s exceeded in "
                      f"a computation that could not be interrupted (stopped {HARD_GRACE:g} s later); raise it "
                      "with --timeout S", file=sys.stderr)
                return EXIT_INPUT
            time.sleep(0.02)
    finally:
        signal.signal(signal.SIGINT, old)


def _entry_limits(args) -> None:
    """Apply --entry-limit KEY=N (grammar.raise_limit): in this process, and in a run's build child."""
    if getattr(args, "entry_limit", None):
        from .exact.grammar import EntryError, raise_limit
        for item in args.entry_limit:
            key, _, value = item.partition("=")
            if not re.fullmatch(r"[0-9]{1,9}", value.strip()):
                raise EntryError(f"--entry-limit {item[:60]!r}: write KEY=N with N an integer, e.g. depth=100")
            raise_limit(key.strip(), int(value))


def _command_of(args) -> str:
    """The command and the inputs it was given (``verify of m.json, n.json``), for messages that
    have no entry to name (a budget killed in FLINT, a MemoryError, a RecursionError)."""
    names = []
    for key in ("files", "file", "paths", "scenes", "suite_dir"):
        v = getattr(args, key, None)
        names += [str(x) for x in v] if isinstance(v, (list, tuple)) else [str(v)] if v else []
    method = getattr(args, "method", None)
    if method and not names:
        names = [str(x) for x in method] if isinstance(method, (list, tuple)) else [str(method)]
    from .inputs import printable
    return printable(f"{args.command} of {', '.join(names)}" if names else args.command)
WRITING_COMMANDS = ("report", "audit", "run", "solve", "design", "convergence", "roundoff", "workprecision", "suite",
                    "replot", "stability", "bench")     # those that may write files (files.py guards every output)
NUMERIC_COMMANDS = ("run", "roundoff", "convergence", "workprecision", "suite", "bench")     # compiled kernels


def dispatch(args) -> int:
    """Run a parsed command (``args.run``) in this process and return its exit code: the entry
    limits applied, the environment's settings checked before any work, the time budget of the
    exact commands, and every error mapped to its exit code (module docstring): bad input and
    budgets 2, Ctrl-C 130, SIGTERM 143, an internal error 3 (one line; the traceback with --debug)."""
    from .budget import time_limit
    from .files import OutputError, command_inputs, lock_timeout
    try:
        _entry_limits(args)
        if args.command in WRITING_COMMANDS:
            lock_timeout()                  # a bad TABLEAU_LAB_LOCK_TIMEOUT refused before any work
        if args.command in NUMERIC_COMMANDS:
            from .numeric.kernels import cache_dir
            cache_dir()                     # and a TABLEAU_LAB_CACHE that is not a folder
        if args.command in EXACT_COMMANDS:
            from .exact import field
            field.FIELD_DEGREE_LIMIT = args.max_field_degree
        with command_inputs(), time_limit(args.timeout if args.command in EXACT_COMMANDS else None):
            return args.run(args)
    except KeyboardInterrupt as exc:        # Ctrl-C, or SIGTERM (Terminated)
        print(f"tableau-lab: {'terminated' if isinstance(exc, Terminated) else 'interrupted'}", file=sys.stderr)
        return EXIT_TERMINATED if isinstance(exc, Terminated) else EXIT_INTERRUPTED
    except InputError as exc:               # bad input, a budget: the message names what and where
        print(f"tableau-lab: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except OutputError as exc:              # an output that cannot be written: the previous one kept
        print(f"tableau-lab: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except (RecursionError, MemoryError) as exc:
        print(f"tableau-lab: error: {_command_of(args)}: the input is too large or too deeply nested to analyse "
              f"({type(exc).__name__})", file=sys.stderr)
        return EXIT_INPUT
    except BrokenPipeError:                 # the reader of our output went away
        return EXIT_CLAIM
    except Exception as exc:                # a bug
        if args.debug:
            import traceback
            traceback.print_exc()
        print(f"tableau-lab: internal error (a bug; please report it with the command that caused it): "
              f"{type(exc).__name__}: {str(exc)[:200]}" + ("" if args.debug else "; --debug shows the traceback"),
              file=sys.stderr)
        return EXIT_BUG


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
