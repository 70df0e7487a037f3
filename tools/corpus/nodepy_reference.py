"""NodePy's own values for its methods, computed by the installed nodepy, for comparison with the
certified (ball) analysis: order, embedded order, stage order, SSP coefficient (absolute
monotonicity radius) and real stability interval, as NodePy prints them (its floats' repr, kept as
strings; NodePy's default tolerances).  Written to corpus/nodepy/nodepy_reference.json with nodepy's
and numpy's versions.  Usage::

    python -m tools.corpus.nodepy_reference [OUT]
"""
from __future__ import annotations

import json
import sys
import time
import warnings
from pathlib import Path

from tableau_lab.files import atomic_write_text

#: the methods whose values are recorded: NodePy's floating-point methods (docs/nodepy.md skips
#: them) and the exact ones of loadRKM, keyed as in loadRKM
FLOATING = ("CMR6", "PD8", "SSP22star", "SSP33", "SSP53", "SSP54", "SSP63", "SSP75", "SSP85", "SSP95", "Tsit5")
QUANTITIES = {
    "order": lambda m: m.order(),
    "embedded_order": lambda m: m.embedded_method.order(),
    "stage_order": lambda m: m.stage_order(),
    "ssp_coefficient": lambda m: m.absolute_monotonicity_radius(),
    "real_stability_interval": lambda m: m.real_stability_interval(),
}


def values(rkm) -> dict:
    out, errors = {}, {}
    for key, f in QUANTITIES.items():
        if key == "embedded_order" and not hasattr(rkm, "embedded_method"):
            continue
        try:
            v = f(rkm)
        except Exception as exc:                      # NodePy has no such method for this kind
            errors[key] = f"{type(exc).__name__}: {exc}"[:160]
            continue
        out[key] = v if isinstance(v, int) and not isinstance(v, bool) else repr(float(v))
    if errors:
        out["nodepy_errors"] = errors
    return out


def main(argv: list[str]) -> None:
    warnings.filterwarnings("ignore")
    import nodepy
    import numpy
    from nodepy import rk
    out = Path(argv[0] if argv else "corpus") / "nodepy"
    methods = rk.loadRKM("All")
    record = {"nodepy": nodepy.__version__, "numpy": numpy.__version__,
              "command": "python -m tools.corpus.nodepy_reference " + " ".join(argv),
              "note": "NodePy's floats are written as their repr; orders with NodePy's default tolerance",
              "methods": {}}
    for key in sorted(methods):
        if key == "Söderlind43":
            continue
        t = time.process_time()
        record["methods"][key] = {"floating_point": key in FLOATING, **values(methods[key])}
        print(f"{key}: {time.process_time() - t:.2f} s CPU", file=sys.stderr)
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out / "nodepy_reference.json",
                      json.dumps(record, indent=1, ensure_ascii=False, sort_keys=True) + "\n")


if __name__ == "__main__":
    main(sys.argv[1:])
