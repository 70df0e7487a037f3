"""A printed formula is a claim (issue 29, item 1): every modified equation, modified Hamiltonian,
error term and stability function the library's methods print — text, LaTeX, the notebook's
Markdown, JSON and the PDF report's .tex — is read back with the project's grammar
(tests/printed.py) and compared exactly with the series or polynomial it was printed from; each
term carries exactly one elementary differential.  On 5ea0488 a coefficient in ℚ(√3) lost its parentheses
(``+ 1/45 + sqrt(3)/72 f''(f, f''(f, f))``) and these comparisons fail."""
import re

import pytest
import sympy as sp
from printed import latex_to_grammar, read_latex_sum, read_text_sum, same

from tableau_lab.analysis.modified import modified_equation
from tableau_lab.analysis.modified_hamiltonian import modified_hamiltonian
from tableau_lab.exact.field import is_zero
from tableau_lab.exact.grammar import LIMITS, parse_entry, raise_limit
from tableau_lab.exact.library import library_names, library_path
from tableau_lab.exact.tableau_json import load

ORDER = 4                      # trees to order 4 (terms to h³): the whole library in about a second
NAMES = library_names()


@pytest.fixture(scope="module")
def equations():
    return {n: modified_equation(load(library_path(n)), ORDER) for n in NAMES}


def _expected(me) -> dict:
    """power of h -> {tree: b(t)/σ(t)} for the nonzero terms, from the series itself."""
    k, out = me.field.kind, {}
    for t, v in me.field.items():
        if v != 0:
            out.setdefault(k.order(t) - 1, {})[t] = v / k.symmetry(t)
    return out


def _groups(tex: str, head: str) -> list:
    r"""(power, body) of each ``h^{n}\left(body\right)`` in ``tex`` (balanced \left( … \right))."""
    out = []
    for m in re.finditer(re.escape(head) + r"(?:\^\{(\d+)\})?\\left\(", tex):
        depth, i = 1, m.end()
        while depth:
            nxt = min((j, s) for s in (r"\left(", r"\right)") if (j := tex.find(s, i)) >= 0)
            depth += 1 if nxt[1] == r"\left(" else -1
            i = nxt[0] + len(nxt[1])
        out.append((int(m[1] or 1), tex[m.end():i - len(r"\right)")]))
    return out


def test_the_readers_catch_the_old_misprint():
    """The readers themselves: 5ea0488's line for Example 4 is refused, the corrected one read."""
    vocab = {"f''(f, f)": "t1", "f'f": "t2"}
    with pytest.raises(AssertionError):
        read_text_sum("-1/2 f'f + 1/45 + sqrt(3)/72 f''(f, f)", vocab)
    with pytest.raises(AssertionError):
        read_text_sum("- sqrt(3)/72 - 1/45 f'f", vocab)
    c = sp.Rational(1, 45) + sp.sqrt(3) / 72
    assert not same(read_text_sum("-1/2 f'f + (1/45 + sqrt(3)/72) f''(f, f)", vocab), {"t1": c, "t2": -sp.S.Half})
    with pytest.raises(AssertionError):
        read_latex_sum(r"\frac{1}{45} + \frac{\sqrt{3}}{72}\, f''(f, f)", vocab)
    assert not same(read_latex_sum(r"- \left(\frac{1}{45} + \frac{\sqrt{3}}{72}\right)\, f'f", vocab), {"t2": -c})
    assert parse_entry(latex_to_grammar(r"\frac{2 \sqrt[3]{2}}{3} + \cos{\left(\frac{\pi}{18} \right)}^{2}")) == \
        2 * sp.cbrt(2) / 3 + sp.cos(sp.pi / 18) ** 2


@pytest.mark.parametrize("name", NAMES)
def test_modified_equation_text_latex_json_reparse_to_the_series(equations, name):
    me = equations[name]
    k, trees = me.field.kind, [t for t, _ in me.field.items()]
    vocab = {k.differential(t): t for t in trees}
    tex_vocab = {k.differential(t, tex=True): t for t in trees}
    assert len(vocab) == len(tex_vocab) == len(trees)                  # one printed form per tree
    expected = _expected(me)
    lines = str(me).splitlines()[1:]
    found = {0: read_text_sum(lines[0].split(" = ", 1)[1], vocab)}
    for line in lines[1:]:
        m = re.fullmatch(r"\s+\+ h(?:\^(\d+))?\s*\( (.*) \)", line)
        assert m, line
        found[int(m[1] or 1)] = read_text_sum(m[2], vocab)
    assert found.keys() == expected.keys() | {0}, (name, found.keys())
    for n in found:
        assert not same(found[n], expected.get(n, {})), (name, n)
    tex = me.to_latex()
    zeroth = tex.split(" = ", 1)[1].split(r" \\ &\quad + ", 1)[0]
    assert not same(read_latex_sum(zeroth, tex_vocab) if zeroth != "0" else {}, expected.get(0, {})), name
    math = re.search(r"\$\$(.*)\$\$", me._repr_markdown_(), re.S)[1]      # the notebook's Markdown
    for shown in (tex, math):
        groups = _groups(shown, "h")
        assert {n for n, _ in groups} == expected.keys() - {0}
        for n, body in groups:
            assert not same(read_latex_sum(body, tex_vocab), expected[n]), (name, n)
    terms = me.to_json()["terms"]
    assert len(terms) == sum(map(len, expected.values()))
    for term in terms:
        t = vocab[term["differential"]]
        assert is_zero(parse_entry(term["coefficient"]) - expected[term["h_power"]][t])


@pytest.mark.parametrize("name", NAMES)
def test_modified_hamiltonian_text_and_latex_reparse_to_beta(equations, name):
    mh = modified_hamiltonian(equations[name].field)
    k = mh.kind
    vocab = {f"H({k.bracket(key)})": key for key in mh.beta}
    tex_vocab = {f"H({k.tex(key)})": key for key in mh.beta}
    expected = {n: dict(mh.terms(n)) for n in range(2, mh.order + 1) if mh.terms(n)}
    found = {}
    for line in str(mh).splitlines()[1:]:
        m = re.fullmatch(r"  h\^(\d+): (.*)", line)
        assert m, line
        found[int(m[1]) + 1] = read_text_sum(m[2], vocab)
    assert found.keys() == expected.keys()
    assert all(not same(found[n], expected[n]) for n in found), name
    groups = _groups(mh.to_latex(), "h")
    assert {n + 1 for n, _ in groups} == expected.keys()
    for n, body in groups:
        assert not same(read_latex_sum(body, tex_vocab), expected[n + 1]), (name, n)


@pytest.mark.parametrize("name", NAMES)
def test_error_terms_reparse(name, monkeypatch):
    from tableau_lab.analysis.order import order
    monkeypatch.setitem(LIMITS, "integer_digits", LIMITS["integer_digits"])   # restored after the test
    raise_limit("integer_digits", 1000)          # glm6_moonshot's error terms have 277-digit numerators
    r = order(load(library_path(name)))
    values = getattr(r, "error_coefficients", None) or getattr(r, "errors", None) or {}
    values = {str(t): v for t, v in values.items()}
    shown = [line.split(": ", 1)[1] for line in str(r).splitlines()
             if re.match(r"  (principal error coefficients|error terms at order)", line)]
    assert bool(shown) == any(v != 0 for v in values.values()), name
    for line in shown:
        for item in re.sub(r" … \(\d+ trees\)$| \(the first nonzero one.*$", "", line).split("; "):
            tree, value = item.rsplit(": ", 1)
            assert is_zero(parse_entry(value) - values[tree]), (name, tree)


# the stability analysis of these takes seconds to minutes (large number fields): not here
SLOW_STABILITY = {"glm6_moonshot", "glm4_symmetric", "glm43_printed", "glm43"}


def _zero_rational_function(e) -> bool:
    num = sp.together(e).as_numer_denom()[0]
    return all(is_zero(c) for c in sp.Poly(sp.expand(num), *sorted(num.free_symbols, key=str)).coeffs()) \
        if num.free_symbols else is_zero(num)


@pytest.mark.parametrize("name", [n for n in NAMES if n not in SLOW_STABILITY])
def test_stability_function_and_polynomial_reparse(name):
    from tableau_lab.analysis.stability import stability
    r = stability(load(library_path(name)))
    real = {s: sp.Symbol(s.name, real=True) for s in r.polynomial.free_symbols}
    printed = {m[1]: m[2] for m in re.finditer(r"^  (P\(w, [zx]\)|R\(z\)) = (.*)$", str(r), re.M)}
    assert _zero_rational_function(parse_entry(printed[f"P(w, {r.variable})"]) - r.polynomial.xreplace(real)), name
    assert ("R(z)" in printed) == (r.kind == "rk")
    if r.kind == "rk":
        R = r.stability_function.xreplace(real)
        assert _zero_rational_function(parse_entry(printed["R(z)"]) - R), name
        tex = re.search(r"R\(z\) = (.*?), \\qquad", r.to_latex())[1]
        assert _zero_rational_function(parse_entry(latex_to_grammar(tex)).xreplace(real) - R), name
        json_r = r.to_json()["stability_function"]
        assert _zero_rational_function(parse_entry(json_r["R"]) - R)
        assert _zero_rational_function(parse_entry(json_r["N"]) / parse_entry(json_r["D"]) - R)


def _section(tex: str, lhs: str) -> str:
    r"""The body of ``lhs &= … + h^{k}\bigl(body\bigr) + O(h^{k+1})`` in a report's .tex."""
    m = re.search(re.escape(lhs) + r" &= [^\n]*?h\^\{(\d+)\}\\bigl\((.*?)\\bigr\) \+ O\(h\^\{\d+\}\)", tex)
    assert m, lhs
    return int(m[1]), m[2]


@pytest.mark.parametrize("name", ["example4_glm", "glm43"])
def test_modified_command_of_example4_and_glm43(name, capsys):
    """Issue 29's case: ``modified --order 5`` of Example 4 (coefficients in ℚ(√3)) and GLM43: each
    term has exactly one elementary differential, and the coefficients are the series'.  Their
    reports' .tex is read the same way by :func:`check_report_tex` (called from test_report.py,
    whose tests build those two reports already)."""
    from tableau_lab.cli import main
    path = str(library_path(name))
    assert main(["modified", path, "--order", "5"]) == 0
    out = capsys.readouterr().out
    me = modified_equation(load(path), 5)
    k, trees = me.field.kind, [t for t, _ in me.field.items()]
    expected = _expected(me)
    assert set(expected) == {0, 4}                   # order 4: f, then the h⁴ terms
    line = next(x for x in out.splitlines() if x.lstrip().startswith("+ h^4"))
    h4 = read_text_sum(re.fullmatch(r"\s+\+ h\^4\s*\( (.*) \)", line)[1], {k.differential(t): t for t in trees})
    assert not same(h4, expected[4])
    if name == "example4_glm":                       # the coefficients of issue 29: ±(1/45 + √3/72)
        c = sp.Rational(1, 45) + sp.sqrt(3) / 72
        assert sum(1 for v in expected[4].values() if is_zero(v - c) or is_zero(v + c)) == 4


def check_report_tex(tex: str, name: str) -> None:
    """The backward-error section of a method's report (.tex, as ``report`` writes it): the leading
    terms of the modified equation and of the modified energy, read back, are the series'."""
    me = modified_equation(load(library_path(name)), 5)
    k, trees = me.field.kind, [t for t, _ in me.field.items()]
    power, body = _section(tex, r"\tilde f")
    assert power == 4
    assert not same(read_latex_sum(body, {k.differential(t, tex=True): t for t in trees}), _expected(me)[4])
    mh = modified_hamiltonian(me.field)
    power, body = _section(tex, r"\tilde H")
    assert power == 4
    assert not same(read_latex_sum(body, {f"H({mh.kind.tex(key)})": key for key in mh.beta}), dict(mh.terms(5)))


@pytest.mark.parametrize("name", ["stormer_verlet", "symplectic_euler", "lobatto_iiia3"])
def test_structure_of_a_partitioned_method_prints_the_equation_and_what_does_not_apply(name, capsys):
    """Issue 29, item 5: ``modified --structure`` on a partitioned method exited 2 ("the structure
    checks are written for B-series"); now the modified equation, then the modified energy's
    order — symplectic PRK methods have one to every order ([HLW06] IX.3, Thm 3.1) — and the
    checks that do not apply (an RK method keeps its B-series checks)."""
    from tableau_lab.cli import main
    assert main(["modified", str(library_path(name)), "--order", "4", "--structure"]) == 0
    out = capsys.readouterr().out
    assert "modified equation, trees to order 4" in out
    if name == "lobatto_iiia3":
        assert "symplectic            to order" in out and "P-series" not in out
    else:
        assert "modified energy (H-series over bicoloured free trees) to order ≥ 4 (budget)" in out
        assert "not checked: symplectic, conjugate-symplectic, symmetric, energy-preserving" in out


def test_a_partitioned_method_without_modified_energy_is_told_apart():
    """Explicit Euler in both partitions has no modified energy beyond the first order: its h-term
    −½ f′f has b([τ]) = −1/2, and a Hamiltonian field needs b(u∘v) + b(v∘u) = 0, here 2b([τ]) = 0
    ([HLW06] IX.9.3), so the conditions fail at order 2."""
    from tableau_lab.analysis.method_series import method_series
    from tableau_lab.analysis.series_structure import structure
    from tableau_lab.exact.methods import PartitionedRungeKutta
    euler = PartitionedRungeKutta.from_lists([[0]], [1], [[0]], [1], name="Euler, both parts")
    s = structure(method_series(euler, 4).phi)
    assert s.energy == 1 and "the conditions fail at order 2" in str(s)
    assert s.to_json()["not_checked"] == ["symplectic", "conjugate-symplectic", "symmetric", "energy-preserving"]


def test_every_file_a_method_source_names_is_in_the_repository():
    """Issue 29, item 10: a method's ``source`` (printed in the report's Source section and the
    notebook repr) named a developer's path, ``shared/seed/…txt``, that is not in the repository;
    a source is a citation, and a file it names is one a user has."""
    import json
    from pathlib import Path
    root = Path(__file__).resolve().parents[1]
    for path in sorted((root / "methods").rglob("*.json")):
        source = json.loads(path.read_text()).get("source", "")      # design files need not load
        for named in re.findall(r"[\w.-]+(?:/[\w.-]+)+\.\w+", source):
            assert (root / named).is_file(), (path.name, named)


@pytest.mark.parametrize("name", NAMES)
def test_method_series_latex_reparses(name):
    """The B-/P-series Φ(t) table in LaTeX (the notebook display): each value, read back, is Φ(t)
    (on 5ea0488 it held grammar text, sqrt(3)/6, which LaTeX reads as s·q·r·t·3/6)."""
    from tableau_lab.analysis.method_series import method_series
    ms = method_series(load(library_path(name)), 3)
    k = ms.phi.kind
    trees = {k.tex(t): t for t, _ in ms.phi.items()}
    body = re.fullmatch(r"\\begin\{array\}\{c\|c\} t & \\Phi\(t\) \\\\ \\hline (.*) \\end\{array\}",
                        ms.to_latex(), re.S)[1]
    rows = [r.strip() for r in body.split(r" \\") if r.strip()]
    assert len(rows) == len(trees)
    for row in rows:
        tree, value = row.split(" & ")
        assert is_zero(parse_entry(latex_to_grammar(value)) - ms.phi[trees[tree]]), (name, row)
