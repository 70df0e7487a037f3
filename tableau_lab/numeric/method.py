"""A method as numbers: the partitioned-GLM coefficients at one precision (``export.py`` rounds
them from the exact method), with the starting and finishing series and the stage predictor.
No sympy here: a copy with ``exact`` None runs in a process that
never imports it (``experiments/job.py``)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .arith import Arith

__all__ = ["NumericMethod"]


@dataclass(frozen=True)
class NumericMethod:
    name: str
    kind: str
    arith: Arith
    Aq: np.ndarray
    Ap: np.ndarray
    U: np.ndarray
    Bq: np.ndarray
    Bp: np.ndarray
    V: np.ndarray
    c: np.ndarray
    u: np.ndarray
    w: np.ndarray
    order: int           # with the exported starting method (GLM order / RK effective order if processed)
    starting: dict       # tree -> array of r numbers ξ(t) (GLM; RK only when effective > classical)
    finishing: dict      # tree -> number α⁻¹(t) (GLM; empty for RK)
    exact: object = None  # the exact method
    order_identity: int = 0   # with the identity / naive start (θ ≡ 0): RK classical order
    E: np.ndarray | None = None       # stage predictor ℓ_j(1 + c_i) (distinct c, implicit methods)
    Aq_inv: np.ndarray | None = None  # A_q⁻¹, A_p⁻¹ when A_q, A_p are invertible: hF = A⁻¹(Y − Ū)
    Ap_inv: np.ndarray | None = None
    modes: tuple = ()                 # parasitic modes as numbers (analysis/growth.py; GLMs)

    @property
    def s(self) -> int:
        return self.Aq.shape[0]

    @property
    def r(self) -> int:
        return self.V.shape[0]

    @property
    def explicit(self) -> bool:
        """Strictly lower triangular A_q and A_p: :attr:`lower` with a zero diagonal."""
        return self.lower and all(self.Aq[i, i] == 0 and self.Ap[i, i] == 0 for i in range(self.s))

    @property
    def lower(self) -> bool:
        """A_q and A_p lower triangular (diagonally implicit stages): Newton's matrix
        I − hA ⊗ f′ is block lower triangular, solved block by block (:mod:`stepcore`)."""
        return bool(all(self.Aq[i, j] == 0 and self.Ap[i, j] == 0 for i in range(self.s) for j in range(i + 1, self.s)))

    def stage_scale(self, h) -> float:
        """|h|·‖A_q‖∞ (the largest absolute row sum): how strongly h f′ enters the stage
        equations.  ‖hA ⊗ f′‖∞ ≤ |h|·‖A‖∞·‖f′‖∞ bounds the contraction of the fixed-point
        iteration on the stages and the conditioning of Newton's matrix I − hA ⊗ f′ (with ρ(f′)
        for ‖f′‖ in :func:`integrate.stage_iteration`); 0 for explicit methods.  A_q alone, as
        the q-stage iteration of separable problems starts from the q stages (symplectic Euler,
        A_q = 0, needs one sweep at any h).  It was |h|·s·max|A_q|, a cruder bound of the same
        norm: the six-stage GLM6M (rows summing to at most 2.56, s·max|A| = 6.5) was iterated by
        Newton where fixed point contracts by 0.05 (the outer solar system: docs/speed.md).

        >>> import numpy as np
        >>> from tableau_lab.numeric.arith import arith
        >>> A = np.array([[0.25, 0.0], [0.5, 0.25]])
        >>> NumericMethod("dirk", "rk", arith("float64"), A, A, *[np.zeros((2, 2))] * 4, *[np.zeros(2)] * 3,
        ...               order=1, starting={}, finishing={}).stage_scale(0.5)     # 0.5 · (0.5 + 0.25)
        0.375
        """
        if self.explicit:
            return 0.0
        A = self.arith.to_float(self.Aq.reshape(-1)).reshape(self.Aq.shape)
        return abs(float(h)) * float(np.max(np.sum(np.abs(A), axis=1)))

    @property
    def partitioned(self) -> bool:
        return self.kind == "prk"
