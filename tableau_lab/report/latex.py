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
import shutil
import os
import subprocess
from pathlib import Path

import sympy as sp

from ..analysis.order import order as order_of
from ..analysis.parasitism import growth_parameters
from ..analysis.symplectic import g_symplectic, rk_symplectic
from .backward_error import modified_section
from ..exact.field import normal_form
from ..files import OutputError, atomic_copy, atomic_write_text, output_phase
from ..process import die_with_parent, scratch_folder
from ..exact.grammar import format_entry
from ..exact.methods import Method

__all__ = ["method_document", "library_document", "compile_pdf", "ReportError", "write_report"]

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
\allowdisplaybreaks
\setlength{\parindent}{0pt}
\setlength{\parskip}{4pt}
"""

LONG = 40          # characters of LaTeX above which an entry becomes a named constant
UNBREAKABLE = 160  # a constant with one term of more LaTeX characters is typeset as a decimal (exact: facts)


class ReportError(RuntimeError):
    """pdflatex missing (when a PDF was required) or failing; the message names the file."""


def _escape(text: str) -> str:
    repl = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#", "_": r"\_",
            "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}", "^": r"\textasciicircum{}"}
    out = "".join(repl.get(c, c) for c in text)
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
        t = sp.latex(term)
        piece = t if k == 0 else (t if t.startswith("-") else "+ " + t)
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
    nf = lambda M: M.applyfunc(lambda x: normal_form(sp.expand(x)))  # noqa: E731
    VtGV, DU = nf(V.T * G * V), nf(D * U)
    DA, BtGB = nf(D * A + A.T * D), nf(B.T * G * B)
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


def _order_section(m: Method, C: _Constants, facts: dict) -> str:
    o = order_of(m)
    facts["order"] = o.order
    out = [r"\section*{Order}"]
    if m.kind == "prk":
        out.append(f"The order conditions of the bicoloured trees hold up to order {o.order} and not all at "
                   f"order {o.order + 1}: the partitioned method has order {o.order}.")
        return "\n".join(out)
    if m.kind == "rk":
        facts["effective_order"] = o.effective_order
        out.append(f"The elementary weights $\\Phi(t)$ equal $1/\\gamma(t)$ for every rooted tree with at most "
                   f"{o.order} vertices and not for all trees with {o.order + 1}: classical order {o.order}"
                   + (f", effective order {o.effective_order}" if o.effective_order is not None else "") + ".")
        out.append(r"{\small " + o.to_latex().replace("\\begin{tabular}", "\\begin{longtable}").replace(
            "\\end{tabular}", "\\end{longtable}") + "}")
        return "\n".join(out)
    facts["order_identity_start"] = o.order_identity_start
    out.append(f"Relative to a suitable starting method the method has order {o.order} "
               f"({o.order_identity_start} with the identity as first starting component, $\\theta \\equiv 0$); "
               f"stage order {o.stage_order}. The starting method $y^{{[0]}}_i = B(\\xi_i, y_0)$:")
    r = len(o.u)
    rows = [f"${_tree(t)}$ & " + " & ".join(f"${C.tex(x)}$" for x in xi) + r" \\"
            for t, xi in o.starting.items()]
    out.append(r"{\small\begin{longtable}{l" + "c" * r + r"} \toprule $t$ & "
               + " & ".join(f"$\\xi_{{{i + 1}}}(t)$" for i in range(r)) + r" \\ \midrule "
               + "\n".join(rows) + r" \bottomrule \end{longtable}}")
    out.append(C.flush())
    if o.errors:
        out.append(f"Error terms at order {o.order + 1}: "
                   + "; ".join(f"${_tree(t)}$: ${C.tex(v)}$" for t, v in list(o.errors.items())[:6]) + ".")
    out.append(C.flush())
    return "\n".join(out)


def _parse(text):
    from ..exact.grammar import parse_entry
    return parse_entry(text)


def _tree(bracket: str) -> str:
    out = bracket.replace("τ", r"\tau ")
    for d, sup in zip("0123456789", "⁰¹²³⁴⁵⁶⁷⁸⁹"):
        out = out.replace(sup, f"^{{{d}}}")
    return out


def method_document(m: Method, figures=(), stability: bool = False) -> tuple[str, dict]:
    """A standalone LaTeX document for one method, and the facts it states (exact, as strings);
    ``stability``: with the exact imaginary-axis interval (``analysis.stability``)."""
    return _document([m], figures, title=m.name, stability=stability)


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
        parts.append(r"Claims (checked below): " + _escape(", ".join(f"{k} = {str(v).lower()}" for k, v in m.claims)) + ".")
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


def compile_pdf(tex_path: Path, required: bool = False) -> Path | None:
    """pdflatex twice in a scratch directory; the PDF and the log are moved beside the .tex.
    Returns None when pdflatex is absent and not required."""
    exe = shutil.which("pdflatex")
    if exe is None:
        if required:
            raise ReportError(f"{tex_path}: pdflatex is not installed (apt-get install texlive-latex-base "
                              "texlive-latex-recommended)")
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


def write_report(tex: str, facts: dict, out: Path) -> Path:
    """Write NAME.tex and NAME.json (the facts) atomically, as one set under the folder's lock
    (:mod:`tableau_lab.files`: a full disk raises ``OutputError`` naming the file and leaves both
    as they were); returns the .tex path."""
    out = Path(out)
    with output_phase(out.parent):
        atomic_write_text(out.with_suffix(".json"), json.dumps(facts, indent=1, ensure_ascii=False, default=str))
        atomic_write_text(out.with_suffix(".tex"), tex)
    return out.with_suffix(".tex")
