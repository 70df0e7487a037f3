"""Faces: LaTeX proof reports (reads analyses and data files, never the integrator):
:func:`latex.report` (``tl.report``), the sections of :mod:`backward_error`.  What a report proves
and its references: README.md, "Proof reports" ([BHHN14] for G-symplecticity, [B16] ch. 3, 5 for
the order)."""
