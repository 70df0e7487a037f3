"""One executor interface for sweeps: in this process, a local process pool, a Dask cluster
(a LocalCluster on loopback here) — the same results, bit for bit; a task's exception comes back
naming the item; an unreachable scheduler is a clear error, quickly."""
import functools
import json
import math
import time
from pathlib import Path

import mpmath
import numpy as np
import pytest
from distributed import LocalCluster

from tableau_lab.cli import main
from tableau_lab.experiments.executor import SchedulerError, executor
from tableau_lab.experiments.runs import convergence, convergence_run, prepare_run

METHODS = Path(__file__).resolve().parents[1] / "methods"


@pytest.fixture(scope="module")
def cluster():
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as c:
        yield c.scheduler_address


def _executors(cluster):
    return {"serial": ("serial", None), "pool": (None, 2), "dask": (cluster, None)}


@pytest.mark.parametrize("name, problem, precision, steps", [
    ("rk4", "harmonic", "float64", (50, 100, 200, 400)),
    ("rk4", "harmonic", "float64", None),          # adaptive: batches as wide as the executor
    ("gauss2", "pendulum", "mp:32", (20, 40, 80)),
])
def test_convergence_identical_in_every_executor(cluster, name, problem, precision, steps):
    got = {key: convergence(METHODS / f"{name}.json", problem, T=10, steps=steps, precision=precision,
                            scheduler=s, workers=w).to_json()
           for key, (s, w) in _executors(cluster).items()}
    assert got["serial"] == got["pool"] == got["dask"]
    assert round(got["serial"]["slope"]) == 4


def test_final_states_identical_to_the_last_digit(cluster):
    _, P, _, nm = prepare_run(METHODS / "gauss2.json", "pendulum", "mp:32", None)
    task = functools.partial(convergence_run, nm, P, 10, "exact")
    finals = {}
    for key, (s, w) in _executors(cluster).items():
        with executor(s, w) as ex:
            finals[key] = [[mpmath.nstr(x, 32, strip_zeros=False) for x in p.final] for p in ex.map(task, [20, 40])]
    assert finals["serial"] == finals["pool"] == finals["dask"]


def test_task_exception_names_the_item(cluster):
    for s, w in _executors(cluster).values():
        with executor(s, w) as ex:
            with pytest.raises(ValueError, match=r"^task 3 of 4 \(x = -1\): math domain error"):
                ex.map(math.sqrt, [4, 9, -1, 16], describe=lambda x: f"x = {x}")
            assert ex.map(math.sqrt, [4, 9]) == [2, 3]     # still usable after a failure


def test_unreachable_scheduler_is_a_clear_error(capsys, tmp_path):
    t = time.monotonic()
    with pytest.raises(SchedulerError, match="tcp://127.0.0.1:1"):
        with executor("tcp://127.0.0.1:1", timeout=1):
            pass
    assert time.monotonic() - t < 10
    with pytest.raises(ValueError, match="tcp://HOST:PORT"):
        with executor("127.0.0.1"):
            pass
    assert main(["convergence", str(METHODS / "rk4.json"), "--problem", "harmonic", "--out", str(tmp_path),
                 "--scheduler", "tcp://127.0.0.1:1"]) == 2
    assert "tcp://127.0.0.1:1" in capsys.readouterr().err


def test_cli_on_the_cluster(cluster, tmp_path):
    args = ["convergence", str(METHODS / "rk4.json"), "--problem", "harmonic"]
    assert main(args + ["--out", str(tmp_path / "dask"), "--scheduler", cluster]) == 0
    assert main(args + ["--out", str(tmp_path / "serial"), "--workers", "1"]) == 0

    def read(d):
        return json.loads((tmp_path / d / "convergence_harmonic_float64.json").read_text())
    assert read("dask") == read("serial")


def test_design_search_identical_in_every_executor(cluster):
    """The design search's sample and local searches give the same candidates in this process, a
    pool of 2 and the Dask cluster (issue 18)."""
    from tableau_lab.analysis.family import families_of
    from tableau_lab.experiments.design_search import search
    fam = families_of(str(METHODS / "design" / "pn_family.json"), ["g-symplectic"])[0]
    got = {key: str(search(fam, maximize="imaginary-interval", constraints=("order=4",), box=(-3.0, 3.0), seed=1,
                           samples=64, starts=2, certify=False, scheduler=s, workers=w))
           for key, (s, w) in _executors(cluster).items()}
    assert got["serial"] == got["pool"] == got["dask"]
    assert "u = 2.154700538" in got["serial"]


def test_four_parameter_design_search_identical_in_every_executor(cluster):
    """A family with four free parameters and three equality constraints (GLM43's symmetric family,
    docs/design.md): the same candidates in this process, a pool of 2 and the Dask cluster, and the
    optimum at the member that beats GLM43 (error norm 0.0110023 at y = 0)."""
    from tableau_lab.analysis.family import families_of
    from tableau_lab.experiments.design_search import search
    fam = families_of(str(METHODS / "design" / "glm4_symmetric_family.json"), [])[0]
    got = {key: search(fam, minimize="error-norm", constraints=("order=4", "parasitism-free", "explicit-first-stage"),
                       box=(-1.0, 1.0), seed=0, samples=32, starts=2, certify=False, scheduler=s, workers=w)
           for key, (s, w) in _executors(cluster).items()}
    # the best member agrees: b21, d1, x to 1e-8 and the error norm to 1e-12.  The optimum sits at y = 0, where the
    # error norm is even in y (flat to second order), so y is found only to about 1e-6, and the SLSQP paths (and
    # evaluation counts) differ in the last bits between processes after other searches ran in this one
    # (seen in CI: y = 4.76e-7 against 4.29e-7, 1199 against 1204 evaluations)
    best = {k: (np.array(r.candidates[0].point), r.candidates[0].values["error-norm"]) for k, r in got.items()}
    for k in ("pool", "dask"):
        assert np.allclose(best[k][0][:3], best["serial"][0][:3], atol=1e-8) and abs(best[k][0][3]) < 1e-5
        assert abs(best[k][1] - best["serial"][1]) < 1e-12
    assert abs(best["serial"][0][1] + 0.04874221937) < 1e-9 and abs(best["serial"][1] - 0.0110023) < 1e-7
