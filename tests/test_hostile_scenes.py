"""Hostile scene and method JSON files (issue 16, input hygiene): each is refused at once with
the caller's error class (SceneError, TableauError), a message naming the file and the entry,
and, through the CLI, exit 2, no traceback and nothing written under --out."""
import json
import os
import re
import signal
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from tableau_lab.exact.tableau_json import MAX_BYTES, TableauError, load
from tableau_lab.experiments.scene import SceneError, load_scene, run_scene
from tableau_lab.inputs import MAX_JSON_BYTES, MAX_JSON_DEPTH, MAX_STEPS

METHODS = (Path(__file__).parent.parent / "methods").resolve()
RK4 = str(METHODS / "rk4.json")
DROP = object()                     # an override that removes the key


def _base():
    return {"format": "tableau_lab/scene/1", "name": "hostile", "problem": "pendulum", "h": "1/100",
            "steps": 100, "runs": [{"method": RK4, "label": "RK4"}], "record_every": 10, "plots": ["invariants"]}


def _scene_text(over=None, run=None):
    d = _base()
    for k, v in (over or {}).items():
        if v is DROP:
            d.pop(k, None)
        else:
            d[k] = v
    for k, v in (run or {}).items():
        d["runs"][0][k] = v
    return json.dumps(d)


def _raw(old, new):
    """The base scene's text with ``old`` replaced by ``new`` (for what json.dumps cannot write)."""
    text = _scene_text()
    assert old in text
    return text.replace(old, new, 1)


DEFINE = {"name": "osc", "q": ["x"], "p": ["v"], "H": "v^2/2 + x^2/2", "q0": ["1"], "p0": ["0"]}

# id -> (scene text, fragments the message must hold besides the file name)
SCENES = {
    # runs and their keys
    "method_null": (_scene_text(run={"method": None}), ["runs[1].method"]),
    "method_int": (_scene_text(run={"method": 5}), ["runs[1].method"]),
    "method_empty": (_scene_text(run={"method": ""}), ["runs[1].method"]),
    "method_list": (_scene_text(run={"method": [RK4]}), ["runs[1].method"]),
    "method_missing_file": (_scene_text(run={"method": "nope.json"}), ["runs[1].method", "no file nope.json"]),
    "method_nul_byte": (_scene_text(run={"method": "a\u0000b"}), ["runs[1].method", "control character"]),
    "project_nested": (_scene_text(run={"project": [["H"]]}), ["runs[1].project"]),
    "project_string": (_scene_text(run={"project": "H"}), ["runs[1].project"]),
    "project_twice": (_scene_text(run={"project": ["H", "H"]}), ["runs[1].project", "distinct"]),
    "project_unknown": (_scene_text(run={"project": ["Q"]}), ["runs[1].project", "not invariants"]),
    "run_precision_list": (_scene_text(run={"precision": ["dd"]}), ["runs[1].precision"]),
    "run_precision_arabic_digits": (_scene_text(run={"precision": "mp:\u0663\u0662"}), ["runs[1].precision"]),
    "run_precision_space": (_scene_text(run={"precision": "mp: 32"}), ["runs[1].precision"]),
    "run_start_null": (_scene_text(run={"start": None}), ["runs[1].start"]),
    "run_start_unknown": (_scene_text(run={"start": "lazy"}), ["runs[1].start", "exact, naive"]),
    "run_label_int": (_scene_text(run={"label": 5}), ["runs[1].label"]),
    "run_label_escape": (_scene_text(run={"label": "\u001b]0;owned\u0007"}), ["runs[1].label", "control character"]),
    "run_label_bidi": (_scene_text(run={"label": "abc\u202edef"}), ["runs[1].label"]),
    "run_label_huge": (_scene_text(run={"label": "x" * 5000}), ["runs[1].label", "at most"]),
    "run_unknown_key": (_scene_text(run={"colour": "red"}), ["runs[1]", "colour"]),
    "run_not_object": (_scene_text({"runs": [5]}), ["runs[1]"]),
    "run_empty_object": (_scene_text({"runs": [{}]}), ["runs[1]"]),
    "runs_empty": (_scene_text({"runs": []}), ["runs"]),
    "runs_object": (_scene_text({"runs": {"method": RK4}}), ["runs"]),
    "runs_null": (_scene_text({"runs": None}), ["runs"]),
    "runs_missing": (_scene_text({"runs": DROP}), ["runs"]),
    "runs_too_many": (_scene_text({"runs": [{"method": RK4}] * 101}), ["runs", "at most 100"]),
    # top-level keys
    "plots_int": (_scene_text({"plots": 5}), ["plots"]),
    "plots_unknown": (_scene_text({"plots": ["pie"]}), ["plots", "unknown plots"]),
    "plots_int_entry": (_scene_text({"plots": [5]}), ["plots"]),
    "plots_twice": (_scene_text({"plots": ["invariants", "invariants"]}), ["plots", "distinct"]),
    "precision_list": (_scene_text({"precision": ["dd"]}), ["precision"]),
    "precision_unknown": (_scene_text({"precision": "quad"}), ["precision", "float64, dd or mp:DIGITS"]),
    "precision_too_few_digits": (_scene_text({"precision": "mp:2"}), ["precision", "5 <= DIGITS"]),
    "precision_too_many_digits": (_scene_text({"precision": "mp:99999"}), ["precision"]),
    "title_int": (_scene_text({"title": 5}), ["title"]),
    "title_list": (_scene_text({"title": ["a"]}), ["title"]),
    "title_escape": (_scene_text({"title": "\u001b[2J"}), ["title", "control character"]),
    "notes_int": (_scene_text({"notes": 5}), ["notes"]),
    "notes_list_of_int": (_scene_text({"notes": [1]}), ["notes"]),
    "seed_object": (_scene_text({"seed": {}}), ["seed"]),
    "seed_delete_char": (_scene_text({"seed": "a\u007fb"}), ["seed", "control character"]),
    "start_unknown": (_scene_text({"start": "lazy"}), ["start"]),
    "start_int": (_scene_text({"start": 1}), ["start"]),
    "record_every_zero": (_scene_text({"record_every": 0}), ["record_every"]),
    "record_every_negative": (_scene_text({"record_every": -1}), ["record_every"]),
    "record_every_string": (_scene_text({"record_every": "10"}), ["record_every"]),
    "record_every_bool": (_scene_text({"record_every": True}), ["record_every"]),
    "record_every_float": (_scene_text({"record_every": 1.5}), ["record_every"]),
    "record_every_above_steps": (_scene_text({"record_every": 101}), ["record_every", "between 1 and 100"]),
    "monitor_zero": (_scene_text({"monitor": "0"}), ["monitor"]),
    "monitor_negative": (_scene_text({"monitor": "-1"}), ["monitor"]),
    "monitor_underflow": (_scene_text({"monitor": "1e-999"}), ["monitor", "rounds to 0.0"]),
    "monitor_null": (_scene_text({"monitor": None}), ["monitor"]),
    "monitor_text": (_scene_text({"monitor": "abc"}), ["monitor"]),
    "steps_zero": (_scene_text({"steps": 0}), ["steps"]),
    "steps_above_limit": (_scene_text({"steps": 10 ** 10, "record_every": 1}), ["steps", str(MAX_STEPS)]),
    "steps_string": (_scene_text({"steps": "100"}), ["steps"]),
    "steps_bool": (_scene_text({"steps": True}), ["steps"]),
    "steps_float": (_scene_text({"steps": 1.5}), ["steps"]),
    "steps_and_T": (_scene_text({"T": 1}), ["exactly one of steps and T"]),
    "T_over_h_overflow": (_scene_text({"steps": DROP, "T": "1e300", "h": "1", "record_every": 1}),
                          ["T", "MAX_STEPS", str(MAX_STEPS)]),
    "T_over_h_huge_exact": (_scene_text({"steps": DROP, "T": "10^9", "h": "1/1000", "record_every": 1}),
                            ["T", "MAX_STEPS"]),
    "T_not_whole_steps": (_scene_text({"steps": DROP, "T": "1/3"}), ["T", "whole number"]),
    "T_negative": (_scene_text({"steps": DROP, "T": "-1"}), ["T", "positive"]),
    "T_null": (_scene_text({"steps": DROP, "T": None}), ["T"]),
    "h_underflow": (_scene_text({"h": "1e-999"}), ["h", "rounds to 0.0"]),
    "h_overflow": (_scene_text({"h": "1e999"}), ["h", "rounds to inf"]),
    "h_zero": (_scene_text({"h": "0"}), ["h must be a positive"]),
    "h_float": (_scene_text({"h": 0.01}), ["h", "exact strings"]),
    "h_arabic_digits": (_scene_text({"h": "\u0661/\u0661\u0660\u0660"}), ["h", "ASCII"]),
    "h_nan_name": (_scene_text({"h": "nan"}), ["h"]),
    "h_inf_name": (_scene_text({"h": "inf"}), ["h"]),
    "h_missing": (_scene_text({"h": DROP}), ["h"]),
    "h_imaginary": (_scene_text({"h": "sqrt(-1)"}), ["h"]),
    "h_list": (_scene_text({"h": [1]}), ["h"]),
    "modified_energy_true": (_scene_text({"modified_energy": True}), ["modified_energy", "an object"]),
    "modified_energy_int": (_scene_text({"modified_energy": 2}), ["modified_energy", "an object"]),
    "modified_energy_null": (_scene_text({"modified_energy": None}), ["modified_energy"]),
    "modified_energy_terms_zero": (_scene_text({"modified_energy": {"terms": 0}}),
                                   ["modified_energy.terms", "between 1 and 3"]),
    "modified_energy_terms_four": (_scene_text({"modified_energy": {"terms": 4}}),
                                   ["modified_energy.terms", "between 1 and 3"]),
    "modified_energy_terms_string": (_scene_text({"modified_energy": {"terms": "2"}}), ["modified_energy.terms"]),
    "modified_energy_terms_bool": (_scene_text({"modified_energy": {"terms": True}}), ["modified_energy.terms"]),
    "modified_energy_terms_float": (_scene_text({"modified_energy": {"terms": 1.5}}), ["modified_energy.terms"]),
    "modified_energy_terms_huge": (_raw('"steps": 100',
                                        '"steps": 100, "modified_energy": {"terms": ' + "9" * 5000 + "}"),
                                   ["modified_energy.terms", "5000 digits"]),
    "modified_energy_unknown_key": (_scene_text({"modified_energy": {"terms": 2, "colour": 1}}),
                                    ["modified_energy", "unknown keys", "colour"]),
    "modified_energy_escape_key": (_scene_text({"modified_energy": {"\u001b[2J": 1}}),
                                   ["modified_energy", "control character"]),
    "modified_energy_general_problem": (_scene_text({"problem": {"define": {"name": "decay", "y": ["x"], "f": ["-x"],
                                                                           "y0": ["1"]}},
                                                     "modified_energy": {"terms": 2}}),
                                        ["modified_energy", "not Hamiltonian"]),
    # the name: it names the output folder
    "name_dotdot": (_scene_text({"name": ".."}), ["name", "file-name-safe"]),
    "name_dot": (_scene_text({"name": "."}), ["name", "file-name-safe"]),
    "name_hidden": (_scene_text({"name": ".hidden"}), ["name"]),
    "name_slash": (_scene_text({"name": "a/b"}), ["name"]),
    "name_parent_path": (_scene_text({"name": "../evil"}), ["name"]),
    "name_empty": (_scene_text({"name": ""}), ["name"]),
    "name_int": (_scene_text({"name": 5}), ["name"]),
    "name_missing": (_scene_text({"name": DROP}), ["name"]),
    "name_arabic_digits": (_scene_text({"name": "\u0661\u0662"}), ["name"]),
    "name_non_ascii_letters": (_scene_text({"name": "\u00fcn\u00ef"}), ["name"]),
    "name_too_long": (_scene_text({"name": "a" * 101}), ["name"]),
    "name_leading_dash": (_scene_text({"name": "-rf"}), ["name"]),
    "name_space": (_scene_text({"name": "a b"}), ["name"]),
    "name_trailing_newline": (_scene_text({"name": "a\n"}), ["name"]),
    "name_nul": (_scene_text({"name": "a\u0000"}), ["name", "control character"]),
    "name_lone_surrogate": (_raw('"name": "hostile"', '"name": "\\ud800"'), ["name", "lone surrogate", "\\ud800"]),
    "format_wrong": (_scene_text({"format": "tableau_lab/scene/2"}), ["format"]),
    "format_int": (_scene_text({"format": 5}), ["format"]),
    "unknown_key": (_scene_text({"color": "red"}), ["unknown keys", "color"]),
    # the problem
    "problem_null": (_scene_text({"problem": None}), ["problem"]),
    "problem_int": (_scene_text({"problem": 5}), ["problem"]),
    "problem_unknown": (_scene_text({"problem": "nope"}), ["problem", "unknown problem"]),
    "problem_set_int": (_scene_text({"problem": {"name": "kepler", "set": 5}}), ["problem.set"]),
    "problem_set_null_value": (_scene_text({"problem": {"name": "kepler", "set": {"e": None}}}), ["problem.set.e"]),
    "problem_set_arabic": (_scene_text({"problem": {"name": "kepler", "set": {"e": "\u0661/\u0662"}}}),
                           ["problem.set.e", "ASCII"]),
    "problem_extra_key": (_scene_text({"problem": {"name": "kepler", "colour": 1}}), ["problem", "colour"]),
    "problem_define_int": (_scene_text({"problem": {"define": 5}}), ["problem"]),
    "problem_define_and_name": (_scene_text({"problem": {"define": DEFINE, "name": "x"}}), ["problem"]),
    "problem_define_nan_name": (_scene_text({"problem": {"define": {**DEFINE, "parameters": {"nan": "1"}}}}),
                                ["problem", "'nan' is not a valid name"]),
    "problem_define_empty_invariant": (_scene_text({"problem": {"define": {**DEFINE, "invariants": {"": "x"}}}}),
                                       ["problem", "invariants."]),
    # JSON itself
    "duplicate_key_top": (_raw('"steps": 100', '"steps": 10, "steps": 100'), ["steps", "duplicate key 'steps'"]),
    "duplicate_key_run": (_raw('"label": "RK4"', '"method": "x.json", "label": "RK4"'),
                          ["runs[1].method", "duplicate key 'method'"]),
    "duplicate_key_problem_set": (_scene_text({"problem": {"name": "kepler", "set": {"e": "0.5"}}}).replace(
        '"e": "0.5"', '"e": "0.5", "e": "0.6"'), ["problem.set.e", "duplicate key"]),
    "nan_literal": (_raw('"h": "1/100"', '"h": NaN'), ["h: NaN"]),
    "nan_literal_nested": (_raw('"label": "RK4"', '"label": [1, NaN]'), ["runs[1].label[2]: NaN"]),
    "infinity_literal": (_raw('"steps": 100', '"steps": Infinity'), ["steps: Infinity"]),
    "minus_infinity_literal": (_raw('"steps": 100', '"steps": -Infinity'), ["steps: -Infinity"]),
    "float_overflow_literal": (_raw('"steps": 100', '"steps": 1e999'), ["steps", "out of the range"]),
    "integer_5000_digits": (_raw('"steps": 100', '"steps": ' + "9" * 5000), ["steps", "5000 digits"]),
    "deep_nesting_1e5": (_raw('"plots": ["invariants"]', '"notes": ' + "[" * 10 ** 5 + "]" * 10 ** 5),
                         ["nested too deeply", str(MAX_JSON_DEPTH)]),
    "deep_nesting_objects": (_raw('"plots": ["invariants"]', '"notes": ' + '{"a": ' * 100 + "1" + "}" * 100),
                             ["nested too deeply"]),
    "deep_nesting_just_over": (_raw('"plots": ["invariants"]',
                                    '"notes": ' + "[" * MAX_JSON_DEPTH + "]" * MAX_JSON_DEPTH),
                               ["nested too deeply"]),
    "deep_nesting_unclosed": ("[" * 10 ** 5, ["nested too deeply"]),
    "top_level_array": ("[" + _scene_text() + "]", ["one JSON object"]),
    "top_level_string": ('"hostile"', ["one JSON object"]),
    "truncated": (_scene_text()[:-5], ["not valid JSON"]),
    "empty_file": ("", ["not valid JSON"]),
    "byte_order_mark": ("\ufeff" + _scene_text(), ["not valid JSON"]),
    "lone_surrogate_key": (_raw('"format"', '"\\udc80": 1, "format"'), ['["\\udc80"]', "lone surrogate"]),
    "lone_surrogate_method": (_raw('"label": "RK4"', '"label": "a\\udfffb"'), ["runs[1].label", "lone surrogate"]),
    "raw_control_char": (_raw('"name": "hostile"', '"name": "a\u0001b"'), ["not valid JSON"]),
}
assert len(SCENES) >= 60


def _fragments_in(message, path, fragments):
    assert str(path) in message, message
    for f in fragments:
        assert f in message, (f, message)
    assert "Traceback" not in message


@pytest.mark.parametrize("case", sorted(SCENES))
def test_hostile_scene_refused(tmp_path, case):
    text, fragments = SCENES[case]
    path = tmp_path / f"{case}.json"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    with pytest.raises(SceneError) as info:
        load_scene(path)
    _fragments_in(str(info.value), path, fragments)
    str(info.value).encode("utf-8")                      # printable: no lone surrogate in the message
    with pytest.raises(SceneError):                      # run_scene refuses before writing anything
        run_scene(path, out_root=tmp_path / "out", progress=False)
    assert not (tmp_path / "out").exists()


def test_not_utf8_scene(tmp_path):
    path = tmp_path / "latin1.json"
    path.write_bytes(_raw('"name": "hostile"', '"name": "hostile", "title": "caf\u00e9"').encode("latin-1"))
    with pytest.raises(SceneError, match="not UTF-8"):
        load_scene(path)


# -- files that are not regular files ----------------------------------------------------------

@pytest.fixture
def alarm():
    """A hang (a FIFO opened for reading) fails the test instead of blocking it."""
    def hung(*_):
        raise TimeoutError("hung reading a special file")
    old = signal.signal(signal.SIGALRM, hung)
    signal.alarm(10)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, old)


def _fifo(p):
    os.mkfifo(p)
    return p


def _dir(p):
    p.mkdir()
    return p


def _symlink_dev_zero(p):
    p.symlink_to("/dev/zero")
    return p


def _huge(limit):
    def make(p):
        with open(p, "wb") as fh:                         # sparse: nothing is really written
            fh.truncate(limit + 1)
        return p
    return make


def _socket(p):
    s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    s.bind(str(p))
    s.close()
    return p


SPECIAL = {
    "fifo": (_fifo, "FIFO"),
    "directory": (_dir, "a directory"),
    "dev_zero": (lambda p: Path("/dev/zero"), "character device"),
    "symlink_to_dev_zero": (_symlink_dev_zero, "character device"),
    "socket": (_socket, "socket"),
    "missing": (lambda p: p, "cannot read"),
}


@pytest.mark.parametrize("case", sorted(SPECIAL) + ["huge"])
def test_special_scene_file_refused_at_once(tmp_path, alarm, case):
    make, fragment = SPECIAL[case] if case != "huge" else (_huge(MAX_JSON_BYTES), "larger than")
    path = make(tmp_path / "scene.json")
    with pytest.raises(SceneError) as info:
        load_scene(path)
    _fragments_in(str(info.value), path, [fragment])


@pytest.mark.parametrize("case", sorted(SPECIAL) + ["huge"])
def test_special_method_file_refused_at_once(tmp_path, alarm, case):
    make, fragment = SPECIAL[case] if case != "huge" else (_huge(MAX_BYTES), "larger than")
    method = make(tmp_path / "m.json")
    with pytest.raises(TableauError) as info:
        load(method)
    _fragments_in(str(info.value), method, [fragment])
    scene = tmp_path / "scene.json"
    scene.write_text(_scene_text(run={"method": str(method)}))
    with pytest.raises(SceneError) as info:
        load_scene(scene)
    msg = str(info.value)
    _fragments_in(msg, scene, ["runs[1].method", fragment if case != "missing" else "no file"])


# -- method files with hostile JSON -----------------------------------------------------------

GOOD_METHOD = '{"name": "Euler", "kind": "rk", "A": [["0"]], "b": ["1"]}'

# id -> (method text, entry named, fragment)
METHOD_TEXTS = {
    "duplicate_key": (GOOD_METHOD.replace('"b": ["1"]', '"b": ["1"], "b": ["2"]'), "b", "duplicate key 'b'"),
    "duplicate_nested_key": (GOOD_METHOD.replace('"b": ["1"]', '"b": ["1"], "claims": {"order": 1, "order": 2}'),
                             "claims.order", "duplicate key 'order'"),
    "lone_surrogate_name": (GOOD_METHOD.replace('"Euler"', '"\\ud800"'), "name", "lone surrogate"),
    "escape_in_name": (GOOD_METHOD.replace('"Euler"', '"\\u001b]0;owned\\u0007"'), "name", "control character"),
    "clear_screen_in_notes": (GOOD_METHOD.replace('"b": ["1"]', '"b": ["1"], "notes": "\\u001b[2J"'),
                              "notes", "control character"),
    "lone_surrogate_in_entry": (GOOD_METHOD.replace('["1"]', '["\\udc00"]'), "b[1]", "lone surrogate"),
    "deep_nesting": (GOOD_METHOD.replace('[["0"]]', "[" * 10 ** 5 + "]" * 10 ** 5), None, "nested too deeply"),
    "nan_entry": (GOOD_METHOD.replace('["1"]', "[NaN]"), "b[1]", "NaN is not a number"),
}


@pytest.mark.parametrize("case", sorted(METHOD_TEXTS))
def test_hostile_method_json_refused(tmp_path, case):
    text, entry, fragment = METHOD_TEXTS[case]
    method = tmp_path / f"{case}.json"
    method.write_text(text)
    with pytest.raises(TableauError) as info:
        load(method)
    msg = str(info.value)
    assert msg.startswith(f"{method}: ")
    _fragments_in(msg, method, [fragment] + ([f"entry {entry}:"] if entry else []))
    scene = tmp_path / "scene.json"
    scene.write_text(_scene_text(run={"method": str(method)}))
    if case == "nan_entry":                              # refused by entry when the method is read in full
        return
    with pytest.raises(SceneError) as info:
        load_scene(scene)
    _fragments_in(str(info.value), scene, ["runs[1].method", str(method), fragment])


def test_every_shipped_scene_still_loads():
    root = Path(__file__).parent.parent / "reports"
    scenes = [p for p in root.rglob("*.json") if '"tableau_lab/scene/1"' in p.read_text(encoding="utf-8")]
    assert len(scenes) >= 20
    for p in scenes:
        load_scene(p)


# -- through the command line -----------------------------------------------------------------

CLI_SAMPLE = ["method_null", "plots_int", "project_nested", "precision_list", "title_int", "name_dotdot", "name_dot",
              "duplicate_key_top", "nan_literal", "deep_nesting_1e5", "name_lone_surrogate", "T_over_h_overflow",
              "h_underflow", "record_every_above_steps", "run_label_escape"]


def _cli(args, timeout=60):
    return subprocess.run([sys.executable, "-m", "tableau_lab", *args], capture_output=True, text=True,
                          timeout=timeout, errors="backslashreplace")


def test_cli_refuses_hostile_scenes_exit_2_no_traceback_nothing_written(tmp_path):
    paths = []
    for case in CLI_SAMPLE:
        p = tmp_path / f"{case}.json"
        p.write_text(SCENES[case][0], encoding="utf-8", errors="surrogatepass")
        paths.append(p)
    fifo = _fifo(tmp_path / "fifo.json")
    out = tmp_path / "out"
    proc = _cli(["run", *map(str, paths), str(fifo), "/dev/zero", str(tmp_path), "--out", str(out)])
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr and proc.stdout == ""
    errors = [line for line in proc.stderr.splitlines() if line.startswith("tableau-lab: error:")]
    assert len(errors) == len(paths) + 3, proc.stderr
    for p, line in zip(paths, errors, strict=False):
        assert str(p) in line
    assert "FIFO" in errors[-3] and "character device" in errors[-2] and "directory" in errors[-1]
    assert "\x1b" not in proc.stderr
    assert not out.exists()


def test_cli_scene_named_dotdot_touches_nothing_outside_out(tmp_path):
    parent = tmp_path / "reports"
    out = parent / "out"
    out.mkdir(parents=True)
    (parent / "meta.json").write_text("keep")
    (parent / "data.npz").write_text("keep")
    before = sorted(p.name for p in tmp_path.rglob("*"))
    for name in ("..", "."):
        scene = tmp_path / f"scene_{len(name)}.json"
        scene.write_text(_scene_text({"name": name}))
        proc = _cli(["run", str(scene), "--out", str(out)])
        assert proc.returncode == 2 and "Traceback" not in proc.stderr and "name" in proc.stderr
    after = sorted(p.name for p in tmp_path.rglob("*") if not p.name.startswith("scene_"))
    assert after == before and list(out.iterdir()) == []
    assert (parent / "meta.json").read_text() == "keep" and (parent / "data.npz").read_text() == "keep"


def test_cli_method_fifo_does_not_hang(tmp_path):
    fifo = _fifo(tmp_path / "m.json")
    proc = _cli(["verify", str(fifo)], timeout=60)
    assert proc.returncode == 2 and "FIFO" in proc.stderr and "Traceback" not in proc.stderr


# issue 29: runs ----------------------------------------------------------------------------------
# entry names one-based in every message of the scene and JSON surface; a constant invariant,
# an invariants plot without invariants; work-precision scenes within a run's step budget, with
# known peers only (tests/hostile_cases.py runs the same through the command line)

RUNS29 = {
    "second_run_missing": (_scene_text({"runs": [{"method": RK4}, {"method": "nope.json"}]}), ["runs[2].method"]),
    "set_list_entry": (_scene_text({"problem": {"name": "pendulum", "set": {"q0": ["1", "x"]}}}),
                       ["problem.set.q0[2]"]),
    "json_path_nested": (_raw('"label": "RK4"', '"label": [1, 2, NaN]'), ["runs[1].label[3]: NaN"]),
    "project_constant": (_scene_text({"problem": {"define": {**DEFINE, "invariants": {"C": "7/2"}}}},
                                     run={"project": ["C"]}), ["runs[1].project", "C = 7/2 is constant"]),
    "invariants_plot_without_invariants": (
        _scene_text({"problem": {"define": {"name": "decay", "y": ["x"], "f": ["-x"], "y0": ["1"]}}}),
        ["plots", "no invariants to plot"]),
}


def _wp(**over):
    d = {"format": "tableau_lab/workprecision/1", "name": "w", "problem": "harmonic", "T": 1,
         "methods": [{"method": RK4, "steps": [10, 20]}], "peers": [{"method": "DOP853", "rtol": ["1e-6"]}]}
    d.update(over)
    return json.dumps(d)


WP29 = {
    "steps_1e12": (_wp(methods=[{"method": RK4, "steps": [10, 10 ** 12]}]), ["methods[1].steps[2]", str(MAX_STEPS)]),
    "steps_float": (_wp(methods=[{"method": RK4, "steps": [1.5]}]), ["methods[1].steps[1]"]),
    "steps_bool": (_wp(methods=[{"method": RK4, "steps": [True]}]), ["methods[1].steps[1]"]),
    "T_1e300": (_wp(T="1e300"), ["reference solution", "MAX_STEPS"]),
    "T_just_over": (_wp(T=str(MAX_STEPS // 1000 + 1)), ["MAX_STEPS"]),
    "T_negative": (_wp(T="-1"), ["T must be positive"]),
    "peer_lsoda": (_wp(peers=[{"method": "LSODA", "rtol": ["1e-6"]}]), ["peers[1].method", "DOP853, RK45"]),
    "peer_second_unknown": (_wp(peers=[{"method": "RK45", "rtol": ["1e-6"]}, {"method": "euler"}]),
                            ["peers[2].method"]),
    "atol_text": (_wp(peers=[{"method": "RK45", "rtol": ["1e-6"], "atol_factor": "x"}]), ["peers[1].atol_factor"]),
    "rtol_zero": (_wp(peers=[{"method": "RK45", "rtol": ["0"]}]), ["peers[1].rtol[1]", "(0, 1)"]),
    "method_key_unknown": (_wp(methods=[{"method": RK4, "steps": [10], "colour": 1}]), ["methods[1]", "colour"]),
    "invariant_unknown": (_wp(invariant="L"), ["invariant", "unknown"]),
}


@pytest.mark.parametrize("case", [("scene", k) for k in sorted(RUNS29)] + [("workprecision", k) for k in sorted(WP29)],
                         ids=lambda c: "-".join(c))
def test_issue29_refused_one_based(tmp_path, case):
    """Scenes and work-precision scenes refused naming the entry, one-based.  5ea0488: "steps":
    [10**12] ran until killed, "T": "1e300" ended in a numba TypingError (exit 3), LSODA was
    accepted, a bad atol_factor was exit 3, entries were named runs[0], q0[0]."""
    from tableau_lab.experiments.workprecision import load_wp_scene
    kind, key = case
    text, fragments = (RUNS29 if kind == "scene" else WP29)[key]
    path = tmp_path / f"{key}.json"
    path.write_text(text)
    with pytest.raises(SceneError) as info:
        (load_scene if kind == "scene" else load_wp_scene)(path)
    _fragments_in(str(info.value), path, fragments)
    assert not re.search(r"\[0\]", str(info.value)), str(info.value)


def test_issue29_workprecision_tolerances_as_json_numbers(tmp_path):
    """A tolerance may be a JSON number (the decimal it is written as) or an exact string."""
    from tableau_lab.experiments.workprecision import load_wp_scene
    path = tmp_path / "w.json"
    path.write_text(_wp(peers=[{"method": "RK45", "rtol": [1e-6, "1e-8"], "atol_factor": 0.5}]))
    (peer,) = load_wp_scene(path).peers
    assert peer == ("RK45", (1e-6, 1e-8), 0.5)
# issue 29: runs (end) ----------------------------------------------------------------------------
