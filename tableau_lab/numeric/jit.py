r"""How numba compiles the step loop: the decorators of :mod:`stepcore` and of the problem
modules, defined once (the generated modules import them; the pure loop's are no-ops).

* ``kernel`` — an entry point called from Python (``run``, ``rescue_step``) or outside the hot
  path (``project``, ``fallback_stages``): no reference counting (``_nrt=False``; the loop
  allocates nothing, and numba's atomic reference counts on every array passed cost about
  0.25 µs a step) and its array arguments declared not to alias (``noalias``: the loop's
  arrays are distinct allocations, :class:`kernels.LoopState`), so that LLVM keeps
  coefficients and counters in registers across stores to the stage arrays.
* ``helper`` — inlined into its caller by LLVM (``forceinline``: the ``alwaysinline``
  attribute).  numba's own ``inline='always'`` copies the callee's IR at every call site and
  took 10–15 s of a 20 s compile; LLVM's inliner does the same job in a fraction.
* ``prim`` — small functions left to LLVM's inliner.
* ``alloc`` — the workspace, allocated once per run (reference counting on).
* ``cold`` — a problem's functions that are not inlined (large f, Jacobians, invariants).

``noalias`` is a flag of numba's compiler (``numba.core.compiler.Flags.noalias``: the
lowering then marks every pointer argument of the function ``noalias``) that ``njit`` does not
expose; :func:`expose_noalias` maps it as numba maps its other options (``CPUTargetOptions``
attributes of type ``TargetOptions.Mapping``, which ``TargetOptions.parse_as_flags`` copies onto
the flags), if this numba has it.  tests/test_kernel_records.py pins these
internals and the effect (the attribute in the compiled IR): a numba upgrade that breaks them
fails there, not silently slower here.
"""
from numba import njit

__all__ = ["kernel", "helper", "prim", "alloc", "cold", "expose_noalias", "KERNEL_OPTIONS"]


def expose_noalias() -> dict:
    """``{"noalias": True}`` once ``njit(noalias=True)`` sets numba's ``Flags.noalias`` (an
    option added to ``CPUTargetOptions``), or {} on a numba without that flag."""
    try:
        from numba.core.compiler import Flags
        from numba.core.cpu import CPUTargetOptions
        from numba.core.options import TargetOptions
    except ImportError:                       # pragma: no cover - another numba layout
        return {}
    if "noalias" not in getattr(Flags, "options", {}) and not hasattr(Flags, "noalias"):
        return {}                             # pragma: no cover
    if not hasattr(CPUTargetOptions, "noalias"):
        CPUTargetOptions.noalias = TargetOptions.Mapping("noalias")
    return {"noalias": True}


_BASE = dict(cache=True, error_model="numpy")
KERNEL_OPTIONS = dict(_BASE, _nrt=False, **expose_noalias())   # an entry point: no refcounts, no aliasing

kernel = njit(**KERNEL_OPTIONS)
helper = njit(**_BASE, _nrt=False, forceinline=True)
prim = njit(**_BASE, _nrt=False)
alloc = njit(**_BASE)
cold = prim
