"""The set of NodePy methods that docs/nodepy.md speaks of, loaded once for the benchmarks that use it
(``nodepy_compare.py``, ``nodepy_stability.py``).

* ``rk_methods()``: the Runge–Kutta methods of the comparison — the named ones of
  ``nodepy.rk.loadRKM('All')`` and the generated families SSPRK2/3, SSPIRK1/2/3, extrap, DC,
  RKC1/2 (sizes up to 6 where the size is s).
* ``stability_methods()``: those, and what the stability run adds — the larger deferred-correction
  methods DC(4), DC(5) (17 and 26 stages) and the Picard pairs DC_pair(2 … 5), the exact low-storage
  methods of ``nodepy.low_storage_rk.load_low_storage('All')`` (Carpenter–Kennedy 2N and 2R+ pairs), and the
  exact linear multistep methods: Adams–Bashforth, BDF, Nyström, Milne–Simpson and the optimal
  2nd-order SSP methods of 1 … 8 steps, Sand's circle-contractive methods sand_cc(0 … 4) (up to 17
  steps) and ``nodepy.lm.loadLMM('All')``'s eBDF5.  NodePy's Adams–Moulton methods have
  floating-point α (1.0): inexact, skipped like the RK methods with floats.

Each entry is (name, NodePy object); a size NodePy does not build is listed in ``skipped``.
"""
from __future__ import annotations

import warnings


def _families(rk, spec):
    out, skipped = [], []
    for fam, size, label in spec:
        try:
            out.append((label, getattr(rk, fam)(size)))
        except Exception as exc:          # a size NodePy does not build
            skipped.append((label, f"NodePy: {type(exc).__name__}: {exc}"[:120]))
    return out, skipped


def rk_methods():
    """(methods, skipped) of the comparison (module docstring)."""
    warnings.filterwarnings("ignore", module="nodepy")
    from nodepy import rk
    methods = sorted(rk.loadRKM("All").items())
    spec = [("SSPRK2", m) for m in range(2, 7)] + [("SSPRK3", m) for m in (4, 9)] \
        + [("SSPIRK1", m) for m in range(1, 7)] + [("SSPIRK2", m) for m in range(1, 7)] \
        + [("SSPIRK3", m) for m in range(2, 7)] + [("extrap", s) for s in range(1, 7)] \
        + [("DC", s) for s in range(0, 4)] + [("RKC1", m) for m in range(2, 7)] + [("RKC2", m) for m in range(2, 7)]
    fam, skipped = _families(rk, [(f, n, f"{f}({n})") for f, n in spec])
    return methods + fam, skipped


def stability_methods():
    """(methods, skipped) of the stability run (module docstring): RK methods, then LMMs."""
    warnings.filterwarnings("ignore", module="nodepy")
    from nodepy import lm, rk
    methods, skipped = rk_methods()
    more, sk = _families(rk, [("DC", s, f"DC({s})") for s in (4, 5)]
                         + [("DC_pair", s, f"DC_pair({s})") for s in range(2, 6)])
    methods, skipped = methods + more, skipped + sk
    from nodepy import low_storage_rk
    methods += sorted(low_storage_rk.load_low_storage("All").items())
    spec = [("Adams_Bashforth", k) for k in range(1, 9)] + [("backward_difference_formula", k) for k in range(1, 9)] \
        + [("Nystrom", k) for k in range(2, 9)] + [("Milne_Simpson", k) for k in range(3, 9)] \
        + [("elm_ssp2", k) for k in range(2, 9)] + [("sand_cc", s) for s in range(0, 5)] \
        + [("Adams_Moulton", k) for k in range(1, 9)]
    more, sk = _families(lm, [(f, n, f"{f}({n})") for f, n in spec])
    methods, skipped = methods + more, skipped + sk
    methods += sorted((k, v) for k, v in lm.loadLMM("All").items() if type(v).__name__ == "LinearMultistepMethod")
    return methods, skipped
