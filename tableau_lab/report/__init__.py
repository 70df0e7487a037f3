r"""Faces: LaTeX proof reports (reads analyses and data files, never the integrator).

The package is also the function ``tableau_lab.report(method, out=None, *, stability=False,
pdf=False)`` (:func:`tableau_lab.report.latex.report`): calling it makes the report, so that
``tl.report`` is one object whether or not this package has been imported.  What a report
proves and its references: README.md, "Proof reports" ([BHHN14] for G-symplecticity, [B16] ch. 3, 5 for the
order).

>>> import tableau_lab as tl
>>> tl.report(tl.load("rk4"))[:14]
'\\documentclass'
"""
import sys
import types


class _CallableModule(types.ModuleType):
    """This package, callable: ``tableau_lab.report(method, ...)`` is :func:`latex.report`."""

    def __call__(self, method, *args, **kw):
        from .latex import report
        return report(method, *args, **kw)


sys.modules[__name__].__class__ = _CallableModule
