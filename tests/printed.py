r"""Readers of printed formulas for the tests: a printed sum Σ c·T (text in the tableau grammar, or
LaTeX as sympy typesets exact numbers) back to {term: exact coefficient}, with the project's own
grammar (:func:`tableau_lab.exact.grammar.parse_entry`).

The terms T are a known vocabulary (the elementary differentials F(t) or H(t) of the trees of a
series, as the analyses write them); each is replaced by a name ``Dk`` (longest match first), a
space between a coefficient and its term becomes ``*``, and the whole line is parsed.  The
result must be linear in the names with no constant part: a coefficient that is a sum printed
without parentheses leaves a constant (``1/45 + sqrt(3)/72 D3``), two terms in one leave a
product — both are caught by :func:`linear_form`.  LaTeX is first translated to the grammar by
:func:`latex_to_grammar`, which knows the few commands sympy uses for algebraic numbers."""
import re

import sympy as sp

from tableau_lab.exact.field import is_zero
from tableau_lab.exact.grammar import parse_entry


def _placeholders(text: str, vocab: dict, starts: str) -> str:
    """``text`` with every vocabulary word (longest first) that begins after one of ``starts``
    (or at the start) replaced by `` Dk ``, k its index in ``vocab``."""
    words = sorted(vocab, key=len, reverse=True)
    index = {w: i for i, w in enumerate(vocab)}
    out, i = [], 0
    while i < len(text):
        if i == 0 or text[i - 1] in starts:
            w = next((w for w in words if text.startswith(w, i)), None)
            if w is not None:
                out.append(f" D{index[w]} ")
                i += len(w)
                continue
        out.append(text[i])
        i += 1
    return "".join(out)


def linear_form(grammar_text: str, keys: list, constants: dict | None = None) -> dict:
    """{key: coefficient} of a parsed sum of ``Dk`` names (``constants``: other names -> values);
    AssertionError when a part has no name or more than one (a term without its differential,
    or two in one)."""
    e = parse_entry(grammar_text)
    e = sp.expand(e.xreplace({sp.Symbol(k, real=True): v for k, v in (constants or {}).items()}))
    names = {sp.Symbol(f"D{i}", real=True): k for i, k in enumerate(keys)}
    out: dict = {}
    for part in sp.Add.make_args(e):
        held = [s for s in part.free_symbols if s in names]
        assert len(held) == 1, f"a term with {len(held)} differentials: {part} in {grammar_text!r}"
        coeff, rest = part.as_independent(held[0])
        assert rest == held[0], f"not linear in {held[0]}: {part}"
        out[names[held[0]]] = out.get(names[held[0]], 0) + coeff
    return out


def read_text_sum(body: str, vocab: dict) -> dict:
    """A printed text sum (``-1/2 f'f + (1/45 + sqrt(3)/72) f''(f, f)``) as {key: coefficient};
    ``vocab``: printed term -> key."""
    marked = _placeholders(body, vocab, " (")
    marked = re.sub(r"(?<=[0-9A-Za-z)])\s+(?=D\d+\b)", "*", marked.strip())
    return linear_form(marked, list(vocab.values()))


_TOKEN = re.compile(r"\\[A-Za-z]+|\\.|[0-9]+|[A-Za-z]|\S")


class _LatexReader:
    """A recursive-descent reader of sympy's LaTeX (:func:`latex_to_grammar`): ``seq`` reads up to a
    closing token, ``atom`` one operand, ``command`` one backslash command."""

    def __init__(self, tex: str):
        self.tex = tex
        self.toks = _TOKEN.findall(tex) + ["\0"]
        self.pos = 0

    def peek(self) -> str:
        return self.toks[self.pos]

    def take(self) -> str:
        self.pos += 1
        return self.toks[self.pos - 1]

    def group(self) -> str:
        t = self.take()
        return "(" + self.seq("}") + ")" if t == "{" else self.atom(t)

    def atom(self, t: str) -> str:
        if t.isdigit():
            return t
        if t in ("(", r"\left", r"\bigl"):
            if t != "(":
                assert self.take() in "(["
            return "(" + self.seq(")") + ")"
        if t == "{":
            return "(" + self.seq("}") + ")"
        if t.startswith("\\"):
            return self.command(t)
        if re.fullmatch(r"[A-Za-z]", t):
            name = t
            while self.pos < len(self.toks) and re.fullmatch(r"[A-Za-z0-9]+", self.peek()):
                name += self.take()
            return name
        raise AssertionError(f"unexpected {t!r} in {self.tex!r}")

    def command(self, t: str) -> str:
        if t == r"\frac":
            return f"(({self.group()})/({self.group()}))"
        if t == r"\sqrt":
            if self.peek() == "[":
                self.take()
                n = self.seq("]")
                return f"(({self.group()})^(1/({n})))"
            return f"sqrt({self.group()})"
        if t in (r"\cos", r"\sin"):                   # \cos^{2}{\left(…\right)} is cos(…)^2
            power = self.take() and self.group() if self.peek() == "^" else None
            call = t[1:] + self.group()
            return call if power is None else f"({call})^{power}"
        if t == r"\pi":
            return "pi"
        if t == r"\operatorname":                    # \operatorname{root}\left(P, k\right): the grammar's root(P, k)
            name = self.group().strip("()")
            return name + self.atom(self.take())
        if t == r"\kappa":
            assert self.take() == "_"
            return "kappa" + self.group().strip("()")
        raise AssertionError(f"unexpected {t!r} in {self.tex!r}")

    def seq(self, stop: str) -> str:
        out, operand = [], False
        while True:
            assert self.pos < len(self.toks), f"unclosed in {self.tex!r}"
            t = self.take()
            if t == stop or (t in (r"\right", r"\bigr") and stop == ")"):
                if t != stop:
                    self.take()
                return "".join(out)
            if t in (r"\,", r"\ ", r"\;"):
                continue
            if t == ",":                              # between the arguments of root(P, k)
                out.append(", ")
                operand = False
                continue
            if t in "+-/":
                out.append(f" {t} ")
                operand = False
            elif t == r"\cdot":
                out.append("*")
                operand = False
            elif t == "^":
                out.append("^" + self.group())
                operand = True
            else:
                out.append(("*" if operand else "") + self.atom(t))
                operand = True


def latex_to_grammar(tex: str) -> str:
    r"""sympy's LaTeX of an exact expression (``\frac``, ``\sqrt[n]``, ``\left(``, ``^{}``,
    ``\cos``, ``\pi``, juxtaposition) as text in the tableau grammar; ``\kappa_{n}`` -> kappan."""
    return _LatexReader(tex).seq("\0")


def read_latex_sum(body: str, vocab: dict, constants: dict | None = None) -> dict:
    """A LaTeX sum (``- \\frac{1}{2}\\, f'f + \\left(\\frac{1}{45} + …\\right)\\, f''(f, f)``) as
    {key: coefficient}; ``constants``: \\kappa names (kappa1, …) -> exact values (the report's)."""
    assert r"\dots" not in body, "a sum cut short cannot be compared"
    body = body.replace(r"\\ &\qquad", " ")
    return linear_form(latex_to_grammar(_placeholders(body, vocab, " ({")), list(vocab.values()), constants)


def same(found: dict, expected: dict) -> list:
    """The keys where two {key: exact value} maps differ (missing keys count as 0)."""
    return [k for k in set(found) | set(expected) if not is_zero(sp.sympify(found.get(k, 0) - expected.get(k, 0)))]
