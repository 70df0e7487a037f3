"""The package's shape, read from its source (docs/architecture.md), over the WHOLE package with no
module left out:

* no import cycle — every ``import`` counts, also one inside a function (the strongly connected
  components of the import graph are single modules);
* no floor reaching up — base (top-level helpers) < exact < render < analysis < numeric < experiments <
  faces; a module imports only from its own floor and those below;
* no private name (leading underscore) imported across modules, by ``from m import _x`` or by
  ``m._x`` on an imported module;
* a module found by name at run time (``importlib.import_module``) only where named below, with
  the reason;
* docs/architecture.md names every module of the package;
* and the step algorithm written once (numeric/stepcore.py).

Every exception is listed here with its reason; the test fails on an exception that is no longer
needed, so that the lists stay true."""
import ast
from pathlib import Path

PKG = Path(__file__).parent.parent / "tableau_lab"
DOC = Path(__file__).parent.parent / "docs" / "architecture.md"

#: the floors, lowest first; a module belongs to the floor of its subpackage, or is named here
#: render (tableau_lab/render/: the document model and one renderer per format) sits on the exact core
#: and under the analyses, whose results build documents from their data and leave the formats to it
FLOORS = ("base", "exact", "render", "analysis", "numeric", "experiments", "faces")
SUBPACKAGE_FLOOR = {"exact": "exact", "render": "render", "analysis": "analysis", "numeric": "numeric",
                    "experiments": "experiments", "proofs": "faces"}
TOP_LEVEL_FLOOR = {
    # the package itself: __version__ and the lazy table of public names; it imports nothing
    # statically, and every module's import runs it first, so it is the lowest floor
    "tableau_lab": "base",
    "tableau_lab.errors": "base",       # error kinds and exit codes: imports nothing
    "tableau_lab.inputs": "base",       # the strict JSON reader: imports nothing of the package
    "tableau_lab.process": "base",      # child-process hygiene: imports nothing of the package
    "tableau_lab.budget": "base",       # time budgets of exact work: errors
    "tableau_lab.files": "base",        # guarded output files: inputs, process, errors
    "tableau_lab.cli": "faces",         # the command line
    "tableau_lab.__main__": "faces",    # python -m tableau_lab: the command line
}

#: modules that look modules up by name at run time (``importlib.import_module``), with the reason
DYNAMIC_LOOKUPS = {
    "tableau_lab": "the public API's lazy table (_LAZY): each public name's module imported on first use, so "
                   "that `import tableau_lab` imports nothing heavy (tests/test_latency.py)",
    "tableau_lab.exact.queries": "THE ONE NAMED INVERSION of the floors: m.order(), m.stability(), ... look the "
                                 "public function up in the package's lazy table at call time, so that a method "
                                 "object offers its analyses (tab completion) while each keeps one definition in "
                                 "its analysis and the exact core imports nothing above it",
    "tableau_lab.numeric.frozen": "generated problem code calls numpy/mpmath/math functions: their modules by "
                                  "name (_HOMES), never a module of the package",
}


def _module_name(path: Path) -> str:
    parts = path.relative_to(PKG.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {_module_name(p): p for p in sorted(PKG.rglob("*.py"))}


def _is_private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


class _Imports(ast.NodeVisitor):
    """The package modules one module imports (at any depth), the private names it takes from
    them, and its run-time lookups by name."""

    def __init__(self, module: str, is_package: bool):
        self.module = module
        self.package = module if is_package else module.rpartition(".")[0]
        self.edges: set[str] = set()
        self.private: set[tuple[str, str]] = set()      # (module, name)
        self.bound: dict[str, str] = {}                  # local name -> package module it is bound to
        self.dynamic = False

    def _absolute(self, node: ast.ImportFrom) -> str:
        if not node.level:
            return node.module or ""
        base = self.package
        for _ in range(node.level - 1):
            base = base.rpartition(".")[0]
        return f"{base}.{node.module}" if node.module else base

    def visit_ImportFrom(self, node):
        target = self._absolute(node)
        for alias in node.names:
            sub = f"{target}.{alias.name}"
            if sub in MODULES:                            # from package import module
                self.edges.add(sub)
                self.bound[alias.asname or alias.name] = sub
            elif target in MODULES:
                self.edges.add(target)
                if _is_private(alias.name):
                    self.private.add((target, alias.name))

    def visit_Import(self, node):
        for alias in node.names:
            if alias.name in MODULES:
                self.edges.add(alias.name)
                if alias.asname:
                    self.bound[alias.asname] = alias.name

    def visit_Call(self, node):
        func = node.func
        name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
        if name in ("import_module", "__import__"):
            self.dynamic = True
        self.generic_visit(node)

    def attribute_access(self, tree):
        """``m._x`` on a name bound to a package module (after the whole file is visited)."""
        for node in ast.walk(tree):
            if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
                    and node.value.id in self.bound and _is_private(node.attr)):
                self.private.add((self.bound[node.value.id], node.attr))


def _scan():
    out = {}
    for mod, path in MODULES.items():
        tree = ast.parse(path.read_text())
        v = _Imports(mod, path.name == "__init__.py")
        v.visit(tree)
        v.attribute_access(tree)
        v.edges.discard(mod)
        out[mod] = v
    return out


SCAN = _scan()


def _floor(mod: str) -> str | None:
    """The floor of a module (None: not placed yet)."""
    if mod in TOP_LEVEL_FLOOR:
        return TOP_LEVEL_FLOOR[mod]
    parts = mod.split(".")
    return SUBPACKAGE_FLOOR.get(parts[1]) if len(parts) >= 2 else None


def test_every_module_has_a_floor():
    unplaced = sorted(m for m in MODULES if _floor(m) is None)
    assert not unplaced, f"place these in SUBPACKAGE_FLOOR or TOP_LEVEL_FLOOR (and docs/architecture.md): {unplaced}"


def _strongly_connected(graph: dict) -> list[list[str]]:
    """Tarjan's strongly connected components (iteratively: no recursion limit)."""
    index, low, on, stack, comps, counter = {}, {}, set(), [], [], [0]
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    comps.append(sorted(comp))
    return comps


def test_the_scan_sees_the_package():
    """The scan is not vacuous: it finds the modules, their imports (also inside functions) and
    the floors of all of them."""
    assert len(MODULES) > 90 and "tableau_lab.exact.real_roots" in MODULES
    assert "tableau_lab.exact.real_roots" in SCAN["tableau_lab.analysis.stability"].edges
    assert "tableau_lab.analysis.symplectic" in SCAN["tableau_lab.analysis.stability"].edges   # inside a function
    assert {_floor(m) for m in MODULES} == set(FLOORS)


def test_strongly_connected_components_of_a_known_graph():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a", "d"}, "d": set(), "e": {"e"}}
    assert sorted(_strongly_connected(graph)) == [["a", "b", "c"], ["d"], ["e"]]


def test_no_import_cycles():
    graph = {m: SCAN[m].edges for m in MODULES}
    cycles = [c for c in _strongly_connected(graph) if len(c) > 1]
    assert not cycles, "import cycles (strongly connected components): " + "; ".join(map(str, cycles))


def test_no_floor_reaches_up():
    rank = {f: i for i, f in enumerate(FLOORS)}
    rank[None] = -1                   # an unplaced module fails test_every_module_has_a_floor
    up = sorted((m, t) for m in MODULES for t in SCAN[m].edges if rank[_floor(t)] > rank[_floor(m)])
    assert not up, "\n".join(f"{m} ({_floor(m)}) imports {t} ({_floor(t)})" for m, t in up)


def test_exact_core_imports_nothing_above_it():
    """The exact core's imports stay in exact/ and the base floor (exact/queries.py's by-name
    lookup is the one named inversion, DYNAMIC_LOOKUPS)."""
    for m in MODULES:
        if _floor(m) == "exact":
            assert all(_floor(t) in ("base", "exact") for t in SCAN[m].edges), (m, SCAN[m].edges)


def test_no_private_name_crosses_a_module():
    found = {(m, t, name) for m in MODULES for t, name in SCAN[m].private}
    assert found == set(), sorted(found)


def test_lookups_by_name_are_the_named_ones():
    assert {m for m in MODULES if SCAN[m].dynamic} == set(DYNAMIC_LOOKUPS)


def test_architecture_doc_names_every_module():
    """docs/architecture.md names each module by its path in the package (``exact/real_roots.py``,
    ``cli.py``)."""
    text = DOC.read_text()
    missing = [p.relative_to(PKG).as_posix() for p in MODULES.values()
               if f"`{p.relative_to(PKG).as_posix()}`" not in text]
    assert not missing, f"docs/architecture.md does not name: {missing}"


def test_step_algorithm_written_once():
    core = {"newton_stages", "split_stages", "rescue_stages", "fallback_stages", "project", "finish_step",
            "explicit_stages", "lu_factor", "lu_solve", "converged", "predict", "run", "rescue_step"}
    where = {}
    for p in (PKG / "numeric").rglob("*.py"):
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, ast.FunctionDef) and node.name in core:
                where.setdefault(node.name, []).append(p.relative_to(PKG).as_posix())
    assert set(where) == core
    assert all(files == ["numeric/stepcore.py"] for files in where.values()), where
    # and no loop kept as a string literal any more
    for p in (PKG / "numeric").rglob("*.py"):
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, ast.Constant) and isinstance(node.value, str):
                assert "def newton_" not in node.value and "def run_(" not in node.value, p
