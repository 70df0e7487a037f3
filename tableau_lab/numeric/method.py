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
        return bool(all(self.Aq[i, j] == 0 and self.Ap[i, j] == 0 for i in range(self.s) for j in range(i, self.s)))

    def stage_scale(self, h) -> float:
        """h·s·max|A|: how strongly h f′ enters the stage equations (the fixed-point contraction
        with ρ(f′), the conditioning of Newton's matrix); 0 for explicit methods."""
        if self.explicit:
            return 0.0
        return abs(float(h)) * self.s * float(np.max(np.abs(self.arith.to_float(self.Aq.reshape(-1)))))

    @property
    def partitioned(self) -> bool:
        return self.kind == "prk"
