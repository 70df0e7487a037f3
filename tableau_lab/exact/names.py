r"""Names of methods for people: "did you mean …" for a name that is neither a file, a shipped
method nor a family (``tl.load`` and every command that reads a tableau).

A name is compared, case folded and with the separators ``-``, ``_``, ``:`` and spaces set aside,
with every shipped name, every alias and every family member written ``family:N`` (N a size
the family is built for), by :func:`difflib.get_close_matches` (Ratcliff–
Obershelp similarity, cut-off :data:`CUTOFF`), then the names that contain it; a name equal
after folding is the one suggestion.

>>> suggestions("RK4"), suggestions("bdf4"), suggestions("gaus:3")[0], suggestions("SSP104")
(['rk4'], ['bdf:4'], 'gauss:3', ['ssp104'])
>>> suggestions("ssprk33"), suggestions("gaus:3")
(['ssprk3:3'], ['gauss:3'])
>>> did_you_mean("RK4")
'; did you mean rk4?'
>>> did_you_mean("zzzz")
''
"""
from __future__ import annotations

import difflib
import re

from .library import ALIASES, FAMILIES, family_sizes, library_names

__all__ = ["suggestions", "did_you_mean", "CUTOFF", "MOST"]

#: similarity (difflib's ratio, 0 … 1) below which a name is not suggested
CUTOFF = 0.6
#: names suggested at most
MOST = 3
#: a typed name longer than this is not compared (a path, a JSON text): no suggestion
LONGEST = 80


def _fold(name: str) -> str:
    return re.sub(r"[-_:\s]+", "", name.casefold())


def _candidates(typed: str) -> list[str]:
    """Every shipped name, every alias and every ``family:N`` of a size the family is built for;
    the families first when the typed name has a colon (``gaus:3`` → ``gauss:3`` rather than
    the file gauss3)."""
    families = [f"{name}:{n}" for name in FAMILIES for n in family_sizes(name)] + list(ALIASES)
    return families + library_names() if ":" in typed else library_names() + families


def suggestions(typed: object) -> list[str]:
    """Up to :data:`MOST` known names close to ``typed``, the closest first (module docstring)."""
    typed = str(typed)
    if not typed or len(typed) > LONGEST or "/" in typed or typed.lstrip().startswith("{"):
        return []
    names = _candidates(typed)
    by_fold: dict[str, str] = {}
    for n in names:
        by_fold.setdefault(_fold(n), n)
    key = _fold(typed)
    if key in by_fold:                       # the same name but for case and separators
        return [by_fold[key]]
    close = [by_fold[k] for k in difflib.get_close_matches(key, list(by_fold), n=5 * MOST, cutoff=CUTOFF)]
    inside = [n for k, n in by_fold.items() if len(key) >= 4 and key in k]    # "euler": explicit_euler, …
    one: dict[str, str] = {}                                 # a family once: its closest member
    for n in close + inside:
        one.setdefault(n.split(":")[0], n)
    return list(one.values())[:MOST]


def did_you_mean(typed: object) -> str:
    """``"; did you mean X?"`` (or ``X or Y``) for a message about ``typed``, or ``""``."""
    found = suggestions(typed)
    if not found:
        return ""
    return "; did you mean " + (found[0] if len(found) == 1 else ", ".join(found[:-1]) + " or " + found[-1]) + "?"
