r"""Rationals of small height in an interval: the Stern–Brocot (continued-fraction) search.

The height of p/q (lowest terms, q > 0) is max(|p|, q).  The *simplest* rational of an interval —
the first one the Stern–Brocot tree reaches — has both the smallest denominator and the smallest
|numerator| of all rationals in the interval, so it is also the one of smallest height
(Graham, Knuth & Patashnik, *Concrete Mathematics*, 2nd ed., Sec. 4.5; Khinchin, *Continued
Fractions*, Sec. 6).  It is found from the continued fractions of the two ends: the integer part
when an integer lies inside, else n + 1/y with y the simplest rational of the reflected interval.

>>> simplest_between(Fraction(3, 10), Fraction(2, 5))
Fraction(1, 3)
>>> simplest_between(-2, -1.5), simplest_between(-1, 1), simplest_between(0, 1, open_lo=True, open_hi=True)
(Fraction(-2, 1), Fraction(0, 1), Fraction(1, 2))
>>> from itertools import islice
>>> [str(r) for r in islice(by_height(Fraction(-2), Fraction(2), near=-1.9), 5)]   # ties: nearest first
['0', '-1', '1', '-2', '-1/2']
>>> height(Fraction(-450464, 911121))
911121
"""
from __future__ import annotations

import heapq
from collections.abc import Iterator
from fractions import Fraction
from math import floor
from typing import Any

#: what Fraction() takes exactly: an int, a Fraction, a float (its binary value), a decimal string
Rat = int | float | Fraction | str

__all__ = ["simplest_between", "by_height", "height"]


def height(r: Any) -> int:
    """max(|numerator|, denominator) of a rational (a Fraction, an int or a sympy Rational)."""
    f = Fraction(int(r.p), int(r.q)) if hasattr(r, "q") else Fraction(r)
    return max(abs(f.numerator), f.denominator)


def simplest_between(lo: Rat, hi: Rat | None = None, *, open_lo: bool = False, open_hi: bool = False) -> Fraction:
    """The rational of smallest height in the interval from ``lo`` to ``hi`` (``hi`` None: no upper
    bound), closed at each end unless ``open_lo``/``open_hi``; the ends are converted exactly
    (a float is its binary value).  ValueError for an empty interval."""
    lo, hi = Fraction(lo), None if hi is None else Fraction(hi)
    if hi is not None and not (lo < hi or (lo == hi and not open_lo and not open_hi)):
        raise ValueError(f"empty interval from {lo} to {hi}")

    def inside(x: Fraction | int) -> bool:
        return (lo < x if open_lo else lo <= x) and (hi is None or (x < hi if open_hi else x <= hi))
    if inside(0):
        return Fraction(0)
    if hi is not None and hi <= 0:
        return -simplest_between(-hi, -lo, open_lo=open_hi, open_hi=open_lo)
    n = floor(lo)
    k = n if (lo == n and not open_lo) else n + 1          # the smallest integer that can lie inside
    if inside(k):
        return Fraction(k)
    # no integer inside: the interval lies in [n, n + 1]; x = n + 1/y maps it onto an interval of y
    assert hi is not None                                  # unbounded above, k would lie inside
    y = simplest_between(1 / (hi - n), None if lo == n else 1 / (lo - n), open_lo=open_hi, open_hi=open_lo)
    return n + 1 / y


def by_height(lo: Fraction, hi: Fraction, near: float = 0.0) -> Iterator[Fraction]:
    """The rationals of the closed interval [lo, hi], smallest height first (ties: nearest to
    ``near`` first), without end: each one found splits its interval in two open at it."""
    def entry(a: Fraction, b: Fraction, oa: bool, ob: bool) -> tuple[int, float, Fraction, Fraction, Fraction,
                                                                      bool, bool]:
        r = simplest_between(a, b, open_lo=oa, open_hi=ob)
        return (height(r), abs(float(r) - near), r, a, b, oa, ob)
    heap = [entry(Fraction(lo), Fraction(hi), False, False)]
    while heap:
        _, _, r, a, b, oa, ob = heapq.heappop(heap)
        yield r
        if a < r:
            heapq.heappush(heap, entry(a, r, oa, True))
        if r < b:
            heapq.heappush(heap, entry(r, b, True, ob))
