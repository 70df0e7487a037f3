"""Readable kernels (issue 31, part 3): the step loop's state travels as named records, the
compiled module is written from stepcore's own function objects (no text markers), every
arithmetic primitive is documented, and the numba internals jit.py relies on are pinned."""
import ast
import inspect

import numpy as np
import pytest

from tableau_lab.numeric import jit, kernels, limits as L, ops_dd, ops_f64, ops_mp, stepcore

# -- records --------------------------------------------------------------------------------


def test_step_loop_takes_a_few_named_records():
    """run and rescue_step take the seven records, not 32 positional parameters, and no function
    of the loop takes more than ten (newton_stages took 24)."""
    for entry in (stepcore.run, stepcore.rescue_step):
        assert list(inspect.signature(entry).parameters) == ["span", "st", "method", "ctl", "inv", "stages", "work"]
    widest = max(stepcore.LOOP, key=lambda fn: len(inspect.signature(fn).parameters))
    assert len(inspect.signature(widest).parameters) <= 10, widest.__name__
    assert all(r._fields and r.__doc__ for r in stepcore.RECORDS)


def test_loop_state_arguments_are_the_records():
    """kernels.LoopState hands run exactly one record of each kind, the arrays the run owns."""
    cp_like = type("P", (), {"f": staticmethod(lambda y: -y), "jac": staticmethod(lambda y: -np.eye(len(y)))})()
    from tableau_lab.exact.tableau_json import load
    from tableau_lab.numeric.export import to_numeric
    nm = to_numeric(load("methods/gauss2.json"))
    pk = kernels.Pack(nm, cp_like, 0.1, ([1.0, 1.0], [0.0, 0.0]), mode=L.FIXED)
    loop = kernels.pure_loop(cp_like, "float64")
    st = kernels.LoopState(loop, pk, np.ones((1, 2)), 4, 2)
    args = st.args(0, 4)
    assert [type(a) for a in args] == [stepcore.Span, stepcore.State, stepcore.Coefficients, stepcore.Controls,
                                      stepcore.ProblemData, stepcore.Stages, stepcore.Projection]
    assert args[1].Y is st.Y and args[1].stats is st.stats
    # y' = -y by the 2-stage Gauss method: the (2,2) Padé approximant of e^(-h) per step
    assert loop.run(*args) == 0
    z = -0.1
    pade = (1 + z / 2 + z * z / 12) / (1 - z / 2 + z * z / 12)
    assert np.allclose(st.Y[0], pade ** 4, rtol=1e-13, atol=0)


def test_pure_loop_is_stepcores_code_with_operations_in_place():
    """The pure loop is stepcore's code, its one-line operations written in place
    (numeric/inliner.py; bit for bit the same numbers: tests/test_inliner.py): every function of
    stepcore.LOOP with its name and parameters, no call left of an operation written in place, and
    the arithmetic's operations themselves bound as they are."""
    loop = kernels.pure_loop(type("P", (), {"f": None})(), "float64")
    for fn in stepcore.LOOP:
        mine, theirs = getattr(loop, fn.__name__).__code__, fn.__code__
        assert mine.co_varnames[:mine.co_argcount] == theirs.co_varnames[:theirs.co_argcount]
    assert not {"wmadd", "wmul", "uses", "isnz"} & set(loop.combine.__code__.co_names)
    assert loop.wadd is ops_f64.wadd and kernels.pure_loop(type("P", (), {})(), "mp").wadd is ops_mp.wadd


# -- the generated module -----------------------------------------------------------------


def _defs(text):
    return [node.name for node in ast.parse(text).body if isinstance(node, ast.FunctionDef)]


@pytest.mark.parametrize("kind", ["f64", "dd"])
def test_generated_module_is_stepcore_and_ops_whole(kind):
    """The text for a small shape compiles; it defines every operation and every function of
    stepcore.LOOP exactly once, each with its source as written in ops_*.py / stepcore.py
    (only dims is written for the shape), and the specialisation's constants once."""
    shape = kernels.Shape(2, 1, 2, L.NEWTON, 1, (1, 0, 1, 1))
    text = kernels.module_source(kind, shape, "some_problem", True)
    compile(text, "generated.py", "exec")
    ops = ops_dd if kind == "dd" else ops_f64
    names = _defs(text)
    expected = [n for n in ops_f64.OPERATIONS if getattr(ops, n).__name__ == n] + [fn.__name__ for fn in stepcore.LOOP]
    assert names == expected
    for fn in stepcore.LOOP:
        if fn.__name__ != "dims":
            assert inspect.getsource(fn) in text
    assert "def dims(A, Y):\n    return 2, 1, 2\n" in text
    tree = ast.parse(text)
    assigned = [t.id for node in tree.body if isinstance(node, ast.Assign) for t in node.targets
                if isinstance(t, ast.Name)]
    for name in stepcore.SPECIALISED:
        assert assigned.count(name) == 1, name
    ns = {}
    exec("\n".join(line for line in text.splitlines() if line.startswith(("LOOP_", "DENSE_"))),
         {"NEWTON": L.NEWTON, "ANY": L.ANY}, ns)
    assert ns == {"LOOP_MODE": L.NEWTON, "LOOP_PROJECTS": 1, "DENSE_A": 1, "DENSE_B": 0, "DENSE_U": 1, "DENSE_V": 1}
    assert max(len(line) for line in text.splitlines()) <= 120
    assert "from some_problem import f_, jac_, inv_, grad_, fq_, fp_" in text


def test_generated_module_needs_no_markers():
    """kernels.py assembles by function objects: no source file is cut at a marker line."""
    src = inspect.getsource(kernels)
    assert "# ---- operations ----" not in src and "# ---- core ----" not in src
    for mod in (ops_f64, ops_dd, ops_mp, stepcore):
        assert "# ---- operations ----" not in inspect.getsource(mod)
        assert "# ---- core ----" not in inspect.getsource(mod)


# -- the arithmetic primitives --------------------------------------------------------------


@pytest.mark.parametrize("ops", [ops_f64, ops_dd, ops_mp])
def test_every_primitive_is_documented(ops):
    for name in ops_f64.OPERATIONS:
        fn = getattr(ops, name)
        assert callable(fn) and fn.__doc__ and fn.__doc__.strip(), (ops.__name__, name)
    text = ops_dd.__doc__
    assert "TwoSum" in text and "Dekker" in text and "Ogita" in text


def test_dd_primitives_are_exact_where_the_transformations_say():
    """wmadd in double-double: 1/3 (rounded to dd) times 3 is 1 to 2^-104; wadd keeps the
    tail that float64 loses (TwoSum: a + b = s + e exactly)."""
    from fractions import Fraction

    from tableau_lab.numeric.ddmath import to_dd
    third = to_dd("1/3")
    x = ops_dd.wmadd(ops_dd.wzero(), third, ops_dd.wint(3))
    assert abs(Fraction(x[0]) + Fraction(x[1]) - 1) <= Fraction(1, 2 ** 104)
    s = ops_dd.wadd((1.0, 0.0), (2.0 ** -70, 0.0))
    assert Fraction(s[0]) + Fraction(s[1]) == 1 + Fraction(1, 2 ** 70)


# -- the numba internals jit.py relies on ---------------------------------------------------


def test_numba_noalias_flag_internals_are_there():
    """jit.expose_noalias relies on numba.core.compiler.Flags having a boolean option
    ``noalias`` (off by default), on TargetOptions.Mapping(flag_name) and on
    TargetOptions.parse_as_flags copying a mapped option onto the flags.  A numba without them
    fails here (the loop would silently lose ``noalias``: docs/speed.md)."""
    from numba.core.compiler import Flags
    from numba.core.cpu import CPUTargetOptions
    from numba.core.options import TargetOptions
    option = Flags.options["noalias"]
    assert option.type is bool and option.default is False
    assert list(inspect.signature(TargetOptions.Mapping).parameters)[:1] == ["flag_name"]
    assert jit.expose_noalias() == {"noalias": True}
    assert isinstance(CPUTargetOptions.noalias, TargetOptions.Mapping)
    assert CPUTargetOptions.noalias.flag_name == "noalias"
    flags = CPUTargetOptions.parse_as_flags(Flags(), {"noalias": True})
    assert flags.noalias is True
    assert jit.KERNEL_OPTIONS["noalias"] is True and jit.KERNEL_OPTIONS["_nrt"] is False


def _arguments_line(fn, sig):
    ir = fn.inspect_llvm(sig)
    name = fn.overloads[sig].fndesc.mangled_name
    return next(line for line in ir.splitlines() if line.startswith("define") and name in line)


def test_noalias_reaches_the_compiled_arguments():
    """The effect: a function compiled with jit's kernel options has its array pointers marked
    noalias in LLVM IR (beyond the return and exception slots numba always marks)."""
    from numba import njit, types

    def store(a, b):
        a[0] = b[0] + b[1]

    sig = (types.float64[::1], types.float64[::1])
    plain = njit(sig, _nrt=False, error_model="numpy")(store)
    marked = njit(sig, **{**jit.KERNEL_OPTIONS, "cache": False})(store)
    without = _arguments_line(plain, sig[0:2] and plain.signatures[0]).count("noalias")
    with_ = _arguments_line(marked, marked.signatures[0]).count("noalias")
    assert with_ >= without + 4, (without, with_)    # meminfo, parent, data of each array at least
