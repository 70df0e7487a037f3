r"""Methods by name: the shipped library and the generated families, in one registry.

A library method is named by its file's stem (``"gauss2"``, ``"example4_glm"``: the JSON files of
``methods/``, installed with the package as ``tableau_lab/methods``).  A family is named with its
size, ``"bdf:5"`` or ``"gauss:3"`` (command line and API), or ``family("bdf", k=5)``.  Each
builds the method exactly (:mod:`families`, :mod:`multistep`).  The explicit SSP methods:
``ssprk:s`` (SSPRK(s,s), s = 1, 2, 3: forward Euler, Heun, Shu–Osher), ``ssprk2:s``, ``ssprk3:s``
(s = 3 or a square) and ``ssprk4:10`` — SSPRK(s, p) with s stages and order p — and the aliases
``ssp22``, ``ssp33``, ``ssp104`` (NodePy's names).

>>> library_path("gauss2").name, "example4_glm" in library_names()
('gauss2.json', True)

>>> family("adams_moulton:2").name
'Adams–Moulton, 2 steps (as a GLM)'
>>> family("ssprk:3").name, family("ssp104").s
('SSPRK(3,3), Shu–Osher, SSP coefficient 1', 10)
>>> family("bdf", k=3).V[0, :]
Matrix([[18/11, -9/11, 2/11]])
>>> family("gauss:0")
Traceback (most recent call last):
...
tableau_lab.exact.library.FamilyError: gauss:0: the number of stages must be an integer 1 … 8, not 0
"""
from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

from ..errors import InputError
from . import families, multistep
from .methods import Method

__all__ = ["FamilyError", "FAMILIES", "ALIASES", "family", "family_sizes", "is_family", "library_path", "library_names",
           "LIBRARY"]

#: the shipped tableau files (a link to the repository's methods/ in a source checkout)
LIBRARY = Path(__file__).resolve().parent.parent / "methods"


class FamilyError(InputError):
    """A family name or size that does not give a method (the message names the spec)."""


# name -> (constructor, size keyword, largest size, what the size counts)
FAMILIES: dict[str, tuple[Callable[[int], Method], str, int, str]] = {
    "gauss": (families.gauss, "s", families.MAX_STAGES, "stages"),
    "radau_iia": (families.radau_iia, "s", families.MAX_STAGES, "stages"),
    "lobatto_iiia": (families.lobatto_iiia, "s", families.MAX_STAGES, "stages"),
    "radau_ia": (families.radau_ia, "s", families.MAX_STAGES, "stages"),
    "lobatto_iiib": (families.lobatto_iiib, "s", families.MAX_STAGES, "stages"),
    "lobatto_iiic": (families.lobatto_iiic, "s", families.MAX_STAGES, "stages"),
    "lobatto_iiic_star": (families.lobatto_iiic_star, "s", families.MAX_STAGES, "stages"),
    "sdirk_crouzeix": (families.sdirk_crouzeix, "s", 3, "stages"),
    "sdirk_alexander": (families.sdirk_alexander, "s", 3, "stages"),
    **{name: (getattr(multistep, name), "k", multistep.MAX_STEPS, "steps") for name in multistep.FAMILIES},
    "ssprk": (families.ssprk, "s", 3, "stages"),
    "ssprk2": (families.ssprk2, "s", families.MAX_SSP_STAGES, "stages"),
    "ssprk3": (families.ssprk3, "s", families.MAX_SSP_STAGES, "stages"),
    "ssprk4": (families.ssprk4, "s", 10, "stages"),
}

#: the sizes each family is built for, where they are not all of 1 … largest (the constructors
#: refuse the others with the reason; tests/test_ssp_families.py checks the two agree)
_SIZES = {
    **{name: range(2, families.MAX_STAGES + 1) for name in ("lobatto_iiia", "lobatto_iiib", "lobatto_iiic",
                                                             "lobatto_iiic_star")},
    "sdirk_crouzeix": (2, 3), "sdirk_alexander": (2, 3),
    "nystrom": range(2, multistep.MAX_STEPS + 1), "milne_simpson": range(2, multistep.MAX_STEPS + 1),
    "ssprk2": range(2, families.MAX_SSP_STAGES + 1),
    "ssprk3": (3,) + tuple(n * n for n in range(2, families.MAX_SSP_STAGES) if n * n <= families.MAX_SSP_STAGES),
    "ssprk4": (10,),
}

#: other names of single family members (NodePy's loadRKM keys, lower-cased)
ALIASES = {"ssp22": "ssprk2:2", "ssp33": "ssprk3:3", "ssp104": "ssprk4:10"}

_SPEC = re.compile(r"(?P<name>[a-z_][a-z0-9_]*)(?::(?P<size>[^:]*))?")


def family_sizes(name: str) -> tuple[int, ...]:
    """The sizes (stages or steps, as FAMILIES says) the family ``name`` is built for.

    >>> family_sizes("ssprk3"), family_sizes("sdirk_alexander"), family_sizes("gauss")[-1]
    ((3, 4, 9, 16, 25), (2, 3), 8)
    """
    if name not in FAMILIES:
        raise FamilyError(f"{name}: not a method family; known: {', '.join(sorted(FAMILIES))}")
    return tuple(_SIZES.get(name, range(1, FAMILIES[name][2] + 1)))


def is_family(spec: object) -> bool:
    """``spec`` names a family ("bdf:5", "gauss:3", or the bare name) or is one of its ALIASES."""
    m = _SPEC.fullmatch(str(spec))
    return m is not None and m.group("name") in FAMILIES or str(spec) in ALIASES


def family(spec: str, **size: int) -> Method:
    """The method ``spec`` ("name:n") or ``family("name", s=n)`` / ``family("name", k=n)``; an
    alias ("ssp104") is the member it names."""
    if str(spec) in ALIASES and not size:
        spec = ALIASES[str(spec)]
    m = _SPEC.fullmatch(str(spec))
    if not m or m.group("name") not in FAMILIES:
        raise FamilyError(f"{spec}: not a method family; known: {', '.join(sorted(FAMILIES))}")
    name = m.group("name")
    build, key, largest, unit = FAMILIES[name]
    if m.group("size") is not None and size:
        raise FamilyError(f"{spec}: give the size once, in the name or as {key}=")
    if set(size) - {key}:
        raise FamilyError(f"{spec}: the size of {name} is {key}=, not {', '.join(sorted(size))}=")
    raw = m.group("size") if m.group("size") is not None else size.get(key)
    if raw is None:
        sizes = family_sizes(name)
        which = (f"= {sizes[0]}" if len(sizes) == 1 else f"{sizes[0]} … {sizes[-1]}"
                 if sizes == tuple(range(sizes[0], sizes[-1] + 1)) else "one of " + ", ".join(map(str, sizes)))
        raise FamilyError(f"{spec}: the number of {unit} is missing (write {name}:N, N {which})")
    shown = raw if len(str(raw)) <= 20 else f"{str(raw)[:12]}… ({len(str(raw))} characters)"
    n = int(raw) if isinstance(raw, str) and raw.isdigit() and len(raw) <= 12 else raw
    label = f"{name}:{shown}"
    if not isinstance(n, int) or isinstance(n, bool) or not 1 <= n <= largest:
        raise FamilyError(f"{label}: the number of {unit} must be an integer 1 … {largest}, not {shown}")
    try:
        return build(n)
    except ValueError as exc:               # MethodError, or no exact construction at this size
        raise FamilyError(f"{label}: {exc}") from None


def library_names() -> list[str]:
    """The names of the shipped tableau files."""
    return sorted(p.stem for p in LIBRARY.glob("*.json")) if LIBRARY.is_dir() else []


def library_path(name: object) -> Path | None:
    """The shipped file named ``name`` (its stem, without .json), or None."""
    if not re.fullmatch(r"[A-Za-z0-9_]+", str(name)):
        return None
    path = LIBRARY / f"{name}.json"
    return path if path.is_file() else None
