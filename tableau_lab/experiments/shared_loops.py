"""The compiled loops shared by every problem, built once per installation (issue 32).

A linked loop (:mod:`~tableau_lab.numeric.linked`) is one module per stage iteration (explicit,
Newton, fixed point, the q-stage iteration of a separable problem) and projection (on or off):
eight modules serving every problem and method shape, each a 6–14 s compile, kept in
:func:`~tableau_lab.numeric.kernels.shared_dir` apart from the problems' cache.  Once they are
built, a run whose specialised loop is not compiled goes on the linked loop after compiling only
its problem's entry points (about a second) instead of a whole loop (the cost rule,
``integrate(kernel="cost")``: ``tableau-lab run``, scenes, :func:`tableau_lab.integrate`).

:func:`warm_up` (``tableau-lab warm-up``) builds them: each by one step of a small method on the
harmonic oscillator, the compile in a pool of processes (one per core, at most two).

>>> [label for label, _ in LOOPS][:3]
['explicit', 'explicit, projection', 'NEWTON']
"""
from __future__ import annotations

import os
import time
from concurrent.futures import ProcessPoolExecutor

__all__ = ["LOOPS", "warm_up", "build_one"]

#: (label, (method, stage iteration, projection)) of the eight shared loops
LOOPS = [(f"{mode}{', projection' if projects else ''}", (method, mode, projects))
         for method, mode in (("rk4", "explicit"), ("gauss2", "NEWTON"), ("gauss2", "FIXED"), ("gauss2", "SPLIT"))
         for projects in (False, True)]


def build_one(method: str, mode: str, projects: bool) -> tuple:
    """Compile (or find in the cache) the shared loop of one stage iteration and projection: one
    step of ``method`` on the harmonic oscillator in it.  (seconds, its state before: "cached",
    "loaded" or "cold")."""
    import numpy as np

    from ..exact.tableau_json import load
    from ..numeric import kernels, limits as L
    from ..numeric.codegen import compile_problem
    from ..numeric.export import to_numeric
    from ..numeric.integrate import component_masks

    t0 = time.perf_counter()
    nm, cp = to_numeric(load(method)), compile_problem("harmonic")
    y0 = np.asarray(cp.y0, dtype=float)
    project = ("H",) if projects else ()
    targets = {"H": cp.invariant("H", y0)}
    iteration = L.NEWTON if mode == "explicit" else getattr(L, mode)     # an explicit method's shape says EXPLICIT
    pk = kernels.Pack(nm, cp, 0.01, component_masks(cp, len(y0)), mode=iteration, project=project, track=("H",),
                      targets=targets, index=kernels.invariant_index(cp))
    shape = kernels.run_shape(pk)
    state = kernels.linked_state(shape)
    loop = kernels.linked_loop(cp.problem, shape)
    kernels.drive(loop, pk, np.array([y0]), 1, 1, record=lambda n, Y: None)
    return time.perf_counter() - t0, state


def warm_up(progress=print, workers: int | None = None) -> dict:
    """Build the eight shared loops (:data:`LOOPS`) in :func:`~tableau_lab.numeric.kernels.shared_dir`:
    label -> (seconds, state before).  ``progress``: called with one line per loop (None: silent);
    ``workers``: processes (default: the cores, at most two).  Measured: docs/speed.md ("No
    waiting on a compile").

    >>> len(LOOPS), LOOPS[-1]
    (8, ('SPLIT, projection', ('gauss2', 'SPLIT', True)))

    Once per installation (about a minute on two cores):

    >>> import tableau_lab as tl
    >>> tl.warm_up()          # doctest: +SKIP
    """
    from ..numeric.kernels import shared_dir
    workers = workers or max(1, min(2, os.cpu_count() or 1))
    if progress:
        progress(f"building the {len(LOOPS)} compiled loops shared by every problem in {shared_dir()} "
                 f"({workers} processes; once per installation) ...")
    out = {}
    with ProcessPoolExecutor(workers) as pool:
        futures = [(label, pool.submit(build_one, *spec)) for label, spec in LOOPS]
        for label, fut in futures:
            out[label] = fut.result()
            if progress:
                seconds, state = out[label]
                progress(f"  {label}: {'already built' if state != 'cold' else 'built'} ({seconds:.1f} s)")
    return out
