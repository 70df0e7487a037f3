"""Issue 19, item 5: docs/seed_figures.md's summary table quotes the saved scene runs
(reports/<scene>/meta.json, ``max_invariant_error``).  Each measured number of the table's
"our run" column (decimals and powers of ten; integers there are names: Gauss2, GLM43, 3/8) is
compared with the run and invariant it describes, to its quoted digits (benchmarks/docs_check.py's
rule), so the page cannot drift from the data — and a scene rerun that changes a value fails here
until the page is updated.

The prose below the table ("Notes per figure", "Runner observations", the "Wall time" paragraph)
is checked the same way, sentence by sentence (second half of this file): its numbers are read
from the page and compared with the saved runs (data.npz: the recorded error series, states and
parasitic components; meta.json), with closed forms computed here, or with the package's exact
analyses (``tableau-lab verify``)."""
import json
import math
import re
import sys
from fractions import Fraction
from functools import cache
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from conftest import benchmark_script

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "seed_figures.md"
MEASURED = re.compile(r"(?<![\w.])−?\d*\.\d+(?:e[-−]?\d+)?|(?<![\w.])−?\d+e[-−]?\d+")
# per table row (its Fig cell): what each measured number of the "our run" cell is, in order:
# (scene, run index, invariant), or None for a number that is not a saved maximum (|H0|, say)
ROWS = {
    "2.1": [("fig2_01_kepler_euler", 0, "H"), ("fig2_01_kepler_euler", 0, "L")],
    "2.2": [("fig2_01_kepler_euler", 1, "H"), ("fig2_01_kepler_euler", 1, "L")],
    "2.3": [("fig2_03_harmonic_rk", 0, "H")],
    "2.4": [("fig2_03_harmonic_rk", 1, "H"), ("fig2_03_harmonic_rk", 2, "H")],
    "2.5": [("fig2_05_glm_pendulum", 1, "H"), ("fig2_05_glm_pendulum", 0, "H")],
    "3.1/3.2": [("fig3_01_euler_pendulum", 0, "H"), ("fig3_01_euler_pendulum", 1, "H")],
    "3.3/3.4": [("fig3_03_glm_pendulum", k, "H") for k in range(4)],
    "3.5/3.6": [("fig3_05_euler_harmonic", 0, "H"), ("fig3_05_euler_harmonic", 1, "H")],
    "3.7/3.8": [("fig3_07_rk_harmonic", 0, "H"), ("fig3_07_rk_harmonic", 1, "H")],
    "3.9/3.10": [("fig3_09_srk_harmonic", 0, "H"), ("fig3_09_srk_harmonic", 1, "H")],
    "3.11": [("fig3_11_euler_kepler", 0, "H"), None],
    "3.12": [("fig3_11_euler_kepler", 1, "H"), ("fig3_11_euler_kepler", 1, "L")],
    "3.13": [("fig3_11_euler_kepler", 2, "H"), ("fig3_11_euler_kepler", 2, "L")],
    "3.14": [("fig3_14_sympl_kepler", 0, "H"), ("fig3_14_sympl_kepler", 0, "L")],
    "3.15": [("fig3_14_sympl_kepler", 1, "H"), ("fig3_14_sympl_kepler", 1, "L")],
    "3.16": [("fig3_14_sympl_kepler", 2, "H"), ("fig3_14_sympl_kepler", 2, "L")],
    "3.17": [("fig3_17_glm43_kepler", 0, "H"), ("fig3_17_glm43_kepler", 0, "L"),
             ("fig3_17_glm43_kepler", 3, "H"), ("fig3_17_glm43_kepler", 3, "L")],
    "3.18": [("fig3_17_glm43_kepler", 1, "H"), ("fig3_18_glm43_kepler_long", 0, "H")],
    "3.19": [("fig3_17_glm43_kepler", 2, "H"), ("fig3_17_glm43_kepler", 2, "L")],
}


def _table() -> dict:
    rows = {}
    for line in DOC.read_text().splitlines():
        cells = [c.strip() for c in line.replace("\\|", "¦").strip().strip("|").split("|")]
        if len(cells) == 5 and re.fullmatch(r"[23]\.\d+(/[23]\.\d+)?", cells[0]):
            rows[cells[0]] = cells[3]
    return rows


def _saved(scene, run, invariant) -> float:
    meta = json.loads((ROOT / "reports" / scene / "meta.json").read_text())
    return meta["runs"][run]["max_invariant_error"][invariant]


def test_the_table_has_every_row():
    assert set(_table()) == set(ROWS)


@pytest.mark.parametrize("fig", sorted(ROWS))
def test_table_numbers_are_the_saved_runs(fig):
    same = benchmark_script("docs_check").same_number
    quoted = [m.group().replace("−", "-").lstrip("-") for m in MEASURED.finditer(_table()[fig])]
    assert len(quoted) == len(ROWS[fig]), (fig, quoted)
    for q, where in zip(quoted, ROWS[fig], strict=False):
        if where is not None:
            assert same(q, repr(_saved(*where))), f"Fig {fig}: the page says {q}, {where} saved {_saved(*where):.3g}"


# ---------------------------------------------------------------------------------------------
# The prose: "Notes per figure", "Runner observations" and the "Wall time" paragraph.  Each test
# finds its sentence by the words around the numbers (a template, "#" for a quoted number, "§" for
# a superscript integer; whitespace matches any line break), reads the numbers from the page and
# compares them with the saved runs (reports/<scene>/data.npz, meta.json), a closed form computed
# here, or the package's exact analyses (tableau_lab.analysis.verify, as `tableau-lab verify`).
# ---------------------------------------------------------------------------------------------
TOKEN = r"(−?(?:\d(?:[\d.,/]*\d)?(?:e[-−]?\d+)?|[½¼]))"
SUPERSCRIPT = "⁻⁰¹²³⁴⁵⁶⁷⁸⁹"
ABOUT = 0.05                 # "t ≈ 20", "about −39": within 5 % of the quoted value
ORDER_ONE = (0.1, 10.0)      # "O(1)": between a tenth and ten
NO_DRIFT = 0.01              # "no drift": every 10-unit window's max |error| within 1 % of the first one's
Q_TOL = 1e-6                 # "|q| ≤ π/3": the recorded states' excess over the exact bound (method error)
CLOSED_FORM_RTOL = 1e-3      # a closed form against a float64 run that it describes exactly
ONE_DIGIT_FACTOR = 3.0       # a one-digit quote ("1e-5") is also within this factor of the value
                             # (same_number alone lets "1e-5" stand for anything in (0, 3e-5])
WORDS = {"seven": 7, "eight": 8, "nine": 9, "ten": 10, "eleven": 11}


def _page() -> str:
    return DOC.read_text()


def _quotes(template: str) -> list:
    """The numbers the page quotes at ``template`` (which must occur exactly once), as strings with
    an ASCII minus, no thousands commas, ½ as 1/2; superscript integers as ints."""
    rx = ""
    for part in re.split(r"([#§])", template):
        if part == "#":
            rx += TOKEN
        elif part == "§":
            rx += f"([{SUPERSCRIPT}]+)"
        else:
            rx += r"\s+".join(re.escape(w) for w in re.split(r"\s+", part))
    found = list(re.finditer(rx, _page()))
    assert len(found) == 1, f"{template!r} occurs {len(found)} times in {DOC.name}"
    out = []
    for g in found[0].groups():
        if g[0] in SUPERSCRIPT:
            out.append(int(g.translate(str.maketrans(SUPERSCRIPT, "-0123456789"))))
        else:
            out.append(g.replace("−", "-").replace(",", "").replace("½", "1/2").replace("¼", "1/4"))
    return out


def _value(q: str):
    return Fraction(q) if "/" in q or re.fullmatch(r"-?\d+(\.\d+)?", q) else float(q)


@cache
def _docs_check():
    return benchmark_script("docs_check")


def _agree(quoted: str, actual, what: str):
    """``quoted`` is ``actual`` to its quoted digits (docs_check.same_number)."""
    same = _docs_check().same_number
    a = float(actual)
    # an integer (a count, an exact bound) must be met to round-off, not to ±2 units
    ok = same(quoted, repr(a)) if not re.fullmatch(r"-?\d+", quoted) else math.isclose(a, int(quoted), rel_tol=1e-9)
    q = float(quoted)
    if ok and len(re.sub(r"e.*|[-.]", "", quoted).strip("0")) == 1 and abs(q) >= _docs_check().ROUNDOFF:
        ok = q * a > 0 and 1 / ONE_DIGIT_FACTOR <= a / q <= ONE_DIGIT_FACTOR
    assert ok, f"{what}: the page says {quoted}, the data give {a:.6g}"


def _closed(quoted: str, exact: float, what: str):
    """A closed form's value to its quoted digits, however small (same_number's round-off
    leniency is for measured round-off, not for a formula)."""
    mantissa, _, exponent = quoted.partition("e")
    scale = 10.0 ** int(exponent or 0)
    _agree(mantissa, exact / scale, f"{what} (× 10^{int(exponent or 0)})")


def _about(quoted: str, actual, what: str):
    q, a = float(_value(quoted)), float(actual)
    assert abs(a - q) <= ABOUT * abs(q), f"{what}: the page says about {quoted}, the data give {a:.6g}"


@cache
def _meta(scene: str) -> dict:
    return json.loads((ROOT / "reports" / scene / "meta.json").read_text())


@cache
def _data(scene: str) -> dict:
    with np.load(ROOT / "reports" / scene / "data.npz") as z:
        return {k: z[k] for k in z.files}


def _at(scene: str, run: int, series: str, t) -> float:
    """The recorded value of ``run<i>_<series>`` at time t (a recorded time)."""
    d = _data(scene)
    k = np.flatnonzero(np.isclose(d[f"run{run}_t"], float(t), rtol=0, atol=1e-9))
    assert len(k) == 1, f"{scene}: t = {t} is not a recorded time"
    return float(d[f"run{run}_{series}"][k[0]])


def _max_error(scene: str, run: int, invariant: str) -> float:
    return _meta(scene)["runs"][run]["max_invariant_error"][invariant]


def _span(scene: str) -> Fraction:
    m = _meta(scene)
    return m["steps"] * Fraction(m["h"])


def _H0(scene: str, run: int = 0) -> float:
    """The problem's Hamiltonian (with the run's parameters) at the recorded initial state."""
    from tableau_lab.numeric.problems import get_problem
    m = _meta(scene)
    prob = get_problem(m["problem"], **m["parameters"])
    y0 = _data(scene)[f"run{run}_y"][0]
    H = prob.hamiltonian.subs({prob.parameter_symbols[k]: v for k, v in prob.parameters.items()})
    return float(H.subs(dict(zip(prob.state, (sp.Float(float(x), 30) for x in y0), strict=False))))


@cache
def _verify(name: str):
    from tableau_lab.analysis.verify import verify
    from tableau_lab.exact.tableau_json import load
    return verify(load(ROOT / "methods" / f"{name}.json"))


def _scene_parameters(scene: str, **quoted):
    m = _meta(scene)
    for key, q in quoted.items():
        saved = _span(scene) if key == "T" else Fraction(m["h"]) if key == "h" else Fraction(m["parameters"][key])
        assert _value(q) == saved, f"{scene}: the page says {key} = {q}, the scene has {saved}"


# --- 2.1–2.2 -----------------------------------------------------------------------------------
KEPLER_E0 = "fig2_01_kepler_euler"


def test_kepler_e0_parameters():
    e, h = _quotes("**2.1–2.2** (seed: e = #, h = #)")
    _scene_parameters(KEPLER_E0, e=e, h=h)


def test_explicit_euler_energy_grows_monotonically():
    v1, t1, v2, t2 = _quotes("grows monotonically (# at t = #, # at t = #)")
    for v, t in ((v1, t1), (v2, t2)):
        _agree(v, _at(KEPLER_E0, 0, "H", t), f"explicit Euler ΔH(t = {t})")
    assert np.all(np.diff(_data(KEPLER_E0)["run0_H"]) >= 0), "explicit Euler's H error is not monotone"


def test_symplectic_euler_energy_band_in_every_window():
    lo, hi, width = _quotes("oscillates in [#, #], and the band is the same in each #-unit window")
    d = _data(KEPLER_E0)
    t, H = d["run1_t"], d["run1_H"]
    _agree(lo, H.min(), "symplectic Euler min ΔH")
    _agree(hi, H.max(), "symplectic Euler max ΔH")
    w = float(width)
    windows = round(t[-1] / w)
    assert windows >= 2 and windows * w == t[-1], f"{width}-unit windows do not tile [0, {t[-1]:g}]"
    for k in range(windows):
        sel = (t >= k * w) & (t <= (k + 1) * w)
        _agree(lo, H[sel].min(), f"symplectic Euler min ΔH over [{k * w:g}, {(k + 1) * w:g}]")
        _agree(hi, H[sel].max(), f"symplectic Euler max ΔH over [{k * w:g}, {(k + 1) * w:g}]")


def test_symplectic_euler_keeps_L():
    (q,) = _quotes("conserves the quadratic invariant L exactly (#)")
    _agree(q, _max_error(KEPLER_E0, 1, "L"), "symplectic Euler max |ΔL|")


# --- 2.3–2.4, 3.7–3.10, 3.5: closed forms ------------------------------------------------------
RK_SCENES = ("fig2_03_harmonic_rk", "fig3_07_rk_harmonic")      # run 0: the 3/8 rule, 50,000 steps


def test_order4_rk_energy_factor_closed_form():
    """|R(ih)|² of the 3/8 rule (the explicit RK run), from its tableau: R(z) = 1 + z bᵀ(I − zA)⁻¹1."""
    p, den, rest = _quotes("|R(ih)|² = 1 − h§/# + O(h§)")
    from tableau_lab.exact.tableau_json import load
    m = load(ROOT / "methods" / "rule_3_8.json")
    z, h = sp.symbols("z h")
    R = sp.expand(sp.simplify(1 + z * (m.b.T * (sp.eye(m.A.shape[0]) - z * m.A).inv() * sp.ones(m.A.shape[0], 1))[0]))
    poly = sp.Poly(sp.expand(R.subs(z, sp.I * h) * R.subs(z, -sp.I * h)), h)
    c = {k[0]: v for k, v in zip(poly.monoms(), poly.coeffs(), strict=False)}
    nonzero = sorted(k for k, v in c.items() if k > 0 and v != 0)
    assert c[0] == 1 and nonzero[:2] == [p, rest], f"|R(ih)|² − 1 has powers {nonzero}"
    assert c[p] == -Fraction(den) ** -1, f"coefficient of h^{p}: {c[p]}, the page says −1/{den}"


def test_order4_rk_energy_loss_per_step_and_total():
    H0, h6, den, per_step, steps, total = _quotes("ΔH per step is −#·10§/# = #. Over # steps that gives #")
    rk = _meta("fig2_03_harmonic_rk")["runs"][0]["file"]
    for scene in RK_SCENES:
        m = _meta(scene)
        assert m["runs"][0]["file"] == rk and "3_8" in rk, f"{scene} run 0 is not the 3/8 rule"
        h = Fraction(m["h"])
        assert _value(H0) == Fraction(_H0(scene)) and Fraction(10) ** h6 == h ** 6, (scene, H0, h6)
        assert int(steps) == m["steps"], f"{scene}: {m['steps']} steps, the page says {steps}"
        closed = -_H0(scene) * float(h) ** 6 / float(den)
        _closed(per_step, closed, f"{scene}: −H0 h⁶/{den}")
        _agree(total, closed * m["steps"], f"{scene}: {steps} × −H0 h⁶/{den}")
        _agree(total, _data(scene)["run0_H"][-1], f"{scene}: the 3/8 rule's final ΔH")
        _agree(total.lstrip("-"), _max_error(scene, 0, "H"), f"{scene}: the 3/8 rule's max |ΔH|")


def test_order4_rk_drift_orders_of_magnitude_below_H():
    (word,) = re.findall(r"the effect is (\w+) orders of magnitude below H", _page())
    scene = RK_SCENES[0]
    orders = math.log10(_H0(scene) / _max_error(scene, 0, "H"))
    assert WORDS[word] == round(orders), f"the page says {word}, H0/|ΔH| is 10^{orders:.2f}"


def test_explicit_euler_harmonic_closed_form():
    half, T, exponent, value = _quotes("H_n = #(1+h²)ⁿ, so ΔH(T=#) = ½(e^{#} − 1) = #, as measured")
    scene = "fig3_05_euler_harmonic"
    _scene_parameters(scene, T=T)
    m = _meta(scene)
    h, n = float(Fraction(m["h"])), m["steps"]
    assert _value(half) == Fraction(_H0(scene)), f"H0 = {_H0(scene)}, the page says {half}"
    _agree(exponent, n * math.log1p(h * h), "n ln(1 + h²)")
    _agree(value, 0.5 * math.expm1(n * math.log1p(h * h)), "½(e^{n ln(1+h²)} − 1)")
    _agree(value, _max_error(scene, 0, "H"), "explicit Euler's max |ΔH| (Fig 3.5)")
    d = _data(scene)
    steps = np.rint(d["run0_t"] / h)
    closed = _H0(scene) * np.expm1(steps * np.log1p(h * h))
    assert np.allclose(d["run0_H"], closed, rtol=CLOSED_FORM_RTOL, atol=0), "H_n − H_0 ≠ H_0((1+h²)ⁿ − 1)"


# --- 2.5 ---------------------------------------------------------------------------------------
PENDULUM = "fig2_05_glm_pendulum"     # run 0 Example 4, run 1 GLM43 repaired
MP32 = "fig2_05_example4_mp32"        # run 0 float64, run 1 32 digits


def test_glm_pendulum_start_and_glm43_bound():
    q0, p0, bound = _quotes("With q0 = # and p0 = #, GLM43 (repaired) keeps |ΔH| ≤ #")
    y0 = _data(PENDULUM)["run1_y"][0]
    assert (float(q0), float(p0)) == tuple(y0), f"the runs start at {y0}"
    saved = _max_error(PENDULUM, 1, "H")
    assert saved <= float(bound)
    _agree(bound, saved, "GLM43's max |ΔH| on the pendulum")


def test_example4_departs_then_parasitic_blow_up():
    t_quoted, start, reaches = _quotes("tracks it until t ≈ #, then its parasitic component grows from # to O(1) "
                                       "and ΔH reaches #")
    d = _data(PENDULUM)
    t, ex4 = d["run0_t"], np.abs(d["run0_H"])
    departs = t[np.argmax(ex4 > _max_error(PENDULUM, 1, "H"))]      # first record beyond GLM43's whole-run max
    _about(t_quoted, departs, "Example 4 leaves GLM43's |ΔH| band at t")
    (mode,) = _meta(PENDULUM)["runs"][0]["parasitic_modes"]
    c = d["run0_parasitic_0"]
    _agree(start, _at(PENDULUM, 0, "parasitic_0", t_quoted), f"Example 4's parasitic component (ζ = {mode['zeta']}) "
                                                            f"at t = {t_quoted}")
    assert ORDER_ONE[0] <= c.max() <= ORDER_ONE[1] and mode["max"] == c.max(), f"max component {c.max():.3g}"
    _agree(reaches, _max_error(PENDULUM, 0, "H"), "Example 4's max |ΔH|")


def test_verify_example4_and_glm43_parasitism():
    d1, d2 = _quotes("Example 4 is G-symplectic (with D = diag(#, #))")
    (zeta,) = _quotes("growth parameter for ζ = # is μ")
    (mu_text,) = re.findall(r"for ζ = −?\d+ is μ = ([^≠]+?) ≠ 0", _page())
    (glm43_mu,) = _quotes("GLM43 has μ = # for all parasitic roots")
    v = _verify("example4_glm")
    gs = v.g_symplectic
    assert gs.holds and [gs.D[i, i] for i in range(gs.D.shape[0])] == [sp.Rational(d1), sp.Rational(d2)], gs.D
    mu = sp.sympify(re.sub(r"(\d*)√(\d+)", lambda m: f"{m[1] or 1}*sqrt({m[2]})", mu_text.replace("−", "-")))
    (item,) = [p for p in v.parasitism.items if sp.simplify(p.zeta - int(zeta)) == 0]
    assert sp.simplify(item.mu - mu) == 0 and mu != 0, f"μ(ζ = {zeta}) = {item.mu}, the page says {mu_text}"
    for run in _meta(PENDULUM)["runs"][:1] + _meta(MP32)["runs"]:          # the runs' own record of μ
        assert [abs(float(x["mu"]) - float(mu)) < 1e-9 for x in run["parasitic_modes"]] == [True], run["label"]
    g43 = _verify("glm43").parasitism
    assert g43.items and all(p.mu == int(glm43_mu) for p in g43.items), g43
    for scene, runs in ((PENDULUM, [1]), ("fig3_17_glm43_kepler", [0, 1, 2])):
        for i in runs:
            assert all(float(x["mu"]) == int(glm43_mu) for x in _meta(scene)["runs"][i]["parasitic_modes"])


def test_pendulum_orbits_and_cos_q():
    (q0,) = _quotes("The orbit from q0 = # reaches them")
    den, fine = _quotes("The orbit of Figs 3.3/3.4 (|q| ≤ π/#) does not, and there Example 4 is fine (#)")
    y = _data(PENDULUM)["run0_y"]
    assert y[0, 0] == float(q0) and np.cos(y[:, 0]).min() < 0
    d = _data("fig3_03_glm_pendulum")
    for i in range(len(_meta("fig3_03_glm_pendulum")["runs"])):
        qmax = np.abs(d[f"run{i}_y"][:, 0]).max()
        assert qmax <= math.pi / int(den) + Q_TOL and qmax > math.pi / int(den) - 1e-2, qmax
        assert np.cos(d[f"run{i}_y"][:, 0]).min() > 0
    _agree(fine, _max_error("fig3_03_glm_pendulum", 0, "H"), "Example 4's max |ΔH| on the (1, 0) pendulum")


def test_example4_32_digits():
    t_h, h64, hmp, digits, t_c, c = _quotes("ΔH(t = #) is # in float64 and # at # digits, and the parasitic "
                                            "component at t = # is # in both")
    runs = _meta(MP32)["runs"]
    assert [r["precision"] for r in runs] == ["float64", f"mp:{digits}"]
    _agree(h64, _at(MP32, 0, "H", t_h), f"float64 ΔH(t = {t_h})")
    _agree(hmp, _at(MP32, 1, "H", t_h), f"{digits}-digit ΔH(t = {t_h})")
    for i in (0, 1):
        _agree(c, _at(MP32, i, "parasitic_0", t_c), f"{runs[i]['precision']} parasitic component at t = {t_c}")


# --- 3.11–3.16 ---------------------------------------------------------------------------------
EULER_KEPLER, SYMPL_KEPLER = "fig3_11_euler_kepler", "fig3_14_sympl_kepler"


def test_kepler_e35_parameters():
    e, h, T = _quotes("**3.11–3.16** (e = #, h = #, T = #)")
    for scene in (EULER_KEPLER, SYMPL_KEPLER):
        _scene_parameters(scene, e=e, h=h, T=T)


def test_explicit_euler_kepler_escapes():
    dH, H0, q1 = _quotes("|ΔH| # > |H0| = #, and q1 reaches about #")
    saved, h0 = _max_error(EULER_KEPLER, 0, "H"), _H0(EULER_KEPLER)
    _agree(dH, saved, "explicit Euler's max |ΔH|")
    _agree(H0, abs(h0), "|H0|")
    d = _data(EULER_KEPLER)
    assert saved > abs(h0) and h0 + d["run0_H"][-1] > 0, "the orbit is not unbound at the end"
    _about(q1, d["run0_y"][:, 0].min(), "min q1")


def test_projection_onto_H_alone_and_L():
    euler, sympl = _quotes("ΔL is # for Euler and # for symplectic Euler")
    _agree(euler, _max_error(EULER_KEPLER, 1, "L"), "Euler + projection onto H: max |ΔL|")
    _agree(sympl, _max_error(SYMPL_KEPLER, 1, "L"), "symplectic Euler + projection onto H: max |ΔL|")
    (alone,) = _quotes("Symplectic Euler alone keeps L exactly (#)")
    _agree(alone, _max_error(SYMPL_KEPLER, 0, "L"), "symplectic Euler: max |ΔL|")


# --- 3.17–3.19 ---------------------------------------------------------------------------------
GLM43_KEPLER, GLM43_LONG = "fig3_17_glm43_kepler", "fig3_18_glm43_kepler_long"


def test_glm43_kepler_parameters():
    h, e, T = _quotes("**3.17–3.19** (GLM43, h = #, e = #, T = #)")
    _scene_parameters(GLM43_KEPLER, e=e, h=h, T=T)


def test_repaired_glm43_bounded_and_parasitic_components():
    (about,) = _quotes("keeps H and L to about # without projection, with no drift")
    for inv in ("H", "L"):
        _agree(about, _max_error(GLM43_KEPLER, 0, inv), f"GLM43 repaired: max |Δ{inv}|")
        d = _data(GLM43_KEPLER)
        t, err = d["run0_t"], np.abs(d[f"run0_{inv}"])
        windows = [err[(t >= a) & (t <= a + 10)].max() for a in range(0, int(t[-1]), 10)]
        assert max(windows) <= (1 + NO_DRIFT) * windows[0], f"|Δ{inv}| per 10-unit window: {windows}"
    (below,) = _quotes("Its parasitic components stay below #.")
    modes = _meta(GLM43_KEPLER)["runs"][0]["parasitic_modes"]
    largest = max(_data(GLM43_KEPLER)[f"run0_parasitic_{j}"].max() for j in range(len(modes)))
    assert largest == max(x["max"] for x in modes) and largest <= float(below)
    _agree(below, largest, "GLM43 repaired: largest parasitic component")


def test_projection_onto_L_alone_drifts():
    (L,) = _quotes("Projecting onto L alone keeps L to #, but H now drifts linearly")
    _agree(L, _max_error(GLM43_KEPLER, 1, "L"), "GLM43 + projection onto L: max |ΔL|")
    T, m1, a1, b1, m2, a2, b2, slope = _quotes("The T = # run shows a window-minimum of # over t in [#, #] and # "
                                               "over [#, #], about # per unit time")
    _scene_parameters(GLM43_LONG, T=T)
    assert float(a1) == 0 and float(b2) == float(T) and float(b1) - float(a1) == float(b2) - float(a2), \
        "the two windows are the first and the last of equal width"
    assert _meta(GLM43_LONG)["runs"][0]["projection"] == ["L"]
    d = _data(GLM43_LONG)
    t, H = d["run0_t"], d["run0_H"]
    lows = []
    for m, a, b in ((m1, a1, b1), (m2, a2, b2)):
        low = H[(t >= float(a)) & (t <= float(b))].min()
        _agree(m, low, f"min ΔH over [{a}, {b}]")
        lows.append(low)
    centres = (float(a2) + float(b2)) / 2 - (float(a1) + float(b1)) / 2
    _agree(slope, (lows[1] - lows[0]) / centres, "slope between the window minima")
    w = float(b1) - float(a1)
    minima = [H[(t >= k * w) & (t <= (k + 1) * w)].min() for k in range(round(t[-1] / w))]
    assert all(np.diff(minima) < 0), f"window minima do not fall steadily: {minima}"


def test_glm43_as_printed_drifts():
    h10, t10, h100, t100 = _quotes("**GLM43 as printed** drifts (ΔH # at t = #, # at t = #)")
    assert "glm43_printed" in _meta(GLM43_KEPLER)["runs"][3]["file"]
    _agree(h10, _at(GLM43_KEPLER, 3, "H", t10), f"printed GLM43 ΔH(t = {t10})")
    _agree(h100, _at(GLM43_KEPLER, 3, "H", t100), f"printed GLM43 ΔH(t = {t100})")


def test_verify_glm43_printed_and_repaired():
    eqs, unknowns, rank, order = _quotes("the #×# system for (G, D) has full rank #, so the only solution is "
                                         "G = D = 0. It also has order #")
    gs = _verify("glm43_printed").g_symplectic
    assert not gs.holds and gs.dimension == 0
    assert (gs.equations, gs.unknowns, gs.rank) == (int(eqs), int(unknowns), int(rank)) and gs.rank == gs.unknowns
    assert _verify("glm43_printed").order.order == int(order)
    *G, d1, d2, d3, d4, den, zero, order = _quotes("G-symplectic (G = diag(#, #, #), D = diag(#, #, #, #)/#, "
                                                  "all three conditions exactly #) and has order #")
    v = _verify("glm43")
    gs = v.g_symplectic
    assert gs.holds and gs.G == sp.diag(*(sp.Rational(g) for g in G)), gs.G
    assert gs.D == sp.diag(*(sp.Rational(x) / int(den) for x in (d1, d2, d3, d4))), gs.D
    assert len(gs.residuals) == 3 and all(x == int(zero) for R in gs.residuals.values() for x in R)
    assert v.order.order == int(order)


# --- Kepler force (ERRATA 5) -------------------------------------------------------------------
FORCE_PRINTED, FORCE_CORRECTED = "fig2_01_force_check_printed", "fig2_01_force_check_corrected"


def _printed_force_mismatch(y0, c: float, delta: float):
    """The seed's printed force −q/r³ − c q/r³ = −(1 + c) q/r³ is central: E = |p|²/2 − (1 + c)/r
    and L are conserved, so r stays between the roots of E r² + (1 + c) r − L²/2, and the stated
    H = |p|²/2 − 1/r − δ/(2r³) = E + g(r), g = c/r − δ/(2r³), changes by g(r) − g(r0).
    Returns (r_min, r_max, max |ΔH|) along the exact orbit from y0."""
    q1, q2, p1, p2 = (float(x) for x in y0)
    k, r0, L = 1 + c, math.hypot(q1, q2), q1 * p2 - q2 * p1
    E = (p1 * p1 + p2 * p2) / 2 - k / r0
    rmin, rmax = sorted(np.roots([E, k, -L * L / 2]).real)
    r = np.append(np.linspace(rmin, rmax, 200001), [x for x in [math.sqrt(1.5 * delta / c)] if rmin <= x <= rmax])

    def g(r):
        return c / r - delta / (2 * r**3)
    return rmin, rmax, float(np.abs(g(r) - g(r0)).max())


def test_force_check_scenes_parameters():
    e, h, T = _quotes("We integrate the same e = # orbit with Gauss2 (h = #, T = #) twice")
    from tableau_lab.numeric.problems import get_problem
    y0 = [float(x) for x in get_problem("kepler", e=e).initial_state()]
    for scene in (FORCE_PRINTED, FORCE_CORRECTED):
        _scene_parameters(scene, h=h, T=T)
        m = _meta(scene)
        assert all("gauss2" in r["file"] for r in m["runs"]), scene
        for i in range(len(m["runs"])):
            assert np.allclose(_data(scene)[f"run{i}_y"][0], y0, rtol=0, atol=1e-15), f"{scene}: not the e = {e} start"


def test_printed_force_changes_the_stated_H():
    (c,) = _quotes("the seed's printed force −q/r³ − # q/r³")
    delta, up_to = _quotes("H (with −#/(2r³)) changes by up to **#**")
    saved = _max_error(FORCE_PRINTED, 0, "H")
    _agree(up_to, saved, "printed force: Gauss2's max |ΔH|")
    *_, closed = _printed_force_mismatch(_data(FORCE_PRINTED)["run0_y"][0], float(c), float(delta))
    assert abs(closed - saved) <= CLOSED_FORM_RTOL * saved, f"closed form {closed:.6g}, run {saved:.6g}"
    _agree(up_to, closed, "printed force: max |ΔH| along the exact orbit")
    about, r_lo, r_hi = _quotes("so the mismatch is only about # there (a closed form, not a run: the printed force "
                                "is central, so the stated H changes only with r, here in [#, #])")
    rmin, rmax, e0 = _printed_force_mismatch(_data(KEPLER_E0)["run0_y"][0], float(c), float(delta))
    _agree(about, e0, "printed force from the e = 0 start: max |ΔH| (closed form)")
    _agree(r_lo, rmin, "e = 0 start, printed force: r_min")
    _agree(r_hi, rmax, "e = 0 start, printed force: r_max")


def test_corrected_force_float64_and_32_digits():
    at_most, same, digits = _quotes("H changes by at most **#**, and by the same # at # digits")
    runs = _meta(FORCE_CORRECTED)["runs"]
    assert [r["precision"] for r in runs] == ["float64", f"mp:{digits}"]
    _agree(at_most, _max_error(FORCE_CORRECTED, 0, "H"), "corrected force, float64: max |ΔH|")
    _agree(same, _max_error(FORCE_CORRECTED, 1, "H"), f"corrected force, {digits} digits: max |ΔH|")


# --- Runner observations, wall time --------------------------------------------------------------
def _scene_files() -> list:
    return sorted((ROOT / "reports" / "scenes").glob("*.json"))


def test_every_scene_run_completed():
    (count,) = _quotes("all # scene runs exited with 0")
    files = _scene_files()
    assert int(count) == len(files), f"the page says {count}, reports/scenes/ holds {len(files)} scenes"
    for f in files:
        name = json.loads(f.read_text())["name"]
        meta = _meta(name)
        assert meta["complete"] and all(r["status"] == "completed" for r in meta["runs"]), name
        assert not (ROOT / "reports" / name / "meta.incomplete.json").exists(), name


def test_wall_time_paragraph_names_the_scenes():
    count, seconds = _quotes("the # scenes of `reports/scenes/`")[0], _quotes("take # s together")[0]
    (listed,) = re.findall(r"the \d+ scenes of `reports/scenes/` \(([^)]*)\)", _page(), re.DOTALL)
    files = {f.stem for f in _scene_files()}
    named = set(re.findall(r"`(\w+)`", _page().split("## Runner observations")[0])) & files
    extras = set(re.findall(r"`(\w+)`", listed))
    assert int(count) == len(files) and named | extras == files, (count, sorted(files - named - extras))
    # a wall time is not in the saved data; it cannot be less than the integration seconds they record
    integration = sum(r["seconds"] for f in files for r in _meta(f)["runs"])
    assert float(seconds) >= integration, f"{seconds} s < the runs' own {integration:.1f} s"


def test_plot_floor():
    (floor,) = _quotes("errors that are exactly 0 at the ~# floor")
    from tableau_lab.experiments.plots import plot_floor
    _agree(floor, plot_floor({"precision": "float64"}), "the float64 plot floor")


def test_a_number_changed_by_hand_fails(tmp_path, monkeypatch):
    """The checks read the page: a copy with one number changed fails."""
    page = tmp_path / "seed_figures.md"
    page.write_text(_page().replace("0.188 at t = 50", "0.198 at t = 50"))
    monkeypatch.setattr(sys.modules[__name__], "DOC", page)
    with pytest.raises(AssertionError, match="0.198"):
        test_explicit_euler_energy_grows_monotonically()
