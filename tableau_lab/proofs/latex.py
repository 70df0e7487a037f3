r"""LaTeX proof reports of a method: the tableau, the G-symplecticity proof (the unknowns, the
linear system, the solution family, the chosen G and D, each condition computed step by step
down to the zero matrix, or the obstruction), the RK symplecticity matrix, the order conditions
and the starting method, the parasitic growth parameters.  Every number comes from the
analyses' result objects; a sidecar JSON of the facts lets a test read them back.

Long exact entries (nested radicals) are replaced by named constants κ₁, κ₂, … listed after the
section, broken across lines at their top-level sums, so that nothing overflows the page.  Only
packages of TeX Live's ``latex-base`` and ``latex-recommended`` are used (amsmath, amssymb,
geometry, graphicx, booktabs, longtable).

>>> from tableau_lab.exact.tableau_json import load
>>> tex, facts = method_document(load("methods/example4_glm.json"))
>>> facts["D"], facts["BtGB"][0][1]
(['1/2', '1/2'], '-sqrt(3)/6')
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import sympy as sp

from ..analysis.glm_order import condition_residuals
from ..analysis.order import order as order_of
from ..analysis.parasitism import growth_parameters
from ..analysis.prk_order import condition_table
from ..analysis.symplectic import g_symplectic, rk_symplectic
from ..analysis.trees import bracket, bracket_tex, trees_of_order
from ..exact.field import normal_form
from ..exact.grammar import format_entry
from ..exact.methods import Method
from ..exact.render import LATEX, latex_text, signed_term
from ..files import OutputError, atomic_copy, atomic_write_text, output_phase
from ..process import die_with_parent, scratch_folder
from .backward_error import modified_section

__all__ = ["method_document", "library_document", "compile_pdf", "ReportError", "write_report", "report_paths",
           "FACTS_SUFFIX", "report"]

PREAMBLE = r"""\documentclass[11pt]{article}
\usepackage[a4paper,margin=2.2cm]{geometry}
\usepackage{amsmath,amssymb}
\usepackage{graphicx}
\usepackage{booktabs}
\usepackage{longtable}
\usepackage[utf8]{inputenc}
\usepackage[T1]{fontenc}
\IfFileExists{lmodern.sty}{\usepackage{lmodern}}{}
\input{glyphtounicode}\pdfgentounicode=1
\ifdefined\pdftrailerid\pdftrailerid{}\fi
\ifdefined\pdfsuppressptexinfo\pdfsuppressptexinfo=-1\fi
\allowdisplaybreaks
\setlength{\parindent}{0pt}
\setlength{\parskip}{4pt}
"""

LONG = 40          # characters of LaTeX above which an entry becomes a named constant
UNBREAKABLE = 160  # a constant with one term of more LaTeX characters is typeset as a decimal (exact: facts)


class ReportError(RuntimeError):
    """pdflatex missing (when a PDF was required) or failing; the message names the file."""


def _escape(text: str) -> str:
    """Plain text in LaTeX text mode (:func:`..exact.render.latex_text`), for pdflatex: the few
    non-ASCII characters the texts use as LaTeX, any other as ?."""
    out = latex_text(text)
    for a, b in (("−", "-"), ("≤", r"$\le$"), ("≥", r"$\ge$"), ("τ", r"$\tau$"), ("θ", r"$\theta$"),
                 ("ξ", r"$\xi$"), ("μ", r"$\mu$"), ("ζ", r"$\zeta$"), ("√", r"$\surd$"), ("–", "--"), ("—", "---"),
                 ("§", r"\S{}"), ("ᵀ", r"$^{\mathsf T}$"), ("·", r"$\cdot$"), ("→", r"$\to$"), ("≠", r"$\ne$"),
                 ("²", r"$^2$"), ("³", r"$^3$"), ("⁴", r"$^4$"), ("₁", r"$_1$"), ("₂", r"$_2$"), ("ö", r"\"o")):
        out = out.replace(a, b)
    return "".join(c if ord(c) < 128 or c in "$" else "?" for c in out)


def _chunks(e, width: int = 70) -> list[str]:
    """The LaTeX of e cut at its top-level sums into pieces of about ``width`` characters."""
    e = sp.sympify(e)
    terms = list(e.args) if e.is_Add else [e]
    chunks, cur = [], ""
    for k, term in enumerate(terms):
        negative, t = signed_term(term, None, LATEX)          # the one printer's sign and magnitude
        piece = ("- " if negative else "+ " if k else "") + t
        if cur and len(cur) + len(piece) > width:
            chunks.append(cur)
            cur = piece
        else:
            cur = (cur + " " + piece).strip()
    chunks.append(cur)
    return chunks


class _Constants:
    """Named constants for long entries: κ_k, defined once each."""

    def __init__(self):
        self.items: list[tuple[str, sp.Expr]] = []
        self._seen: dict = {}
        self.exact: dict = {}           # constants typeset as decimals: name -> exact value (text)

    def tex(self, e) -> str:
        e = sp.sympify(e)
        t = sp.latex(e)
        if len(t) <= LONG:
            return t
        key = sp.srepr(e)
        if key not in self._seen:            # numbered through the whole document
            self.items.append((rf"\kappa_{{{len(self._seen) + 1}}}", e))
            self._seen[key] = self.items[-1][0]
        return self._seen[key]

    def matrix(self, M) -> str:
        M = sp.Matrix(M)
        rows = [" & ".join(self.tex(M[i, j]) for j in range(M.cols)) for i in range(M.rows)]
        return r"\begin{pmatrix}" + r" \\ ".join(rows) + r"\end{pmatrix}"

    def flush(self) -> str:
        """The definitions so far (each broken at its top-level sums), then forget them."""
        if not self.items:
            return ""
        lines = []
        for name, e in self.items:
            chunks = _chunks(e)
            if max(map(len, chunks)) > UNBREAKABLE:      # one term wider than the page: its decimal value here,
                self.exact[name] = str(e)                # the exact value in the facts file ("long_constants")
                lines.append(rf"{name} &\approx {sp.latex(sp.N(e, 20))} "
                             r"\quad\text{(exact value: facts file, long\_constants)}")
                continue
            lines.append(f"{name} &= {chunks[0]}" + "".join(rf" \\ &\quad {c}" for c in chunks[1:]))
        self.items = []
        return "\n\nwhere\n\\begin{align*}\n" + " \\\\\n".join(lines) + "\n\\end{align*}\n"


def _tableau(m: Method, C: _Constants) -> str:
    """The tableau (``Method.tableau_latex``, shared with the notebook display) as display math,
    long entries as named constants; a GLM's stage abscissae below it."""
    out = rf"\[ {m.tableau_latex(C.tex)} \]"
    if m.kind == "glm":
        out += "\n" + rf"with stage abscissae ${m.abscissae_latex(C.tex)}$."
    return out


def _g_section(m: Method, res, C: _Constants, facts: dict) -> str:
    g = m.as_glm()
    r, s = g.r, g.s
    out = [r"\section*{G-symplecticity}",
           r"We seek a symmetric $G$ and a diagonal $D$ with "
           r"\[ V^{\mathsf T}GV = G,\qquad DU = B^{\mathsf T}GV,\qquad DA + A^{\mathsf T}D = B^{\mathsf T}GB. \]",
           rf"With the unknowns $g_{{ij}}$ ($i \le j$) of $G$ and $d_1,\dots,d_{s}$ of $D$ these are "
           rf"{res.equations} homogeneous linear equations in {res.unknowns} unknowns, of rank {res.rank}, "
           rf"solved exactly over the number field of the tableau: the solution family has dimension "
           rf"{res.dimension}."]
    out.append(_system(g, C))
    if res.basis:
        out.append("A basis of the family:")
        for k, (G, D) in enumerate(res.basis, 1):
            out.append(rf"\[ G_{{{k}}} = {C.matrix(G)},\qquad D_{{{k}}} = {C.matrix(D)} \]")
    if res.G is None:
        out.append(r"\textbf{The method is not G-symplectic:} " + _escape(res.reason))
        out.append(C.flush())
        return "\n".join(out)
    G, D = sp.Matrix(res.G), sp.Matrix(res.D)
    A, U, B, V = (sp.Matrix(x) for x in (g.A, g.U, g.B, g.V))
    def normal(M):                               # each entry in its exact normal form
        return M.applyfunc(lambda x: normal_form(sp.expand(x)))

    VtGV, DU = normal(V.T * G * V), normal(D * U)
    DA, BtGB = normal(D * A + A.T * D), normal(B.T * G * B)
    facts.update(G=[[str(format_entry(x)) for x in G.row(i)] for i in range(r)],
                 D=[str(format_entry(D[i, i])) for i in range(s)],
                 BtGB=[[str(format_entry(x)) for x in BtGB.row(i)] for i in range(s)],
                 DA_AtD=[[str(format_entry(x)) for x in DA.row(i)] for i in range(s)])
    out += [r"We take the member whose first nonzero entry of $G$ is 1:",
            rf"\[ G = {C.matrix(G)},\qquad D = {C.matrix(D)}. \]",
            "Then, computed exactly,",
            rf"\[ V^{{\mathsf T}}GV = {C.matrix(VtGV)} = G, \]",
            rf"\[ DU = {C.matrix(DU)} = B^{{\mathsf T}}GV, \]",
            rf"\[ DA + A^{{\mathsf T}}D = {C.matrix(DA)} = B^{{\mathsf T}}GB, \]",
            r"so each of $V^{\mathsf T}GV - G$, $DU - B^{\mathsf T}GV$ and $DA + A^{\mathsf T}D - B^{\mathsf T}GB$ "
            r"is the zero matrix. "
            + (rf"$\det G = {C.tex(normal_form(G.det()))} \ne 0$, and $G$ is "
               + ("definite" if res.definite else "indefinite") + ". The method is G-symplectic.")]
    out.append(C.flush())
    return "\n".join(out)


def _system(g, C: _Constants, most: int = 16) -> str:
    """The linear equations in the entries of G and D (listed when there are at most ``most``)."""
    r, s = g.r, g.s
    G = sp.Matrix(r, r, lambda i, j: sp.Symbol(f"g_{{{min(i, j) + 1}{max(i, j) + 1}}}"))
    D = sp.diag(*[sp.Symbol(f"d_{{{i + 1}}}") for i in range(s)])
    A, U, B, V = (sp.Matrix(x) for x in (g.A, g.U, g.B, g.V))
    eqs = []
    for M, sym in ((V.T * G * V - G, True), (D * U - B.T * G * V, False), (D * A + A.T * D - B.T * G * B, True)):
        for i in range(M.rows):
            for j in range(i if sym else 0, M.cols):
                e = sp.expand(M[i, j])
                if e == 0:
                    continue
                e = sp.Add(*[normal_form(c) * x for x, c in e.as_coefficients_dict().items()])
                if e != 0 and e not in eqs and -e not in eqs:
                    eqs.append(e)
    if not eqs or len(eqs) > most:
        return ""
    body = r" \\ ".join("&" + r" \\ &\quad ".join(_chunks(e, 120)) + " = 0" for e in eqs)
    return (f"Written out, the {len(eqs)} distinct nonzero equations are\n\\begin{{align*}} {body} \\end{{align*}}\n"
            + C.flush())


MAX_CONDITION_ROWS = 400   # beyond: the rows |t| ≤ 6 and the failing ones are listed, all in the facts


def _order_section(m: Method, C: _Constants, facts: dict) -> str:
    """The order as a proof: every order condition up to p + 1 evaluated exactly, row by row."""
    o = order_of(m)
    facts["order"] = o.order
    out = [r"\section*{Order}"]
    if m.kind == "glm":
        return "\n".join(out + _glm_order_proof(m, o, C, facts))
    if m.kind == "prk":
        rows = [(n, label, label.replace("●", r"\bullet ").replace("○", r"\circ "), phi, g, d)
                for n, label, phi, g, d in condition_table(m, o.order + 1)]
        out.append(r"The elementary weights of the bicoloured trees ($\bullet$: a vertex of the first "
                   r"partition, $q$; $\circ$: of the second, $p$; the colour of the root follows its bracket), "
                   r"$\Phi(t) = b_{\mathrm{root}}^{\mathsf T}\Psi(t)$, against $1/\gamma(t)$ "
                   "([HLW06] III.2.1), computed exactly:")
    else:
        facts["effective_order"] = o.effective_order
        rows = list(o.conditions)
        out.append(r"The elementary weights $\Phi(t) = b^{\mathsf T}\Psi(t)$ of the rooted trees against "
                   rf"$1/\gamma(t)$, computed exactly (stage order {o.stage_order}; simplifying assumptions "
                   rf"$B({o.B})$, $C({o.C})$, $D({o.D})$):")
    out += _weights_proof(rows, o.order, C, facts, capped=not o.errors if m.kind == "prk" else o.capped)
    if m.kind == "rk" and o.effective_order is not None:
        out.append(f"Effective order (with a starting method, analysis.glm\\_order): {o.effective_order}.")
    return "\n".join(out)


def _conditions_facts(p: int, values: dict, orders: dict, failing: list) -> dict:
    """The facts of an order proof: which orders were checked, up to which order every residual is
    zero (read from the residuals themselves), the failing trees at p + 1."""
    zero_up_to = 0
    for k in range(1, p + 2):
        if any(orders[t] == k and not _all_zero(v) for t, v in values.items()):
            break
        if any(orders[t] == k for t in values):
            zero_up_to = k
    return {"checked_up_to": p + 1, "all_zero_up_to": zero_up_to, "nonzero_at_p_plus_1": failing}


def _all_zero(v) -> bool:
    return all(x == 0 for x in v) if isinstance(v, tuple) else v == 0


def _weights_proof(rows, p: int, C: _Constants, facts: dict, capped: bool) -> list:
    """rows: (order, key, LaTeX of t, Φ(t), 1/γ(t), Φ(t) − 1/γ(t)); the table and the pinning."""
    failing = [key for n, key, _, _, _, d in rows if n == p + 1 and d != 0]
    shown = rows if len(rows) <= MAX_CONDITION_ROWS else [r for r in rows if r[0] <= 6 or r[5] != 0]
    body, last = [], 1
    for n, _, tex, phi, g, d in shown:
        if n != last:
            body.append(r"\midrule")
            last = n
        body.append(rf"${tex}$ & ${n}$ & ${C.tex(phi)}$ & ${C.tex(g)}$ & ${C.tex(d)}$ & "
                    + ("$=$" if d == 0 else r"$\ne$") + r" \\")
    out = [r"{\small\begin{longtable}{lccccc} \toprule $t$ & $|t|$ & $\Phi(t)$ & $1/\gamma(t)$ & "
           r"$\Phi(t) - 1/\gamma(t)$ & \\ \midrule \endhead" + "\n" + "\n".join(body)
           + r" \bottomrule \end{longtable}}", C.flush()]
    if len(shown) < len(rows):
        out.append(f"({len(rows) - len(shown)} further conditions of order $7 \\le |t| \\le {p}$, each with "
                   r"$\Phi(t) - 1/\gamma(t) = 0$ exactly, are not listed; all are in the facts file.)")
    held = sum(1 for r in rows if r[0] <= p)
    head = (rf"All {held} conditions with $|t| \le {p}$ hold: $\Phi(t) - 1/\gamma(t) = 0$ exactly in each "
            "row. " if p else r"No condition has $|t| \le 0$. ")
    at = sum(1 for r in rows if r[0] == p + 1)
    if failing:
        names = {key: tex for _, key, tex, *_ in rows}
        out.append(head + rf"At $|t| = {p + 1}$ the conditions fail for {len(failing)} of the {at} trees ("
                   + ", ".join(f"${names[k]}$" for k in failing) + rf"), so the order is exactly {p}.")
    else:
        out.append(head + rf"The {at} conditions at $|t| = {p + 1}$ hold as well"
                   + (": the check stopped at its cap, the order is at least that." if capped else "."))
    orders = {key: n for n, key, *_ in rows}
    facts["order_conditions"] = dict(_conditions_facts(p, {key: d for _, key, _, _, _, d in rows}, orders, failing),
                                     differences={key: str(format_entry(d)) for _, key, _, _, _, d in rows})
    return out


def _glm_order_proof(m: Method, o, C: _Constants, facts: dict) -> list:
    """Butcher's order conditions of a GLM with the computed starting method, evaluated tree by tree."""
    p, r = o.order, len(o.u)
    facts["order_identity_start"] = o.order_identity_start
    values, repairable = condition_residuals(m, o.starting_exact, p + 1)
    orders = {bracket(t): k for k in range(1, p + 2) for t in trees_of_order(k)}

    def vec(v):                                  # a vector in LaTeX, 0 for the zero vector
        return "0" if _all_zero(v) else r"\bigl(" + ", ".join(C.tex(x) for x in v) + r"\bigr)"

    out = [r"Butcher's algebraic order theory ([B16] Sec.~53; analysis.glm\_order): the starting method is "
           r"$y^{[0]}_i = B(\xi_i, y_0)$ with $\xi(\emptyset) = u = " + vec(o.u)
           + r"$, the stages of a step from it are B-series with coefficients $\eta$, "
           r"$(\eta D)(\tau) = 1$, $(\eta D)([t_1\dots t_m]) = \prod_k \eta(t_k)$, and $E$ is the exact flow. "
           rf"The method has order {p} relative to $\xi$ when, for every rooted tree $t$ with $|t| \le {p}$,",
           r"\[ \eta(t) = A\,(\eta D)(t) + U\,\xi(t), \qquad R(t) := B\,(\eta D)(t) + V\,\xi(t) - (\xi E)(t) = 0, \]",
           r"where $(\xi E)(t) = \xi(\emptyset)/\gamma(t) + \sum_s c(t, s)\,\xi(s) + \xi(t)$ is the composition "
           r"of $\xi$ with the exact flow (the sum over the trunks $s \ne \emptyset, t$ left by the cuts of $t$, "
           r"$c(t, s)$ the sum over those cuts of $\prod 1/\gamma$ of the pieces cut off). "
           r"The first (stage) condition defines $\eta(t)$; the table gives the computed starting method "
           r"$\xi(t)$ and the residual $R(t)$ of the second (output) condition, a vector of "
           rf"{r} entries, evaluated exactly with that $\xi$. For $|t| = {p + 1}$ it gives $w^{{\mathsf T}}R(t)$, "
           rf"with $w = {vec(o.w)}$ the left eigenvector of $V$ for the eigenvalue 1 ($w^{{\mathsf T}}u = 1$): "
           r"since $w^{\mathsf T}(V - I) = 0$ it does not depend on $\xi(t)$, and the output condition can be "
           r"solved for $\xi(t)$ only if it is zero."]
    body = [f"${bracket_tex(t)}$ & " + " & ".join(f"${C.tex(x)}$" for x in o.starting[t]) + f" & ${vec(v)}$" + r" \\"
            for t, v in values.items() if orders[t] <= p]
    late = [(t, v) for t, v in values.items() if orders[t] == p + 1]
    body.append(r"\midrule "
                + rf"$|t| = {p + 1}$ & \multicolumn{{{r}}}{{c}}{{(not needed)}} & $w^{{\mathsf T}}R(t)$ \\")
    body += [f"${bracket_tex(t)}$ & \\multicolumn{{{r}}}{{c}}{{}} & ${C.tex(v)}$" + r" \\" for t, v in late]
    out.append(r"{\small\begin{longtable}{l" + "c" * r + r"c} \toprule $t$ & "
               + " & ".join(f"$\\xi_{{{i + 1}}}(t)$" for i in range(r)) + r" & $R(t)$ \\ \midrule \endhead"
               + "\n" + "\n".join(body) + r" \bottomrule \end{longtable}}")
    out.append(C.flush())
    failing = [t for t, v in late if v != 0]
    zero = all(_all_zero(v) for t, v in values.items() if orders[t] <= p)
    text = (rf"Every $R(t)$ with $|t| \le {p}$ is the zero vector: the starting method above satisfies all the "
            rf"order conditions up to order {p}. " if zero else
            rf"\textbf{{Not every $R(t)$ with $|t| \le {p}$ is zero}}: the starting method above does not "
            rf"give order {p}. ")
    if failing:
        text += (rf"At $|t| = {p + 1}$, $w^{{\mathsf T}}R(t) \ne 0$ for "
                 + ", ".join(f"${bracket_tex(t)}$" for t in failing)
                 + rf". Changing the principal parts $\theta(s) = w^{{\mathsf T}}\xi(s)$, $|s| = {p}$ "
                 r"($\xi(s) \mapsto \xi(s) + \theta(s)u$, which changes no condition of lower order) adds "
                 rf"$L_{{{p + 1}}}\theta$ to these values, and the linear system $L_{{{p + 1}}}\theta = "
                 r"-w^{\mathsf T}R$ " + ("has a solution." if repairable else
                                          "has no solution (solved exactly); the principal parts of lower order "
                                          r"are forced by the conditions up to order " + str(p)
                                          + r" ($L_k$ has full column rank for $k \ge 3$, and $\theta(\tau)$, a "
                                          "time shift, never matters). So no starting method gives order "
                                          f"{p + 1}: the order is exactly {p}."))
    elif o.capped:
        text += rf"The conditions at $|t| = {p + 1}$ hold as well: the check stopped at its cap."
    out.append(text)
    if o.errors:
        out.append(rf"The error terms at order {p + 1} (the residuals left when $\theta$ satisfies a maximal "
                   r"independent set of the conditions): "
                   + "; ".join(f"${bracket_tex(t)}$: ${C.tex(v)}$" for t, v in list(o.errors.items())[:6]) + ".")
    if o.errors_identity_start:
        out.append(rf"With $\theta \equiv 0$ (the identity as first starting component) the order is "
                   rf"{o.order_identity_start}: the conditions $w^{{\mathsf T}}R(t) = 0$ of order "
                   rf"{o.order_identity_start + 1} fail for "
                   + ", ".join(f"${bracket_tex(t)}$" for t in o.errors_identity_start) + ".")
    out.append(C.flush())
    facts["order_conditions"] = dict(
        _conditions_facts(p, values, orders, failing), theta_can_repair=repairable,
        identity_start_fails_at=list(o.errors_identity_start),
        residuals={t: [str(format_entry(x)) for x in v] for t, v in values.items() if orders[t] <= p},
        solvability={t: str(format_entry(v)) for t, v in late})
    return out


def _parse(text):
    from ..exact.grammar import parse_entry
    return parse_entry(text)


def method_document(m: Method, figures=(), stability: bool = False) -> tuple[str, dict]:
    """A standalone LaTeX document for one method, and the facts it states (exact, as strings);
    ``stability``: with the exact imaginary-axis interval (``analysis.stability``)."""
    return _document([m], figures, title=m.name, stability=stability)


def report(method: Method, out=None, *, stability: bool = False, pdf: bool = False):
    r"""The LaTeX proof report of ``method`` (``tl.report``; ``tableau-lab report``): with ``out``
    None its LaTeX source as a string; with ``out`` (``FOLDER/NAME``) the files NAME.tex and
    NAME.report.json written there (never over an input or a file of another kind:
    :mod:`tableau_lab.files`) and, when ``pdf`` is true, compiled to NAME.pdf (pdflatex required);
    returns the path of the .tex, or of the .pdf when one was made.  ``stability``: with the exact
    imaginary-axis interval.  Each section states the analysis it reports and its reference
    (G-symplecticity: [BHHN14] Butcher, Habib, Hill & Norton, SIAM J. Numer. Anal. 52 (2014);
    order: [B16] Butcher, *Numerical Methods for ODEs*, 3rd ed., ch. 3 and 5).

    >>> import tableau_lab as tl
    >>> tex = tl.report(tl.load("implicit_midpoint"))
    >>> tex.startswith(r"\documentclass"), "symplectic" in tex
    (True, True)
    """
    tex, facts = method_document(method, stability=stability)
    if out is None:
        return tex
    from ..files import refuse_outputs
    paths = report_paths(out)
    refuse_outputs(list(paths.values()), what="report")
    tex_path = write_report(tex, facts, Path(out))
    made = compile_pdf(tex_path, required=True) if pdf else None
    return made or tex_path


def library_document(methods) -> tuple[str, dict]:
    """One document for many methods: a summary table, then a section per method."""
    return _document(list(methods), (), title="The tableau_lab method library", summary=True)


def _stability_section(m: Method, facts: dict) -> str:
    """The exact end Y* of the stable interval of the imaginary axis, as a decimal and as the root of
    an integer polynomial (that polynomial is in the facts file: it is too long to typeset)."""
    from ..analysis.stability import stability
    st = stability(m)
    Y = st.imaginary_interval
    facts["imaginary_interval"] = str(Y)
    facts["imaginary_interval_decimal"] = "oo" if Y == sp.oo else str(sp.N(Y, 20))
    rel = "= 1" if st.symplectic else r"\le 1"
    if Y == sp.oo:
        value = r"\infty"
    else:
        roots = list(Y.atoms(sp.RootOf))
        value = sp.latex(sp.N(Y, 15)) + r"\ldots"
        if roots:
            r = roots[0]
            shown = sp.latex(Y.xreplace({r: sp.Symbol("rho")}))
            value += (rf" = {shown}, \text{{ where }} \rho \text{{ is real root "
                      rf"no.\ }} {r.index + 1} \text{{ of an integer polynomial of degree }} {r.poly.degree()}")
    return "\n".join([r"\section*{Linear stability on the imaginary axis}",
                      r"With $z = iy$, every root $w$ of $P(w, z) = \det(wI - M(z))$ has "
                      rf"$|w| {rel}$ for $0 \le y < Y^*$, exactly (Sturm sequences of the axis polynomials, "
                      r"analysis.stability), with", rf"\[ Y^* = {value}. \]",
                      r"The polynomial is given in full in the facts file (key \texttt{imaginary\_interval})."])


def _body(m: Method, figures, C: _Constants, stability: bool = False) -> tuple[str, dict]:
    facts: dict = {"name": m.name, "kind": m.kind}
    parts = [r"\subsection*{Source}", r"{\sloppy " + _escape(m.source or "—") + r"\par}"]
    if m.claims:
        claims = ", ".join(f"{k} = {str(v).lower()}" for k, v in m.claims)
        parts.append(r"Claims (checked below): " + _escape(claims) + ".")
    parts += [r"\subsection*{Tableau}", _tableau(m, C), C.flush()]
    if m.kind in ("rk", "prk"):
        rs = rk_symplectic(m)
        facts["symplectic"] = rs.holds
        cond = (r"\operatorname{diag}(b)A + A^{\mathsf T}\operatorname{diag}(b) - bb^{\mathsf T}" if m.kind == "rk"
                else r"\bigl(b_i\hat a_{ij} + \hat b_j a_{ji} - b_i\hat b_j\bigr)_{ij}")
        parts += [r"\section*{Symplecticity}", rf"\[ M = {cond} = {C.matrix(rs.M)} \]",
                  "The method is " + ("symplectic." if rs.holds else "not symplectic."), C.flush()]
    if m.kind in ("rk", "glm"):
        gs = g_symplectic(m)
        facts["g_symplectic"] = gs.holds
        parts.append(_g_section(m, gs, C, facts))
    if not m.parameters:
        parts.append(_order_section(m, C, facts))
        parts.append(modified_section(m, C, facts))
    if m.kind == "glm" and not m.V.free_symbols:
        par = growth_parameters(m)
        facts["parasitism"] = [{"zeta": str(p.zeta), "mu": str(p.mu)} for p in par.items]
        parts.append(r"\section*{Parasitism}")
        if par.items:
            parts.append(r"For each eigenvalue $\zeta \ne 1$ of $V$ on the unit circle, with right and left "
                         r"eigenvectors $x$, $y$ ($yx = 1$), the growth parameter $\mu = \zeta^{-1} yBUx$:")
            parts.append(r"\[ " + r",\qquad ".join(rf"\zeta = {C.tex(p.zeta)}:\ \mu = {C.tex(p.mu)}"
                                                   for p in par.items) + r" \]")
            parts.append("Parasitism is controlled to first order." if par.free else
                         r"The growth parameters are not all zero: parasitic components can grow where "
                         r"$\mu f'(y)$ has eigenvalues with positive real part.")
        else:
            parts.append("$V$ has no eigenvalue other than 1 on the unit circle.")
        parts.append(C.flush())
    if stability and not m.parameters:
        parts.append(_stability_section(m, facts))
    for path, caption in figures:
        parts.append(rf"\begin{{figure}}[h]\centering\includegraphics[width=0.9\linewidth]{{{path}}}"
                     rf"\caption{{{_escape(caption)}}}\end{{figure}}")
    return "\n".join(p for p in parts if p), facts


def _document(methods, figures, title, summary=False, stability=False) -> tuple[str, dict]:
    out = [PREAMBLE, r"\begin{document}", rf"\begin{{center}}\Large {_escape(title)}\end{{center}}",
           r"\noindent\small Generated by tableau\_lab: every statement below is computed exactly, "
           r"not copied from the source.\normalsize"]
    facts = {}
    C = _Constants()                         # κ numbered through the whole document
    bodies = [(m, *_body(m, figures, C, stability)) for m in methods]
    if summary:
        rows = []
        for m, _, f in bodies:
            sym = "yes" if f.get("symplectic") or f.get("g_symplectic") else "no"
            gd = "--"
            if f.get("G") is not None:
                G = sp.Matrix([[_parse(x) for x in row] for row in f["G"]])
                gd = (rf"$G = {C.matrix(G)}$, $D = \operatorname{{diag}}(" + ", ".join(C.tex(_parse(x)) for x in f["D"])
                      + ")$")
            rows.append(" & ".join([_escape(m.name), m.kind, str(m.s), str(getattr(m, "r", 1)),
                                    str(f.get("order", "--")), sym, gd]) + r" \\")
        out.append(r"{\scriptsize\begin{longtable}{p{3.6cm}lcccc p{6.4cm}} \toprule method & kind & $s$ & $r$ & "
                   r"order & (G-)sympl. & $G$, $D$ \\ \midrule " + "\n".join(rows)
                   + r" \bottomrule \end{longtable}}" + C.flush())
    for m, body, f in bodies:
        if len(methods) > 1:
            out.append(rf"\clearpage\section{{{_escape(m.name)}}}")
        out.append(body)
        facts[m.name] = f
    out.append(r"\end{document}")
    result = facts if len(methods) > 1 else facts[methods[0].name]
    if C.exact:
        result["long_constants"] = {k.replace("\\", ""): v for k, v in C.exact.items()}
    return "\n".join(out) + "\n", result


REPORT_EPOCH = 1767225600   # 2026-01-01 00:00 UTC: the PDFs' date unless SOURCE_DATE_EPOCH is set


def _reproducible_env() -> dict:
    """pdflatex's environment for byte-identical PDFs from the same .tex: the creation and
    modification dates (and \\today) from SOURCE_DATE_EPOCH (reproducible-builds.org), fixed
    to REPORT_EPOCH unless the caller sets it; the preamble drops the trailer /ID."""
    env = dict(os.environ)
    env.setdefault("SOURCE_DATE_EPOCH", str(REPORT_EPOCH))
    env["FORCE_SOURCE_DATE"] = "1"
    return env


# what a PDF report needs (Debian/Ubuntu names; .ci/run installs the same): pdflatex and the
# packages above, and lmodern for Type 1 (vector) fonts
TEX_PACKAGES = ("texlive-latex-base", "texlive-latex-recommended", "lmodern")


def compile_pdf(tex_path: Path, required: bool = False) -> Path | None:
    """pdflatex twice in a scratch directory; the PDF and the log are moved beside the .tex.
    Returns None when pdflatex is absent and not required."""
    exe = shutil.which("pdflatex")
    if exe is None:
        if required:
            raise ReportError(f"{tex_path}: pdflatex is not installed (apt-get install {' '.join(TEX_PACKAGES)})")
        return None
    given = Path(tex_path)
    tex_path = given.resolve()
    with scratch_folder("tableau_lab_pdf_") as tmp:
        for _ in range(2):                       # pdflatex dies with this process (kill -9 included)
            p = subprocess.run([exe, "-interaction=nonstopmode", "-halt-on-error", "-output-directory", tmp,
                                str(tex_path)], capture_output=True, text=True, errors="replace", cwd=tex_path.parent,
                               timeout=300, preexec_fn=die_with_parent, env=_reproducible_env())
        log = Path(tmp) / (tex_path.stem + ".log")
        pdf = Path(tmp) / (tex_path.stem + ".pdf")
        failed = p.returncode != 0 or not pdf.exists()
        try:
            # the PDF and its log: atomic copies, in place together (a full disk leaves both as they were)
            with output_phase(tex_path.parent):
                if log.exists():
                    atomic_copy(log, tex_path.with_suffix(".log"))
                if not failed:
                    atomic_copy(pdf, tex_path.with_suffix(".pdf"))
        except OutputError as exc:
            raise ReportError(str(exc)) from exc
        if failed:
            raise ReportError(f"{tex_path}: pdflatex failed (see {tex_path.with_suffix('.log')}): "
                              + p.stdout[-400:].replace("\n", " "))
    return given.with_suffix(".pdf")


FACTS_SUFFIX = ".report.json"      # the facts sidecar: NAME.report.json, never NAME.json (a method file's name)


def report_paths(out) -> dict:
    """The files of the report ``out`` (``FOLDER/NAME``): ``tex`` NAME.tex, ``facts``
    NAME.report.json (its own name: a tableau ``NAME.json`` beside it is never replaced), ``pdf``
    and ``log``.

    >>> sorted(p.name for p in report_paths("proofs/glm4.3").values())
    ['glm4.3.log', 'glm4.3.pdf', 'glm4.3.report.json', 'glm4.3.tex']
    """
    out = Path(out)
    return {k: out.parent / f"{out.name}{suffix}" for k, suffix in
            (("tex", ".tex"), ("facts", FACTS_SUFFIX), ("pdf", ".pdf"), ("log", ".log"))}


def write_report(tex: str, facts: dict, out: Path) -> Path:
    """Write NAME.tex and NAME.report.json (the facts) atomically, as one set under the folder's
    lock (:mod:`tableau_lab.files`: a full disk raises ``OutputError`` naming the file and leaves
    both as they were); returns the .tex path."""
    paths = report_paths(out)
    with output_phase(Path(out).parent):
        atomic_write_text(paths["facts"], json.dumps(facts, indent=1, ensure_ascii=False, default=str))
        atomic_write_text(paths["tex"], tex)
    return paths["tex"]
