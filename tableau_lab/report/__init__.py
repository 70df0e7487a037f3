"""Faces: LaTeX proof reports (reads analyses and data files, never the integrator)."""
