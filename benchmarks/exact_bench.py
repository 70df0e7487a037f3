"""Timings of the exact analyses against the issue targets (a benchmark, not a test).

    python benchmarks/exact_bench.py

Prints seconds and the ratio to each target (ratio < 1 meets it).
"""
import glob
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def timed(fn):
    t = time.perf_counter()
    out = fn()
    return time.perf_counter() - t, out


def main():
    from tableau_lab.analysis.glm_order import glm_order
    from tableau_lab.analysis.rk_order import rk_order
    from tableau_lab.analysis.stability import stability
    from tableau_lab.analysis.verify import verify
    from tableau_lab.exact.families import gauss
    from tableau_lab.exact.tableau_json import load

    rows = []
    t, m = timed(lambda: gauss(5))
    rows.append(("build Gauss 5 (nested radicals, degree-8 field)", t, None))
    t, r = timed(lambda: rk_order(m))
    assert r.order == 10 and r.residuals and len(r.weights) == 1205 + 1842
    rows.append(("Gauss 5: order 10 pinned through order-11 conditions (elementary weights)", t, 10.0))
    t, r = timed(lambda: glm_order(m, max_order=10))
    assert r.order_identity_start == 10 and not r.capped
    rows.append(("Gauss 5: the same by GLM theory (starting-method solve, r = 1)", t, 10.0))
    t, r = timed(lambda: glm_order(load(ROOT / "methods/example4_glm.json")))
    rows.append(("Example 4 GLM order (starting method, theta free and theta = 0)", t, 5.0))
    glm4s = ROOT / "methods/glm4_symmetric.json"          # seven square roots, a degree-16 field (docs/design.md)
    t, m = timed(lambda: load(glm4s))
    rows.append(("GLM4S: load (square roots over a basis, degree 16)", t, None))
    t, v = timed(lambda: verify(m))
    assert v.ok
    rows.append(("GLM4S: verify (G-symplecticity, order, parasitism)", t, None))
    t, st = timed(lambda: stability(m))
    assert abs(float(st.bounded_radius) - 1.72571401762551) < 1e-12
    rows.append(("GLM4S: exact Y* (axis analysis in the coefficient subfield Q(sqrt(265551)))", t, None))
    files = sorted(glob.glob(str(ROOT / "methods/*.json")))
    t, p = timed(lambda: subprocess.run([sys.executable, "-m", "tableau_lab", "verify", *files], capture_output=True))
    assert p.returncode == 0
    rows.append((f"tableau-lab verify methods/*.json ({len(files)} files, one process)", t, 10.0))
    bad = sorted(glob.glob(str(ROOT / "tests/data/bad/*.json")))
    worst = max(timed(lambda f=f: subprocess.run([sys.executable, "-m", "tableau_lab", "verify", f],
                                                 capture_output=True))[0] for f in bad)
    rows.append((f"slowest rejection of a hostile file ({len(bad)} files, one process each)", worst, 1.0))
    for name, secs, target in rows:
        ratio = "" if target is None else f"  ratio to target {target:g} s: {secs / target:.2f}"
        print(f"{secs:8.2f} s  {name}{ratio}")


if __name__ == "__main__":
    main()
