r"""A Python callable f(t, y) traced to sympy expressions, so that it runs as a problem with
symbols: the compiled step loop, the exact Jacobian, a GLM's exact starting values.

:func:`trace_callable` calls f once with :class:`Traced` values — a numpy object array of the
state symbols y1 … yd and the time symbol t — that record Python's arithmetic (+ − * / **,
unary −) and numpy's functions of the project's problem grammar (``np.sin``, ``np.exp``,
``np.sqrt``, ``np.arctan`` …: :data:`~tableau_lab.numeric.expressions.FUNCTIONS`), whether
called on one value or on an array.  A callable is *not traceable* when it needs a number
where it has a symbol — ``math.sin(y[0])`` or ``float(y[0])`` (``__float__``), a branch on a
value (``if y[0] > 0``: comparisons raise), a float array filled with traced values, a
function outside the grammar (``np.abs``, ``np.floor``) — or when its result has a symbol
or an exponent outside the grammar; the reason is returned, never raised.  Number constants
are read exactly as the decimals they print as (0.1 is 1/10), as in every problem entry.

A trace is a claim about the callable, so it is checked (:func:`agrees`): the traced
expressions, evaluated by the code the run will use, against the callable itself at (t₀, y₀)
and at :data:`CHECK_POINTS` seeded perturbations of it, to a relative :data:`AGREEMENT`.  A
callable with hidden state (a call counter, randomness) or one the trace misread disagrees,
and its trace is discarded.

>>> import numpy as np
>>> exprs, why = trace_callable(lambda t, y: np.array([y[1], -np.sin(y[0]) + 0.1 * t]), 2)
>>> exprs, why
((y2, t/10 - sin(y1)), '')
>>> import math
>>> trace_callable(lambda t, y: [y[1], -math.sin(y[0])], 2)
(None, 'f(t, y) needs a number where it has a symbol: float() of a traced value (math functions, float arrays, int())')
>>> trace_callable(lambda t, y: [y[1], -y[0] if y[0] > 0 else y[0]], 2)[1]
'f(t, y) branches on a value (y1 > 0 ...)'

Reference: the technique is operator overloading, as in automatic differentiation by
overloading (A. Griewank, A. Walther, *Evaluating Derivatives*, 2nd ed., SIAM 2008, §6.1) and
in JAX's tracing of Python functions to expressions (jax.make_jaxpr), recording sympy
expressions instead of a tape.
"""
from __future__ import annotations

import operator
import time
from fractions import Fraction

import numpy as np
import sympy as sp

from ..numeric.expressions import FUNCTIONS, LIMITS

__all__ = ["NotTraceable", "Traced", "trace_callable", "agrees", "TRACE_OPERATIONS", "TRACE_SECONDS", "AGREEMENT",
           "CHECK_POINTS", "CHECK_SEED"]

#: operations a trace may record, and seconds it may take, before it is abandoned (a loop of the
#: user's that builds a huge expression: a sum of 12 000 distinct sines took 128 s, sympy's sums
#: being quadratic in their terms; a pendulum's trace takes about 1 ms)
TRACE_OPERATIONS = 20_000
TRACE_SECONDS = 2.0
#: relative agreement of the traced expressions with the callable (max |difference| against max |value|)
AGREEMENT = 1e-12
#: perturbed points at which the trace is checked, besides (t₀, y₀); their seed
CHECK_POINTS = 3
CHECK_SEED = 20261127
#: numpy's name of each grammar function (np.arctan is the grammar's atan); sqrt is a power in sympy
NUMPY_NAMES = {name: {"atan": "arctan"}.get(name, name) for name in FUNCTIONS}
_ARITHMETIC = {"add": operator.add, "subtract": operator.sub, "multiply": operator.mul, "true_divide": operator.truediv,
               "divide": operator.truediv, "power": operator.pow, "negative": operator.neg, "positive": operator.pos,
               "square": lambda x: x * x}
_ALLOWED = tuple({type(FUNCTIONS[n](sp.Symbol("x"))) for n in FUNCTIONS if n != "sqrt"})


class NotTraceable(TypeError):
    """The callable needs a value where the trace has a symbol (or leaves the grammar)."""


def _number(x):
    """An operand that is a number, exactly (a float as the decimal it prints as); None if it is not one."""
    if isinstance(x, (bool, np.bool_)):
        return sp.Integer(int(x))
    if isinstance(x, (int, np.integer)):
        return sp.Integer(int(x))
    if isinstance(x, (float, np.floating)):
        if not np.isfinite(x):
            raise NotTraceable(f"f(t, y) uses the non-finite constant {float(x)!r}")
        return sp.Rational(Fraction(repr(float(x))))
    return None


class Traced:
    """A value of a traced call: a sympy expression ``e``, with Python's arithmetic and numpy's
    grammar functions (as methods, which numpy's object arrays call, and through
    ``__array_ufunc__`` on a single value).  Anything that needs a number raises
    :class:`NotTraceable`.  ``tape``: [the shared count of operations, the deadline on
    ``time.perf_counter()``] (:data:`TRACE_OPERATIONS`, :data:`TRACE_SECONDS`).

    >>> import math
    >>> x = Traced(sp.Symbol("x"), [0, math.inf])
    >>> (2 * x ** 2 - np.cos(x) / 4).e
    2*x**2 - cos(x)/4
    """

    __slots__ = ("e", "tape")

    def __init__(self, e, tape):
        self.e, self.tape = e, tape

    def _new(self, e):
        self.tape[0] += 1
        if self.tape[0] > TRACE_OPERATIONS:
            raise NotTraceable(f"the trace of f(t, y) took more than {TRACE_OPERATIONS} operations (TRACE_OPERATIONS)")
        if time.perf_counter() > self.tape[1]:
            raise NotTraceable(f"the trace of f(t, y) took more than {TRACE_SECONDS:g} s (TRACE_SECONDS)")
        return Traced(e, self.tape)

    def _operand(self, x):
        if isinstance(x, Traced):
            return x.e
        if isinstance(x, sp.Expr):
            return x
        return _number(x)

    def _binary(self, other, op, reflected=False):
        o = self._operand(other)
        if o is None:
            return NotImplemented
        return self._new(op(o, self.e) if reflected else op(self.e, o))

    def __add__(self, o): return self._binary(o, operator.add)
    def __radd__(self, o): return self._binary(o, operator.add, True)
    def __sub__(self, o): return self._binary(o, operator.sub)
    def __rsub__(self, o): return self._binary(o, operator.sub, True)
    def __mul__(self, o): return self._binary(o, operator.mul)
    def __rmul__(self, o): return self._binary(o, operator.mul, True)
    def __truediv__(self, o): return self._binary(o, operator.truediv)
    def __rtruediv__(self, o): return self._binary(o, operator.truediv, True)
    def __pow__(self, o): return self._binary(o, operator.pow)
    def __rpow__(self, o): return self._binary(o, operator.pow, True)
    def __neg__(self): return self._new(-self.e)
    def __pos__(self): return self

    def _sympy_(self):                      # sympy's own functions of a traced value give expressions
        return self.e

    def __float__(self):
        raise NotTraceable("f(t, y) needs a number where it has a symbol: float() of a traced value "
                           "(math functions, float arrays, int())")

    __int__ = __index__ = __complex__ = __float__

    def _branch(self, other, sign):
        raise NotTraceable(f"f(t, y) branches on a value ({self.e} {sign} {str(other)[:20]} ...)")

    def __lt__(self, o): self._branch(o, "<")
    def __le__(self, o): self._branch(o, "<=")
    def __gt__(self, o): self._branch(o, ">")
    def __ge__(self, o): self._branch(o, ">=")
    def __eq__(self, o): self._branch(o, "==")
    def __ne__(self, o): self._branch(o, "!=")
    def __bool__(self): self._branch(0, "!=")
    __hash__ = None

    def __array_ufunc__(self, ufunc, method, *inputs, **kwargs):
        if method != "__call__" or kwargs:
            return NotImplemented
        if any(isinstance(x, np.ndarray) for x in inputs):     # elementwise: numpy's object loops call us back
            boxed = []
            for x in inputs:
                if isinstance(x, Traced):
                    b = np.empty((), dtype=object)
                    b[()] = x
                    x = b
                boxed.append(x)
            return ufunc(*boxed)
        first = inputs[0] if isinstance(inputs[0], Traced) else next(x for x in inputs if isinstance(x, Traced))
        if ufunc.__name__ in _ARITHMETIC:
            ops = [first._operand(x) for x in inputs]
            if any(o is None for o in ops):
                return NotImplemented
            return first._new(_ARITHMETIC[ufunc.__name__](*ops))
        if len(inputs) == 1 and ufunc.__name__ in NUMPY_NAMES.values():
            return getattr(self, ufunc.__name__)()
        raise NotTraceable(f"f(t, y) calls numpy's {ufunc.__name__}, which is outside the problem grammar "
                           f"({', '.join(NUMPY_NAMES.values())})")


def _function(name):
    fn = FUNCTIONS[name]

    def method(self):
        return self._new(fn(self.e))
    method.__name__ = NUMPY_NAMES[name]
    return method


for _name in FUNCTIONS:
    setattr(Traced, NUMPY_NAMES[_name], _function(_name))


def _checked(e, symbols, i):
    """e if it is an expression of ``symbols`` in the grammar, else NotTraceable naming component i."""
    where = f"component {i + 1} of f(t, y)"
    extra = e.free_symbols - set(symbols)
    if extra:
        raise NotTraceable(f"{where} has the symbols {', '.join(sorted(map(str, extra)))} (sympy inside f?)")
    for node in sp.preorder_traversal(e):
        if isinstance(node, sp.Pow):
            x = node.exp
            if not (x.is_Rational and abs(x.p) <= LIMITS["exponent_size"] and x.q <= LIMITS["exponent_size"]):
                raise NotTraceable(f"{where} has the power {node}: exponents must be rational constants of "
                                   f"modest size")
        elif isinstance(node, sp.Function) and not isinstance(node, _ALLOWED):
            raise NotTraceable(f"{where} uses {type(node).__name__}, which is outside the problem grammar")
        elif node.is_Number and not node.is_finite:
            raise NotTraceable(f"{where} is not finite ({node})")
        elif not (node.is_Atom or isinstance(node, (sp.Add, sp.Mul, sp.Pow, sp.Function))):
            raise NotTraceable(f"{where} has a {type(node).__name__}, which is outside the problem grammar")
    return e


def trace_callable(fn, d: int, *, timed: bool = True, names=None) -> tuple:
    """(the d expressions of ``fn(t, y)`` in the symbols y1 … yd (``names``) and t, "") or (None,
    the reason it is not traceable).  ``timed=False`` traces ``fn(y)`` (an invariant; the result
    then has one component).  The symbols are those :func:`symbols` returns."""
    t, ys = symbols(d, names)
    tape = [0, time.perf_counter() + TRACE_SECONDS]
    y = np.empty(d, dtype=object)
    for i, s in enumerate(ys):
        y[i] = Traced(s, tape)
    try:
        out = fn(Traced(t, tape), y) if timed else fn(y)
        items = np.asarray(out, dtype=object).reshape(-1) if not isinstance(out, Traced) else [out]
        if len(items) != (d if timed else 1):
            return None, f"f(t, y) returned {len(items)} values for a state of dimension {d}"
        exprs = []
        for i, v in enumerate(items):
            e = v.e if isinstance(v, Traced) else v if isinstance(v, sp.Expr) else _number(v)
            if e is None:
                return None, f"component {i + 1} of f(t, y) is a {type(v).__name__}, not an expression"
            exprs.append(_checked(sp.sympify(e), (t, *ys), i))
    except NotTraceable as exc:
        return None, str(exc)
    except Exception as exc:                # whatever the user's code raises on symbols: not traceable
        first = str(exc).strip().splitlines()
        return None, f"f(t, y) raised {type(exc).__name__} on symbols ({first[0][:120] if first else ''})"
    return tuple(exprs), ""


def symbols(d: int, names=None) -> tuple:
    """(t, (y1, …, yd)): the symbols of a trace (``names``: the state's names; "y" for d = 1)."""
    names = names or ([f"y{i + 1}" for i in range(d)] if d > 1 else ["y"])
    return sp.Symbol("t"), tuple(sp.Symbol(n) for n in names)


def agrees(traced, fn, t0: float, y0, scale=None) -> str:
    """"" if ``traced(t, y)`` (the traced expressions as the run evaluates them) agrees with
    ``fn(t, y)`` to :data:`AGREEMENT` (relative to the larger of their largest entries) at
    (t₀, y₀) and at :data:`CHECK_POINTS` perturbations (each entry moved by up to 10 % of
    max(1, |entry|), seeded), else why not.  Points where fn raises are skipped; entries must be
    finite in both or in neither.

    >>> f = lambda t, y: np.array([y[1], -y[0]])
    >>> agrees(f, f, 0.0, np.array([1.0, 0.0]))
    ''
    >>> calls = [0]
    >>> def g(t, y):
    ...     calls[0] += 1
    ...     return np.array([y[1], -y[0] * calls[0]])
    >>> agrees(f, g, 0.0, np.array([1.0, 0.0]))[:55]
    'the traced expressions disagree with f at t = -0.026169'
    """
    rng = np.random.default_rng(CHECK_SEED)
    y0 = np.asarray(y0, dtype=float)
    points = [(float(t0), y0)]
    for _ in range(CHECK_POINTS):
        u = rng.uniform(-0.1, 0.1, len(y0) + 1)
        points.append((t0 + u[0] * max(1.0, abs(t0)), y0 + u[1:] * np.maximum(1.0, np.abs(y0))))
    for k, (t, y) in enumerate(points):
        try:
            with np.errstate(all="ignore"):
                want = np.asarray(fn(t, y.copy()), dtype=float).reshape(-1)
        except Exception as exc:            # f undefined there (a perturbed point): not a check
            if k == 0:
                return f"f(t0, y0) raised {type(exc).__name__} when called again (f has hidden state?)"
            continue
        try:
            with np.errstate(all="ignore"):
                got = np.asarray(traced(t, y.copy()), dtype=float).reshape(-1)
        except (ArithmeticError, ValueError):       # math.sqrt(-1) in the generated code: not a number
            got = np.full(want.shape, np.nan)
        fin = np.isfinite(want)
        size = max(float(np.max(np.abs(want[fin]), initial=0.0)), float(np.max(np.abs(got[fin]), initial=0.0)))
        if (got.shape != want.shape or not np.array_equal(fin, np.isfinite(got))
                or not np.all(np.abs(got[fin] - want[fin]) <= AGREEMENT * size)):
            return (f"the traced expressions disagree with f at t = {t:.6g}, y = {np.array2string(y, precision=6)} "
                    "(f has hidden state or randomness?)")
    return ""
