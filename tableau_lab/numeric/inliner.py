"""The pure loop's source with its one-line functions written in place: what numba's inlining
does for a compiled loop, done to the Python text for the interpreter.

The pure (Python) loop runs :mod:`stepcore`'s functions as they are (``kernels.pure_loop``).
Their arithmetic is one call per operation — ``wmadd(acc, a, g3(A, k, i, j))`` — and in the
interpreter a call costs more than the floating-point operation it makes.  :func:`inline_functions`
rewrites the functions' syntax trees: a call of a function whose body is one ``return`` of an
expression (``wadd``: ``return a + b``; ``uses``: ``if dense == 1: return True`` then
``return isnz(a)``) becomes that expression with the arguments put for the parameters, and a call
statement of a function whose body is one statement (``p2``: ``a[i, j] = v``) becomes that
statement; names of constants become their values and the conditions that then hold or fail are
folded (``DENSE_A == 1``).  The rewritten text is compiled once per arithmetic and set of constants.

The numbers do not change: each operation is the same Python operation on the same operands, in
the same order (a parameter used more than once, or not at all, is inlined only when its argument
is a name or a constant, whose evaluation has no effect and costs nothing).  The definitions stay
where they are — stepcore's algorithm and the arithmetic module's operations; this module only
moves their text.

>>> import numpy as np
>>> from tableau_lab.numeric import ops_f64, stepcore
>>> ops = {name: getattr(ops_f64, name) for name in ops_f64.OPERATIONS}
>>> ns = inline_functions([stepcore.uses, stepcore.combine], ops, {"DENSE_A": 0})
>>> A, F, cls = np.array([[[0.5, 0.0], [0.25, 0.25]]]), np.array([[1.0], [2.0]]), np.array([0])
>>> float(ns["combine"](0.1, A, 0, cls, 1, F, 0, 2))         # h (a₂₁F₁ + a₂₂F₂)
0.07500000000000001
>>> sorted(set(ns["combine"].__code__.co_names) & {"wmadd", "wmul", "g3", "uses", "isnz"})
[]
"""
from __future__ import annotations

import ast
import builtins
import contextlib
import copy
import functools
import hashlib
import inspect
import operator
import os
import textwrap
from pathlib import Path
from types import FunctionType

from ..files import atomic_write_text

__all__ = ["inline_functions", "inlined_name", "inlined_text", "plain_functions", "SHIPPED"]

SHIPPED = Path(__file__).parent / "inlined"    # the package's rewritten texts (benchmarks/write_inlined.py)
INLINED_TEXT_BYTES = 1 << 20   # the largest cached text read back
INLINE_PASSES = 4           # rounds of rewriting: an inlined body's own calls are inlined in the next


def _tree(fn) -> ast.FunctionDef:
    """The syntax tree of ``fn``'s definition, without its decorators."""
    node = ast.parse(textwrap.dedent(inspect.getsource(fn))).body[0]
    assert isinstance(node, ast.FunctionDef)
    node.decorator_list = []
    return node


def _body(node: ast.FunctionDef) -> list:
    """The statements of a definition without its docstring."""
    body = node.body
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
            and isinstance(body[0].value.value, str):
        body = body[1:]
    return body


def _expression(body: list):
    """The expression a body returns: ``return e`` or ``if t: return x`` then ``return y``
    (as ``x if t else y``); None for any other body."""
    if len(body) == 1 and isinstance(body[0], ast.Return) and body[0].value is not None:
        return body[0].value
    if len(body) == 2 and isinstance(body[0], ast.If) and not body[0].orelse and len(body[0].body) == 1:
        first, rest = body[0].body[0], _expression(body[1:])
        if isinstance(first, ast.Return) and first.value is not None and rest is not None:
            return ast.IfExp(test=body[0].test, body=first.value, orelse=rest)
    return None


_BIN = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
        ast.FloorDiv: operator.floordiv, ast.Mod: operator.mod}
_CMP = {ast.Eq: operator.eq, ast.NotEq: operator.ne, ast.Lt: operator.lt, ast.LtE: operator.le,
        ast.Gt: operator.gt, ast.GtE: operator.ge}
_UNARY = {ast.Not: operator.not_, ast.USub: operator.neg, ast.UAdd: operator.pos}


def _meaning(namespace: dict, name: str):
    """What a global ``name`` of code run in ``namespace`` is bound to (a builtin when the
    namespace has no such name; None when neither has it)."""
    return namespace.get(name, getattr(builtins, name, None))


class _Template:
    """A function that can be written in place: its parameters and its expression or statement."""

    def __init__(self, node: ast.FunctionDef, home: dict):
        self.params = [a.arg for a in node.args.args]
        body = _body(node)
        self.expr = _expression(body)
        self.stmt = None
        if self.expr is None and len(body) == 1 and isinstance(body[0], (ast.Assign, ast.AugAssign, ast.Expr)):
            self.stmt = body[0]
        inside = self.expr if self.expr is not None else self.stmt
        names = [n.id for n in ast.walk(inside) if isinstance(n, ast.Name)] if inside is not None else []
        self.uses = {p: names.count(p) for p in self.params}
        self.free = {n: _meaning(home, n) for n in set(names) - set(self.params)}

    def fits(self, call: ast.Call, local: set) -> bool:
        """Whether ``call`` can be replaced: positional arguments, one per parameter, each
        argument used once by the body or free of effects, and no free name of the body a
        local of the caller."""
        if call.keywords or len(call.args) != len(self.params) or local & set(self.free) \
                or any(isinstance(a, ast.Starred) for a in call.args):
            return False
        return all(self.uses[p] == 1 or isinstance(a, (ast.Name, ast.Constant))
                   for p, a in zip(self.params, call.args, strict=True))

    def written(self, node, call: ast.Call):
        """``node`` (the expression or statement) with the call's arguments for the parameters."""
        args = dict(zip(self.params, call.args, strict=True))

        class Put(ast.NodeTransformer):
            def visit_Name(self, name):
                return ast.copy_location(copy.deepcopy(args[name.id]), name) if name.id in args else name
        return Put().visit(copy.deepcopy(node))


def _locals(fn: ast.FunctionDef) -> set:
    """The names ``fn`` binds: its parameters and every name it stores."""
    return {a.arg for a in fn.args.args} | {n.id for n in ast.walk(fn)
                                             if isinstance(n, ast.Name) and not isinstance(n.ctx, ast.Load)}


class _Inline(ast.NodeTransformer):
    """One rewriting pass over one function: calls of templates written in place, constants
    put and folded."""

    def __init__(self, templates: dict, constants: dict, local: set):
        self.templates, self.local = templates, local
        self.constants = {k: v for k, v in constants.items() if k not in local}

    def _template(self, call, kind: str):
        if isinstance(call, ast.Call) and isinstance(call.func, ast.Name) and call.func.id not in self.local:
            t = self.templates.get(call.func.id)
            if t is not None and getattr(t, kind) is not None and t.fits(call, self.local):
                return t
        return None

    def visit_Expr(self, node):
        t = self._template(node.value, "stmt")
        if t is not None:
            return ast.copy_location(self.visit(t.written(t.stmt, node.value)), node)
        return self.generic_visit(node)

    def visit_Call(self, node):
        node = self.generic_visit(node)
        t = self._template(node, "expr")
        return ast.copy_location(t.written(t.expr, node), node) if t is not None else node

    def visit_Name(self, node):
        if isinstance(node.ctx, ast.Load) and node.id in self.constants:
            return ast.copy_location(ast.Constant(self.constants[node.id]), node)
        return node

    def visit_If(self, node):
        node = self.generic_visit(node)
        if isinstance(node.test, ast.Constant):
            return (node.body if node.test.value else node.orelse) or ast.Pass()
        return node

    def generic_visit(self, node):
        node = super().generic_visit(node)
        return _folded(node) if isinstance(node, (ast.BinOp, ast.UnaryOp, ast.Compare, ast.BoolOp, ast.IfExp)) \
            else node


def _value(node):
    """The value of an operation on constants (bool, int, float), or None."""
    kids = [n for n in ast.iter_child_nodes(node) if isinstance(n, ast.expr)]
    if not all(isinstance(n, ast.Constant) and isinstance(n.value, (bool, int, float)) for n in kids):
        return None
    try:
        if isinstance(node, ast.BinOp) and type(node.op) in _BIN:
            return _BIN[type(node.op)](node.left.value, node.right.value)
        if isinstance(node, ast.UnaryOp) and type(node.op) in _UNARY:
            return _UNARY[type(node.op)](node.operand.value)
        if isinstance(node, ast.Compare) and len(node.ops) == 1 and type(node.ops[0]) in _CMP:
            return _CMP[type(node.ops[0])](node.left.value, node.comparators[0].value)
    except ArithmeticError:           # left to raise where it runs
        return None
    return None


def _folded(node):
    """``node`` evaluated when all it reads are constants; ``x if True else y`` → ``x``;
    ``True or …`` → True, ``False and …`` → False, ``False or x`` → x, ``True and x`` → x."""
    if isinstance(node, ast.IfExp) and isinstance(node.test, ast.Constant):
        return node.body if node.test.value else node.orelse
    if isinstance(node, ast.BoolOp) and isinstance(node.values[0], ast.Constant):
        first = node.values[0].value
        if (isinstance(node.op, ast.Or) and first) or (isinstance(node.op, ast.And) and not first):
            return ast.copy_location(ast.Constant(first), node)
        rest = node.values[1:]
        return rest[0] if len(rest) == 1 else ast.copy_location(ast.BoolOp(op=node.op, values=rest), node)
    value = _value(node)
    return node if value is None else ast.copy_location(ast.Constant(value), node)


def inline_functions(functions, operations: dict, constants: dict, namespace: dict | None = None,
                     folder: Path | None = None) -> dict:
    """``functions`` defined again in ``namespace`` (a new dict if None: returned) from their
    rewritten text: calls of ``operations`` and of ``functions`` whose body is one expression or
    statement written in place (where the body's free names mean the same in ``namespace``),
    the names of ``constants`` with int, float or bool values put as values and folded.
    The rewritten text is named by :func:`inlined_name` (the source files, the constants, what
    each name of ``namespace`` is bound to) and looked up in :data:`SHIPPED` (the package's texts,
    written by ``benchmarks/write_inlined.py``: a fresh installation rewrites nothing), then in
    ``folder`` (the cache, where a text made here is kept): the rewrite parses the functions'
    source (about 0.2 s), reading a text back takes about 0.01 s."""
    namespace = {} if namespace is None else namespace
    namespace.setdefault("__builtins__", builtins)
    for name, fn in operations.items():
        namespace.setdefault(name, fn)
    named = _names(tuple(functions) + tuple(operations.values()))      # a constant the code never names changes nothing
    consts = tuple(sorted((k, v) for k, v in constants.items() if type(v) in (bool, int, float) and k in named))
    name = inlined_name(functions, operations, consts, namespace)
    path = None if folder is None else Path(folder) / name
    text = _read(SHIPPED / name)
    text = _read(path) if text is None else text
    if text is None:
        text = inlined_text(functions, operations, consts, namespace)
        if path is not None:
            with contextlib.suppress(OSError):      # a folder that cannot be written: no cache
                path.parent.mkdir(parents=True, exist_ok=True)
                atomic_write_text(path, text)
    exec(_compiled(text), namespace)            # stepcore's own source, rewritten: no user text
    return namespace


def plain_functions(functions, operations: dict, constants: dict, namespace: dict,
                    folder: Path | None = None) -> dict:
    """:func:`inline_functions`'s stand-in that writes nothing in place: ``functions`` bound to
    ``namespace`` as they are (the loop before the inliner; what tests/test_inliner.py and
    benchmarks/bench_inliner.py compare with).  ``operations``, ``constants`` and ``folder`` are
    taken for the same signature and not used: the namespace already holds them."""
    namespace.update({fn.__name__: FunctionType(fn.__code__, namespace, fn.__name__, fn.__defaults__,
                                                fn.__closure__) for fn in functions})
    return namespace


def _names(functions: tuple) -> frozenset:
    """Every global name the functions' code objects (nested ones too) name."""
    out: set = set()
    todo = [f.__code__ for f in functions if hasattr(f, "__code__")]
    while todo:
        code = todo.pop()
        out.update(code.co_names)
        todo.extend(c for c in code.co_consts if hasattr(c, "co_names"))
    return frozenset(out)


def _read(path: Path | None) -> str | None:
    """The text at ``path`` if it is a regular file (a folder or a FIFO put there is not opened)
    of at most ``INLINED_TEXT_BYTES``; else None (the text is made again)."""
    if path is None or not os.path.isfile(path):
        return None
    with contextlib.suppress(OSError, UnicodeDecodeError), open(path, "rb") as f:
        data = f.read(INLINED_TEXT_BYTES + 1)          # bounded: a file that grew is written again
        return data.decode() if len(data) <= INLINED_TEXT_BYTES else None
    return None


@functools.lru_cache(maxsize=8)
def _file_digest(filename: str) -> str:
    return hashlib.sha256(Path(filename).read_bytes()).hexdigest()


def inlined_name(functions, operations: dict, consts: tuple, namespace: dict) -> str:
    """The file name of the rewritten text, a digest of what it depends on: the files the
    functions come from (and this one), the constants (``consts``: sorted (name, value) pairs)
    and, for every name of the namespace bound to a function, class or module, what it is
    (module and qualified name)."""
    files = sorted({f.__code__.co_filename for f in (*functions, *operations.values())} | {__file__})
    bound = sorted(f"{k}={getattr(v, '__module__', None)}.{getattr(v, '__qualname__', getattr(v, '__name__', ''))}"
                   for k, v in namespace.items() if not k.startswith("__") and callable(v) or inspect.ismodule(v))
    text = "\n".join([*(_file_digest(f) for f in files), repr(consts), ",".join(f.__name__ for f in functions), *bound])
    return f"inlined_{hashlib.sha256(text.encode()).hexdigest()[:24]}.txt"


def inlined_text(functions, operations: dict, consts: tuple, namespace: dict) -> str:
    """The rewritten module text of :func:`inline_functions`."""
    named = {**operations, **{f.__name__: f for f in functions}}
    constant = dict(consts)
    templates = {name: t for name, t in _templates(tuple(sorted(named.items()))).items()
                 if all(_meaning(namespace, n) is v for n, v in t.free.items()
                        if n not in constant)}
    out = []
    for fn in functions:
        tree = _tree(fn)
        for _ in range(INLINE_PASSES):
            tree = _Inline(templates, constant, _locals(tree)).visit(tree)
        out.append(tree)
    return ast.unparse(ast.Module(body=out, type_ignores=[])) + "\n"


@functools.lru_cache(maxsize=8)
def _templates(named: tuple) -> dict:
    """name -> :class:`_Template` of the functions in ``named`` that can be written in place."""
    out = {}
    for name, fn in named:
        t = _Template(_tree(fn), getattr(fn, "__globals__", {}))
        if t.expr is not None or t.stmt is not None:
            out[name] = t
    return out


@functools.lru_cache(maxsize=16)
def _compiled(text: str):
    return compile(text, "<tableau_lab pure loop, inlined>", "exec")
