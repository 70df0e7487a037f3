r"""The audit's report files (``tableau-lab audit --out DIR``, ``tl.audit(paths, out=DIR)``):
``audit.json`` (every row, bad and skipped file), ``audit.md`` (the table and every disagreement
with its evidence), ``audit.tex`` (the same as a LaTeX document on the proof reports' preamble,
one longtable line per method) and ``audit.pdf`` when pdflatex is installed
(:func:`~tableau_lab.proofs.latex.compile_pdf`, as ``tableau-lab report`` does).  The files are
written together, atomically, inside ``out`` only and never over an input (:mod:`tableau_lab.files`).
The audit itself is :mod:`tableau_lab.experiments.audit`.

>>> import tableau_lab as tl
>>> tex = audit_tex(tl.audit(["methods/gauss2.json"], workers=1))
>>> tex.startswith(r"\documentclass"), r"\begin{longtable}" in tex
(True, True)
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from ..exact.render import latex_text
from ..experiments.audit import AUDIT_SECONDS, AuditResult, audit_files, markdown_report
from ..files import atomic_write_text, output_phase, refuse_outputs
from .latex import PREAMBLE, compile_pdf

__all__ = ["audit", "audit_tex", "AUDIT_FILES"]

#: the files an audit writes into its --out folder (audit.pdf and audit.log only with pdflatex)
AUDIT_FILES = ("audit.json", "audit.md", "audit.tex", "audit.pdf", "audit.log")

# characters outside Latin-1 that the audit's text may hold, for pdflatex (inputenc knows Latin-1 and T1 letters)
_UNICODE = {"Φ": r"\ensuremath{\Phi}", "γ": r"\ensuremath{\gamma}", "τ": r"\ensuremath{\tau}",
            "Σ": r"\ensuremath{\Sigma}",
            "→": r"\ensuremath{\to}", "≥": r"\ensuremath{\ge}", "≤": r"\ensuremath{\le}", "−": "-",
            "≠": r"\ensuremath{\neq}", "…": r"\dots{}", "ᵢ": r"\ensuremath{_i}", "ⱼ": r"\ensuremath{_j}",
            "\u0302": r"\^{}", "β": r"\ensuremath{\beta}", "∞": r"\ensuremath{\infty}", "√": r"\ensuremath{\surd}",
            "–": "--", "—": "---", "’": "'", "·": r"\ensuremath{\cdot}", "±": r"\ensuremath{\pm}",
            "∈": r"\ensuremath{\in}", "θ": r"\ensuremath{\theta}", "Ψ": r"\ensuremath{\Psi}",
            **{sup: rf"\textsuperscript{{{d}}}" for d, sup in enumerate("⁰¹²³⁴⁵⁶⁷⁸⁹")}}


def _unicode_declarations(tex: str) -> str:
    """\\DeclareUnicodeCharacter for each character above Latin Extended-B in ``tex`` (a character
    with no entry in the table is shown as ?)."""
    wide = sorted({ch for ch in tex if ord(ch) > 0x24F})
    return "".join(rf"\DeclareUnicodeCharacter{{{ord(ch):04X}}}{{{_UNICODE.get(ch, '?')}}}" + "\n" for ch in wide)


def audit_tex(result: AuditResult) -> str:
    """The audit as a LaTeX document: the summary, one longtable line per method, every
    disagreement (and undecided claim with a reason) with its evidence, the bad and skipped files."""
    def cell(text: str) -> str:
        """Plain text, literal, with a line break allowed after each / (file paths)."""
        return "/\\allowbreak{}".join(latex_text(part) for part in text.split("/"))
    rows = []
    for r in result.rows:
        rows.append(" & ".join(cell(x) for x in (r.name, r.library, r.kind, r.numbers, str(r.stages), r.claims_text(),
                                                  r.found_text(), r.verdict_text(), f"{r.seconds:.2f}")) + r" \\")
    body = [r"\begin{document}", r"\begin{center}\Large Audit of tableau files\end{center}",
            cell(result.summary()) + ".", r"\par Decimal files are certified in ball arithmetic (a claim holds "
            r"\emph{to the stated precision}); exact files by the exact analyses.",
            r"{\scriptsize\setlength{\tabcolsep}{3pt}\begin{longtable}{p{2.6cm}p{1.6cm}llr p{3.2cm}p{2.2cm}p{1.8cm}r} "
            r"\toprule method & library & "
            r"kind & numbers & $s$ & claimed $\to$ found & found & verdict & s \\ \midrule \endhead",
            "\n".join(rows), r"\bottomrule \end{longtable}}"]
    evidence = result.with_evidence()
    if evidence:
        body.append(r"\section*{Evidence}\sloppy\begin{itemize}")
        body += [rf"\item \textbf{{{cell(r.name)}}} ({cell(r.file)}): {cell(c.prop)} claimed {cell(c.claimed)}, found "
                 rf"{cell(c.found or '?')}: {cell(c.verdict)}" + "".join(rf"\\ {cell(e)}" for e in c.evidence)
                 for r, c in evidence]
        body.append(r"\end{itemize}")
    if result.bad or result.skipped:
        body.append(r"\section*{Files not audited}\sloppy\begin{itemize}")
        body += [rf"\item bad: {cell(b.message)}" for b in result.bad]
        body += [rf"\item skipped: {cell(s.file)}: {cell(s.why)}" for s in result.skipped]
        body.append(r"\end{itemize}")
    body.append(r"\end{document}")
    text = "\n".join(body) + "\n"
    return PREAMBLE + _unicode_declarations(text) + text


def audit(paths, out=None, *, seconds: float = AUDIT_SECONDS, workers: int | None = None, scheduler: Any = None,
          progress: bool | None = None, pdf: bool | None = None) -> AuditResult:
    """The audit of ``paths`` (tableau files and folders searched for ``*.json``; ``tl.audit``,
    ``tableau-lab audit``): each method through the exact or the certified analyses within
    ``seconds``, every claim checked (:mod:`tableau_lab.experiments.audit`).  With ``out`` (a
    folder) the report files are written there (module docstring): ``pdf`` True requires
    pdflatex, None compiles when it is installed, False never.  The verdicts, the evidence and the
    outputs: docs/audit.md; the order conditions checked are those of [HNW93] II.2.

    >>> import tableau_lab as tl
    >>> r = tl.audit(["methods/rk4.json", "methods/gauss2.json"], workers=1)
    >>> [(row.name, row.verdict) for row in r.rows], r.exit_code
    ([('classical Runge–Kutta (RK4)', 'agrees'), ('Gauss–Legendre, 2 stages', 'agrees')], 0)
    """
    inputs = [str(p) for p in paths]
    targets = None
    if out is not None:
        targets = {name: Path(out) / name for name in AUDIT_FILES}
        refuse_outputs(list(targets.values()), inputs, what="audit report")      # before any work
    result = audit_files(inputs, seconds=seconds, workers=workers, scheduler=scheduler, progress=progress)
    if targets is not None:
        with output_phase(Path(out)):
            atomic_write_text(targets["audit.json"], json.dumps(result.to_json(), indent=1, ensure_ascii=False))
            atomic_write_text(targets["audit.md"], markdown_report(result))
            atomic_write_text(targets["audit.tex"], audit_tex(result))
        if pdf is not False:
            compile_pdf(targets["audit.tex"], required=bool(pdf))
    return result
