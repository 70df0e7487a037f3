"""The numeric floor's shape, read from its source: no import circles among the numeric,
experiment and face modules (any import, also inside a function, counts; the analyses'
stability ↔ algebraic_stability pair is not yet untangled), and the step algorithm written
once — the stage iterations, the GLM step and the projection are functions of
numeric/stepcore.py and appear nowhere else in numeric/, not even as string literals."""
import ast
from pathlib import Path

PKG = Path(__file__).parent.parent / "tableau_lab"


def _imports(path: Path) -> set:
    """Modules of the package that ``path`` imports (relative and absolute, at any depth)."""
    mod = ".".join(path.relative_to(PKG.parent).with_suffix("").parts)
    package = mod.rsplit(".", 1)[0] if path.name != "__init__.py" else mod
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.rsplit(".", node.level - 1)[0] if node.level > 1 else package
                target = f"{base}.{node.module}" if node.module else base
            else:
                target = node.module or ""
            names = [f"{target}.{a.name}" for a in node.names]
            for t in [target] + names:
                if (PKG.parent / Path(*t.split("."))).with_suffix(".py").exists():
                    out.add(t)
        elif isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name.startswith("tableau_lab")}
    out.discard(mod)
    return out


def test_no_import_circles():
    graph = {".".join(p.relative_to(PKG.parent).with_suffix("").parts): _imports(p) for p in PKG.rglob("*.py")
             if not p.relative_to(PKG).as_posix().startswith("analysis/")}
    cycles = []

    def visit(node, stack, seen):
        for nxt in sorted(graph.get(node, ())):
            if nxt in stack:
                cycles.append(stack[stack.index(nxt):] + [nxt])
            elif nxt not in seen:
                seen.add(nxt)
                visit(nxt, stack + [nxt], seen)
    for start in sorted(graph):
        visit(start, [start], {start})
    assert not cycles, "import circles: " + "; ".join(" -> ".join(c) for c in cycles[:5])


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
