r"""The backward-error section of a proof report: the leading term of the modified equation and,
for a (conjugate-)symplectic method, of its modified energy ([HLW06] IX; :mod:`..analysis.modified`,
:mod:`..analysis.modified_hamiltonian`).  RK methods and GLMs (their underlying one-step method)
have B-series and the structure orders; partitioned methods have P-series, whose symplecticity the
report has already decided from the tableau."""
from __future__ import annotations

from ..analysis.bseries import modified_field, series_order
from ..analysis.method_series import method_series
from ..analysis.modified_hamiltonian import modified_hamiltonian
from ..analysis.series_structure import structure
from ..exact.methods import Method, MethodError
from ..exact.render import LATEX, exact_sum

__all__ = ["modified_section", "BEA_EXTRA", "BEA_MAX_ORDER"]

#: trees up to the method's order + BEA_EXTRA are examined, and at most BEA_MAX_ORDER
BEA_EXTRA, BEA_MAX_ORDER = 3, 9
#: terms shown per line, and at most this many per power of h
PER_LINE, MOST = 2, 9
_ROWS = {"per_row": PER_LINE, "newline": r"\\ &\qquad", "most": MOST}      # exact_sum's layout of a long sum


def modified_section(m: Method, C, facts: dict) -> str:
    """LaTeX for the section (empty when the method has no series here: V without a simple
    eigenvalue 1, or a number field over the degree budget).  ``C`` abbreviates long constants."""
    try:
        phi = method_series(m, BEA_MAX_ORDER).phi
    except (ValueError, MethodError):
        return ""
    kind = phi.kind
    N = min(series_order(phi) + BEA_EXTRA, BEA_MAX_ORDER)
    phi = phi.truncate(N)
    b = modified_field(phi)
    lead = [(t, v / kind.symmetry(t)) for t, v in b.items() if kind.order(t) > 1 and v != 0]
    out = [r"\section*{Backward error analysis}"]
    what = ("the underlying one-step method of the method" if m.kind == "glm"
            else "the method (a P-series: $q' = f(q, p)$, $p' = g(q, p)$)" if kind.coloured else "the method")
    if not lead:
        out.append(f"The series of {what} equals the exact flow for every tree with at most {N} vertices.")
        return "\n".join(out)
    k = kind.order(lead[0][0])
    facts["modified_leading_power"] = k - 1
    body = exact_sum([(c, kind.differential(t, tex=True)) for t, c in lead if kind.order(t) == k],
                     LATEX.using(C.tex), **_ROWS)
    lhs = r"(\tilde f, \tilde g) &= (f, g)" if kind.coloured else r"\tilde f &= f"
    out.append(f"The numerical solution of {what} is, formally, the exact flow of the modified equation "
               r"(Hairer, Lubich \& Wanner, \emph{Geometric Numerical Integration}, IX"
               + ("; the terms headed $f$ belong to $\\tilde f$, those headed $g$ to $\\tilde g$"
                  if kind.coloured else "")
               + "):")
    out.append(rf"\begin{{align*}} {lhs} + h^{{{k - 1}}}\bigl({body}\bigr) + O(h^{{{k}}}) \end{{align*}}")
    if kind.coloured:
        conserves = bool(facts.get("symplectic"))
    else:
        st = structure(phi, b)
        facts.update({"symplectic_series_order": st.symplectic, "conjugate_symplectic_order": st.conjugate_symplectic,
                      "series_budget": N})

        def says(n):
            return f"at least to order {n} (the budget)" if n >= N else f"to order {n} only"
        out.append(f"As a B-series it is symplectic {says(st.symplectic)}, conjugate-symplectic "
                   f"{says(st.conjugate_symplectic)}, symmetric {says(st.symmetric)} and energy-preserving "
                   f"{says(st.energy_preserving)}.")
        conserves = st.conjugate_symplectic >= N
    if conserves:
        mh = modified_hamiltonian(b)
        for n in range(2, mh.order + 1):
            terms = mh.terms(n)
            if terms:
                facts["modified_energy_leading_power"] = n - 1
                hb = mh.sum(n, LATEX, C.tex, **_ROWS)
                out.append(r"It conserves a modified energy (an H-series over free trees; "
                           r"$H(t) = H^{(m)}(F(t_1), \dots, F(t_m))$ for $t = [t_1 \dots t_m]$):")
                out.append(rf"\begin{{align*}} \tilde H &= H + h^{{{n - 1}}}\bigl({hb}\bigr) "
                           rf"+ O(h^{{{n}}}) \end{{align*}}")
                break
    out.append(C.flush())
    return "\n".join(out)
