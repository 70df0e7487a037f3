"""Errors of a run, with messages that name the step and the time."""
from __future__ import annotations

__all__ = ["IntegrationError", "ParasiticBoundExceeded", "not_finite", "projection_failed", "stages_failed"]


class IntegrationError(RuntimeError):
    """A run that cannot continue; the message names step, time and the reason.  ``partial``:
    the run's records so far (set by ``integrate``)."""


class ParasiticBoundExceeded(IntegrationError):
    """The parasitism monitor stopped the run: a parasitic component exceeded the bound.
    ``step``, ``t``, ``zeta`` (as printed), ``value``, ``bound``, ``mu``."""


def projection_failed(names, n, t, res) -> IntegrationError:
    return IntegrationError(f"step {n} (t = {float(t):.6g}): projection onto {', '.join(names)} did not converge "
                            f"(residual {res:.3g} after the last iteration)")


def not_finite(n, t) -> IntegrationError:
    return IntegrationError(f"step {n} (t = {float(t):.6g}): the solution is not finite (NaN or overflow): the "
                            "method is unstable at this step size, or the problem is singular here")


def stages_failed(n, t, h, last, tol) -> IntegrationError:
    return IntegrationError(f"step {n} (t = {float(t):.6g}): the implicit stage equations did not converge "
                            f"(fixed point or simplified Newton, full Newton, then fixed-point iteration on the "
                            f"stage values; last correction {last:.3g}, tolerance {float(tol):.3g}); try a step "
                            f"size smaller than h = {float(h):.6g}")
