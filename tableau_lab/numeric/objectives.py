r"""Design objectives of a general linear method in float64, fast enough to sit inside a search
loop (thousands of members per second); the winner is then certified exactly
(:mod:`..experiments.design_search`).  An RK method is the GLM with r = 1.

* ``imaginary_interval``: Y* = sup{Y : ρ(M(iy)) ≤ 1 for 0 ≤ y ≤ Y}, M(z) = V + zB(I − zA)⁻¹U,
  on a grid refined by bisection (capped at :data:`YMAX`; the exact value comes from
  :mod:`..analysis.stability`);
* ``real_interval``: the same on the negative real axis;
* ``growth``: the parasitic growth parameters μ = ζ⁻¹yBUx/(yx) of the eigenvalues ζ ≠ 1 of V on the
  unit circle ([BHHN14]; exactly: :mod:`..analysis.parasitism`);
* ``series_defects``: from the underlying one-step method's B-series (the same recursion as the exact
  one, :func:`..analysis.method_series.glm_series`, in floats): the largest order-condition residual
  up to order p and the principal error norm ‖(Φ(t) − 1/γ(t))/σ(t)‖₂ over |t| = p + 1.

>>> from tableau_lab.exact.tableau_json import load
>>> g = NumericGLM.of(load("methods/glm43.json"))
>>> round(imaginary_interval(g), 3), max(abs(m) for m in growth(g)) < 1e-12
(1.614, True)
>>> residual, error = series_defects(g, 4)
>>> residual < 1e-13, round(error, 8)      # the exact series (analysis.method_series) gives 0.0110291758…
(True, 0.01102918)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..analysis.method_series import error_terms, glm_series
from ..analysis.trees import density, trees_of_order

__all__ = ["NumericGLM", "imaginary_interval", "real_interval", "growth", "series_defects", "order_residuals", "YMAX",
           "STABLE_SLACK", "UNIT_CIRCLE"]

YMAX = 20.0              # the axis intervals are searched on [0, YMAX]; beyond: reported as YMAX
AXIS_POINTS = 2001       # grid points on [0, YMAX] before bisection
COLLISION_GAP = 0.1      # eigenvalues of M closer than this at a local minimum: the grid is refined there
FINE_POINTS = 4001       # points of that refinement over two grid steps (spacing 5e-6 for YMAX = 20)
STABLE_SLACK = 1e-9      # ρ(M) ≤ 1 + STABLE_SLACK counts as stable (G-symplectic methods sit on |ζ| = 1)
UNIT_CIRCLE = 1e-9       # | |ζ| − 1 | below this: ζ is on the unit circle; |ζ − 1| below it: ζ = 1


@dataclass(frozen=True)
class NumericGLM:
    """A, U, B, V as float arrays, with u, w (Vu = u, wᵀV = wᵀ, wᵀu = 1) and the solver Pinv of
    (I − V)x = q, wᵀx = 0."""

    A: np.ndarray
    U: np.ndarray
    B: np.ndarray
    V: np.ndarray

    @classmethod
    def of(cls, m) -> "NumericGLM":
        g = m.as_glm()

        def floats(M):                           # an exact sympy matrix as a float array
            return np.array(M.evalf(20).tolist(), dtype=float)

        return cls(floats(g.A), floats(g.U), floats(g.B), floats(g.V))

    @property
    def s(self) -> int:
        return self.A.shape[0]

    @property
    def r(self) -> int:
        return self.V.shape[0]

    def vectors(self):
        r = self.r
        eye = np.eye(r)
        u = np.linalg.lstsq(np.vstack([self.V - eye, self.U]), np.r_[np.zeros(r), np.ones(self.s)], rcond=None)[0]
        vals, left = np.linalg.eig(self.V.T)
        k = int(np.argmin(abs(vals - 1)))
        w = left[:, k].real
        w = w / (w @ u)
        P = np.vstack([eye - self.V, w])
        return u, w, np.linalg.pinv(P)


def _eigenvalues(g: NumericGLM, z: np.ndarray) -> np.ndarray:
    """The eigenvalues of M(z) for each z (vectorised), shape (len(z), r)."""
    s = g.s
    lhs = np.eye(s)[None, :, :] - z[:, None, None] * g.A[None, :, :]
    X = np.linalg.solve(lhs, np.broadcast_to(g.U, (len(z),) + g.U.shape).astype(complex))
    M = g.V[None, :, :] + z[:, None, None] * np.einsum("ij,njk->nik", g.B, X)
    return np.linalg.eigvals(M)


def _radii(g: NumericGLM, z: np.ndarray) -> np.ndarray:
    """ρ(M(z)) for each z (vectorised)."""
    return np.max(np.abs(_eigenvalues(g, z)), axis=1)


def _interval(g: NumericGLM, direction: complex) -> float:
    """The end of the stable interval along ``direction``: a grid, then bisection.  On the unit circle
    (a G-symplectic method) instability starts where two eigenvalues of M collide, and the band it
    opens can be narrower than the grid: for GLM6M (methods/glm6_moonshot.json) the grid of 0.01
    stepped over the band at y = 2.0779 and read Y* = 3.68.  So around each local minimum of the
    eigenvalues' smallest mutual distance below COLLISION_GAP (before the first unstable grid point)
    the grid is refined to FINE_POINTS points."""
    ys = np.linspace(0.0, YMAX, AXIS_POINTS)
    with np.errstate(all="ignore"):
        ev = _eigenvalues(g, direction * ys)
    rho = np.max(np.abs(ev), axis=1)
    bad = np.flatnonzero(~(rho <= 1 + STABLE_SLACK))
    end = bad[0] if len(bad) else len(ys)
    # thin bands: refine around near-collisions of eigenvalues before the first unstable grid point
    r = ev.shape[1]
    if r > 1 and end > 1:
        with np.errstate(all="ignore"):
            gap = np.min([np.abs(ev[:, i] - ev[:, j]) for i in range(r) for j in range(i + 1, r)], axis=0)
        near = [i for i in range(1, end - 1)
                if gap[i] < COLLISION_GAP and gap[i] <= gap[i - 1] and gap[i] <= gap[i + 1]]
        for i in near:
            fine = np.linspace(ys[i - 1], ys[i + 1], FINE_POINTS)
            with np.errstate(all="ignore"):
                fr = _radii(g, direction * fine)
            fbad = np.flatnonzero(~(fr <= 1 + STABLE_SLACK))
            if len(fbad):
                if fbad[0] == 0:
                    return float(fine[0])
                lo, hi = fine[fbad[0] - 1], fine[fbad[0]]
                return _bisect(g, direction, lo, hi)
    if not len(bad):
        return YMAX
    if bad[0] == 0:
        return 0.0
    return _bisect(g, direction, ys[bad[0] - 1], ys[bad[0]])


def _bisect(g: NumericGLM, direction: complex, lo: float, hi: float) -> float:
    """The end of stability between a stable ``lo`` and an unstable ``hi``."""
    for _ in range(40):
        mid = (lo + hi) / 2
        with np.errstate(all="ignore"):
            ok = _radii(g, np.array([direction * mid]))[0] <= 1 + STABLE_SLACK
        lo, hi = (mid, hi) if ok else (lo, mid)
    return float(lo)


def imaginary_interval(g: NumericGLM) -> float:
    """Y*, the end of the stable interval [0, iY*] of the imaginary axis (YMAX: at least that)."""
    return _interval(g, 1j)


def real_interval(g: NumericGLM) -> float:
    """X*, the end of the stable interval [−X*, 0] of the real axis (YMAX: at least that)."""
    return _interval(g, -1.0)


def growth(g: NumericGLM) -> list:
    """μ for each eigenvalue ζ ≠ 1 of V on the unit circle (complex)."""
    vals, right = np.linalg.eig(g.V)
    lvals, left = np.linalg.eig(g.V.T)
    out = []
    for k, z in enumerate(vals):
        if abs(abs(z) - 1) > UNIT_CIRCLE or abs(z - 1) < UNIT_CIRCLE:
            continue
        x = right[:, k]
        y = left[:, int(np.argmin(abs(lvals - z)))]
        out.append(complex(y @ g.B @ g.U @ x / (z * (y @ x))))
    return out


def _underlying(g: NumericGLM, n: int) -> dict:
    """Φ(t) for |t| ≤ n: the underlying one-step method normalised by wᵀξ = 0."""
    u, w, Pinv = g.vectors()
    return glm_series(g.A.tolist(), g.U.tolist(), g.B.tolist(), list(u), list(w), Pinv.tolist(), n, 0.0, 1.0)[0]


def order_residuals(g: NumericGLM, p: int) -> np.ndarray:
    """Φ(t) − 1/γ(t) for every tree with |t| ≤ p (by order), Φ the underlying one-step method
    normalised by wᵀξ = 0: all vanish up to p when the method has order p with the identity as its
    principal starting component (θ ≡ 0)."""
    phi = _underlying(g, p)
    return np.array([phi[t] - 1 / density(t) for n in range(1, p + 1) for t in trees_of_order(n)])


def series_defects(g: NumericGLM, p: int) -> tuple:
    """(max |Φ(t) − 1/γ(t)| over |t| ≤ p, ‖(Φ(t) − 1/γ(t))/σ(t)‖₂ over |t| = p + 1) for the
    underlying one-step method Φ normalised by wᵀξ = 0 (:func:`..analysis.method_series.error_terms`)."""
    phi = _underlying(g, p + 1)
    residual = max((abs(phi[t] - 1 / density(t)) for n in range(1, p + 1) for t in trees_of_order(n)), default=0.0)
    return float(residual), float(np.sqrt(sum(e * e for e in error_terms(phi, p + 1))))
