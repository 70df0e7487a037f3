"""A Python callable traced to sympy expressions (issue 30, item 2; experiments/tracing.py):
the expressions are compared with the ones written by hand for the same right-hand sides
(structural equality after expansion: independent of the trace), the refusals name their
reason, the checks against the callable catch hidden state, and the trace is bounded."""
import math

import numpy as np
import pytest
import sympy as sp

from tableau_lab.experiments import tracing
from tableau_lab.experiments.tracing import agrees, symbols, trace_callable

t, (y1, y2, y3, y4) = symbols(4)


def same(got, want):
    return len(got) == len(want) and all(sp.expand(a - sp.sympify(b)) == 0 for a, b in zip(got, want, strict=False))


@pytest.mark.parametrize("f, want", [
    (lambda t, y: -y[::-1], [-y4, -y3, -y2, -y1]),                                      # array arithmetic
    (lambda t, y: np.concatenate([y[2:], -y[:2] / np.linalg.norm(y[:2]) ** 3]),         # Kepler, numpy's norm
     [y3, y4, -y1 / (y1**2 + y2**2) ** sp.Rational(3, 2), -y2 / (y1**2 + y2**2) ** sp.Rational(3, 2)]),
    (lambda t, y: [y[1], -np.sin(y[0]) + 0.1 * np.cos(t), y[3] ** 0.5, np.exp(-y[2]) * np.arctan(y[0])],
     [y2, -sp.sin(y1) + sp.cos(t) / 10, sp.sqrt(y4), sp.exp(-y3) * sp.atan(y1)]),
    (lambda t, y: (y @ y) * y, [(y1**2 + y2**2 + y3**2 + y4**2) * v for v in (y1, y2, y3, y4)]),
    (lambda t, y: [sp.tanh(y[0]), 2, np.float64(1.5), sum(y)], [sp.tanh(y1), 2, sp.Rational(3, 2), y1 + y2 + y3 + y4]),
    (lambda t, y: np.zeros_like(y) + np.square(y), [y1**2, y2**2, y3**2, y4**2]),
])
def test_traces_are_the_expressions_written_by_hand(f, want):
    exprs, why = trace_callable(f, 4)
    assert why == "" and same(exprs, want), (exprs, why)
    assert not any(e.atoms(sp.Float) for e in exprs)          # constants read exactly (0.1 is 1/10)


@pytest.mark.parametrize("f, reason", [
    (lambda t, y: [math.sin(y[0])] * 4, "needs a number where it has a symbol"),
    (lambda t, y: [y[0] if y[1] >= 0 else -y[0]] * 4, "branches on a value (y2 >= 0"),
    (lambda t, y: [y[0] / y[1] if y[1] != 0 else y[0]] * 4, "branches on a value (y2 != 0"),
    (lambda t, y: np.abs(y), "bad operand type for abs()"),
    (lambda t, y: np.floor(y[0]) * y, "numpy's floor, which is outside the problem grammar"),
    (lambda t, y: np.zeros(4) + np.array([y[0], 0, 0, 0], dtype=float), "needs a number"),
    (lambda t, y: y ** y[0], "exponents must be rational constants"),
    (lambda t, y: y[:3], "returned 3 values for a state of dimension 4"),
    (lambda t, y: [sp.Symbol("k") * y[0]] * 4, "has the symbols k"),
    (lambda t, y: [sp.Abs(y[0])] * 4, "uses Abs, which is outside the problem grammar"),
    (lambda t, y: ["y1"] * 4, "is a str, not an expression"),
])
def test_untraceable_callables_say_why(f, reason):
    exprs, why = trace_callable(f, 4)
    assert exprs is None and reason in why, why


def test_the_trace_is_bounded(monkeypatch):
    monkeypatch.setattr(tracing, "TRACE_OPERATIONS", 50)
    exprs, why = trace_callable(lambda t, y: [sum(y[0] * k for k in range(100))] * 4, 4)
    assert exprs is None and "more than 50 operations (TRACE_OPERATIONS)" in why
    monkeypatch.setattr(tracing, "TRACE_SECONDS", 0.0)
    exprs, why = trace_callable(lambda t, y: y + 1, 4)
    assert exprs is None and "(TRACE_SECONDS)" in why


def test_agreement_is_checked_at_perturbed_points():
    """A callable that agrees with its trace at (t0, y0) only (its hidden state changes after
    the first call) is caught at a perturbed point; one that raises off (t0, y0) is checked
    where it is defined; non-finite entries must match."""
    def f(t, y):
        return np.array([y[1], -y[0]])

    state = {"calls": 0}

    def g(t, y):
        state["calls"] += 1
        return np.array([y[1], -y[0] * (1 if state["calls"] == 1 else 1 + 1e-9)])

    assert agrees(f, f, 0.0, [1.0, 0.0]) == ""
    assert "disagree" in agrees(f, g, 0.0, [1.0, 0.0]) and state["calls"] == 2

    def h(t, y):
        if t != 0.0:
            raise ValueError("only at t0")
        return f(t, y)
    assert agrees(f, h, 0.0, [1.0, 0.0]) == ""
    assert "disagree" in agrees(lambda t, y: np.array([np.inf, 0.0]), f, 0.0, [1.0, 0.0])
