"""Parasitic modes as numbers and their local growth rate, for the run-time monitor: no sympy
here, so that a run can go on in a process that never imports it (``experiments/job.py``).

The exact modes (ζ, μ = ζ⁻¹ y B U x, left eigenvector y) come from
:func:`tableau_lab.analysis.parasitism.growth_parameters`; :func:`growth_rate` is the local
growth rate max Re eig(μ f′(y)) of [BHHN14] (Butcher, Habib, Hill, Norton, *The control of
parasitism in G-symplectic methods*, SIAM J. Numer. Anal. 52, 2014).

>>> round(growth_rate(1.0, [[0.0, 1.0], [-4.0, 0.0]]), 12)   # eigenvalues ±2i: no growth
0.0
>>> growth_rate(1.0, [[0.0, 1.0], [4.0, 0.0]])    # eigenvalues ±2
2.0
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["NumericMode", "growth_rate"]


@dataclass(frozen=True)
class NumericMode:
    """One parasitic mode as numbers: ``label`` is ζ as ``growth_parameters`` prints it."""
    label: str
    zeta: complex
    mu: complex
    left: np.ndarray     # complex r-vector y, y x = 1


def growth_rate(mu, jacobian) -> float:
    """max Re λ over the eigenvalues λ of μ·J: the rate (per unit time) at which a parasitic
    component v′ = μ f′(y) v grows at a state with Jacobian J = f′(y).  0 when μ = 0."""
    mu = complex(mu)
    J = np.asarray(jacobian, dtype=float)
    if mu == 0 or not J.size:
        return 0.0
    return float(np.max(np.linalg.eigvals(mu * J).real))
