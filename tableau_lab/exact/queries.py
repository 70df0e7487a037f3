r"""What can be asked of a method, as methods of the method object (tab completion in a notebook).

Each is a thin stub calling the public function of the same name at the package top
(``tableau_lab.order(m)`` for ``m.order()``, :data:`tableau_lab._LAZY`), looked up by name at
call time.  This is the one deliberate inversion of the layers (docs/architecture.md): the exact
core names its analyses but imports none of them, so a property of a method keeps one
definition, in its analysis, and ``import tableau_lab.exact.methods`` stays as cheap as before.
Method objects stay frozen: nothing is cached on them.

>>> import tableau_lab as tl
>>> rk4 = tl.load("rk4")
>>> int(rk4.order()), rk4.imaginary_stability_interval(), rk4.principal_error_norm()
(4, 2*sqrt(2), sqrt(1745)/2880)
"""
from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any

__all__ = ["Queries"]


def _top(name: str) -> Callable[..., Any]:
    """The public function ``tableau_lab.<name>``."""
    function: Callable[..., Any] = getattr(importlib.import_module("tableau_lab"), name)
    return function


def _delegate(name: str, doc: str) -> Callable[..., Any]:
    """The method ``name`` of :class:`Queries`: ``tableau_lab.<name>(self, ...)``, with ``doc``."""
    def method(self: Queries, *args: Any, **kw: Any) -> Any:
        return _top(name)(self, *args, **kw)
    method.__name__ = name
    method.__qualname__ = f"Queries.{name}"
    method.__doc__ = doc
    return method


class Queries:
    """The analyses of a method as its methods; each calls ``tableau_lab.<name>(self, ...)``."""

    __slots__ = ()

    order = _delegate("order", """The order analysis (``tl.order``): ``int(m.order())`` is the order — classical for RK
        and partitioned RK (elementary weights over (bicoloured) trees, [B16] ch. 3, [HLW06]
        III.2), the highest achievable with a starting method for GLMs ([B16] ch. 5).

        >>> import tableau_lab as tl
        >>> int(tl.load("gauss:3").order())
        6
        """)

    stability = _delegate("stability", """The exact linear-stability analysis (``tl.stability``): P(w, z), R(z),
        A-stability,
        the imaginary-axis radii ([HW96] IV.3, [BHHN14]).

        >>> import tableau_lab as tl
        >>> tl.load("gauss2").stability().a_stable
        True
        """)

    imaginary_stability_interval = _delegate("imaginary_stability_interval", """The exact Y with |R(iy)| ≤ 1 for |y| ≤ Y
        (``tl.imaginary_stability_interval``; NodePy's
        ``imaginary_stability_interval``, exact; [HW96] IV.2).

        >>> import tableau_lab as tl
        >>> tl.load("rk4").imaginary_stability_interval()
        2*sqrt(2)
        """)

    principal_error_norm = _delegate("principal_error_norm", """‖τ^(p+1)‖₂ of an RK method, exact
        (``tl.principal_error_norm``; NodePy's
        ``principal_error_norm``; [HNW93] II.3).

        >>> import tableau_lab as tl
        >>> tl.load("rk4").principal_error_norm()
        sqrt(1745)/2880
        """)

    ssp_coefficient = _delegate("ssp_coefficient", """The SSP coefficient (radius of absolute monotonicity) of an RK
        method, exact
        (``tl.ssp_coefficient``; NodePy's ``absolute_monotonicity_radius``; [GKS11] ch. 3).

        >>> import tableau_lab as tl
        >>> tl.load("ssp104").ssp_coefficient().R
        6
        """)

    stability_function = _delegate("stability_function", """R(z) = P(z)/Q(z) of an RK method, exact
        (``tl.stability_function``; [HW96] IV.3).

        >>> import tableau_lab as tl
        >>> print(tl.load("implicit_midpoint").stability_function())
        R(z) = (z/2 + 1)/(1 - z/2)
        """)

    modified_equation = _delegate("modified_equation", """The modified equation to trees of order n
        (``tl.modified_equation(m, n)``; [HLW06] IX.1).

        >>> import tableau_lab as tl
        >>> print(tl.load("explicit_euler").modified_equation(3))
        explicit Euler: modified equation, trees to order 3
          ỹ′ = f
             + h   ( -1/2 f'f )
             + h^2 ( 1/12 f''(f, f) + 1/3 f'f'f )
        """)

    modified_hamiltonian = _delegate("modified_hamiltonian", """The modified Hamiltonian H̃ for a Hamiltonian H to order
        n
        (``tl.modified_hamiltonian(m, H, n)``; [HLW06] IX.3).

        >>> import tableau_lab as tl, sympy as sp
        >>> q, p = sp.symbols("q p")
        >>> tl.load("implicit_midpoint").modified_hamiltonian(p**2/2 + q**2/2, 3).expression
        h**2*(-p**2/24 - q**2/24) + p**2/2 + q**2/2
        """)

    verify = _delegate("verify", """Every analysis that applies, and the verdict on each claim of the tableau
        (``tl.verify``; ``tableau-lab verify``).

        >>> import tableau_lab as tl
        >>> tl.load("example4_glm").verify().failed
        ()
        """)

    g_symplectic = _delegate("g_symplectic", """G-symplecticity: G and D with the three conditions of [BHHN14]
        (``tl.g_symplectic``).

        >>> import tableau_lab as tl
        >>> tl.load("example4_glm").g_symplectic().holds
        True
        """)

    parasitism = _delegate("parasitism", """The parasitic growth parameters μ of a GLM (``tl.parasitism``; [BHHN14] Sec.
        4).

        >>> import tableau_lab as tl
        >>> tl.load("example4_glm").parasitism().free
        False
        """)

    report = _delegate("report", r"""The LaTeX proof report (``tl.report``; ``tableau-lab report``).

        >>> import tableau_lab as tl
        >>> tl.load("implicit_midpoint").report()[:14]
        '\\documentclass'
        """)

    # the four below call functions of the numeric side and the plots (tl.integrate, …)

    integrate = _delegate("integrate", """Integrate a problem with this method (``tl.integrate(m, f, y0, t_span,
        h=...)``).

        >>> import tableau_lab as tl, math
        >>> sol = tl.load("gauss2").integrate(lambda t, y: [y[1], -y[0]], [1, 0], (0, 2 * math.pi), h=0.01,
        ...                                   notice=False)
        >>> bool(abs(sol.states[-1] - [1, 0]).max() < 1e-6)       # one period: back at (1, 0)
        True
        """)

    plot_stability_region = _delegate("plot_stability_region", """The stability region, on matplotlib axes
        (``tl.plot_stability_region(m, ax=None, window=None)``).

        >>> import tableau_lab as tl
        >>> ax = tl.load("rk4").plot_stability_region()
        >>> type(ax).__name__
        'Axes'
        """)

    plot_order_star = _delegate("plot_order_star", """The order star |R(z)e^(−z)| > 1 ([HW96] IV.4), on matplotlib axes
        (``tl.plot_order_star``).

        >>> import tableau_lab as tl
        >>> ax = tl.load("gauss2").plot_order_star()
        >>> type(ax).__name__
        'Axes'
        """)

    plot_imaginary_axis = _delegate("plot_imaginary_axis", """The root moduli along the imaginary axis, on matplotlib
        axes (``tl.plot_imaginary_axis``).

        >>> import tableau_lab as tl
        >>> ax = tl.load("leapfrog").plot_imaginary_axis()
        >>> type(ax).__name__
        'Axes'
        """)

    error_constant = _delegate("error_constant", """The classical error constant C_{p+1} of a linear multistep method
        (``tl.error_constant``;
        [HNW93] III.2).

        >>> import tableau_lab as tl
        >>> c = tl.load("bdf:2").error_constant()
        >>> c.C, c.normalised                      # C₃ with α₂ = 1, and C₃/σ(1)
        (-2/9, -1/3)
        """)
