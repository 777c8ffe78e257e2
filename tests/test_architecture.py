"""The house rules of DESIGN.md, measured on the code itself: modules of at most 600 lines, functions
of at most 80 lines of code (the docstring is documentation and does not count), no import circle,
no private name imported across subpackages, matplotlib only at the edge (plot/, reporting/)."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1] / "vibmeasure"
MAX_MODULE_LINES = 600
MAX_FUNCTION_LINES = 80


def modules():
    for p in sorted(ROOT.rglob("*.py")):
        yield p, ast.parse(p.read_text())


def _name(p: Path) -> str:
    parts = list(p.relative_to(ROOT.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _resolve(p: Path, node: ast.ImportFrom) -> str:
    """The absolute module an ``from ... import`` names (relative imports resolved)."""
    if not node.level:
        return node.module or ""
    pkg = _name(p).split(".")
    if p.name != "__init__.py":
        pkg = pkg[:-1]
    base = pkg[:len(pkg) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _type_checking_only(tree) -> set:
    """Import nodes under ``if TYPE_CHECKING:`` (annotations only: no import at run time)."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and getattr(node.test, "id", None) == "TYPE_CHECKING":
            out |= {id(n) for n in ast.walk(node)}
    return out


def test_no_module_is_longer_than_600_lines():
    long = [(str(p.relative_to(ROOT)), n) for p, _ in modules()
            if (n := p.read_text().count("\n")) > MAX_MODULE_LINES]
    assert long == []


def test_no_function_has_more_than_80_lines_of_code():
    long = []
    for p, tree in modules():
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                body = node.body
                doc = isinstance(body[0], ast.Expr) and isinstance(getattr(body[0], "value", None), ast.Constant)
                start = body[1].lineno if doc and len(body) > 1 else body[0].lineno
                if node.end_lineno - start + 1 > MAX_FUNCTION_LINES:
                    long.append(f"{p.relative_to(ROOT)}:{node.name}")
    assert long == []


def test_no_private_name_is_imported_across_subpackages():
    crossing = []
    for p, tree in modules():
        here = _name(p).split(".")
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                there = _resolve(p, node).split(".")
                for a in node.names:
                    private = a.name.startswith("_") and not a.name.startswith("__")
                    if private and len(there) > 1 and (len(here) < 2 or here[1] != there[1]):
                        crossing.append(f"{_name(p)} <- {'.'.join(there)}.{a.name}")
    assert crossing == []


def test_no_import_circle():
    graph: dict = {}
    known = {_name(p) for p, _ in modules()}
    for p, tree in modules():
        skip = _type_checking_only(tree)
        deps = set()
        for node in ast.walk(tree):
            if id(node) in skip:
                continue
            if isinstance(node, ast.ImportFrom):
                mod = _resolve(p, node)
                for a in node.names:
                    sub = f"{mod}.{a.name}"
                    deps.add(sub if sub in known else mod)
            elif isinstance(node, ast.Import):
                deps |= {a.name for a in node.names}
        me = _name(p)
        # a package's __init__ re-exports its modules; a module importing its own package is no circle
        graph[me] = {d for d in deps if d in known and d != me and not me.startswith(d + ".")}
    circles, state = [], {}

    def visit(n, stack):
        state[n] = 1
        for d in graph.get(n, ()):
            if state.get(d) == 1:
                circles.append(stack[stack.index(d):] + [d])
            elif d not in state:
                visit(d, stack + [d])
        state[n] = 2

    for n in sorted(graph):
        if n not in state:
            visit(n, [n])
    assert circles == []


def test_matplotlib_is_imported_only_at_the_edge():
    edge = ("plot", "reporting")
    found = []
    for p, tree in modules():
        parts = p.relative_to(ROOT).parts
        if parts[0] in edge:
            continue
        for node in ast.walk(tree):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                     [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            if any(n.split(".")[0] == "matplotlib" for n in names):
                found.append(str(p.relative_to(ROOT)))
    assert found == []


def test_every_diagnosis_flag_has_its_sentence_and_advice():
    """A flag the diagnosis sets (``flags.append("...")`` or ``_held(flags, "...")``) is shown in a report
    only with its sentence (FLAG_TEXT) and advice (FLAG_ADVICE): fifteen were missing, so a report left
    out ``speed_doubtful`` and the other doubts while the JSON carried them."""
    import re
    from vibmeasure.core.results import FLAG_TEXT
    from vibmeasure.reporting import FLAG_ADVICE
    flags = set()
    for path in (Path(__file__).resolve().parents[1] / "vibmeasure" / "monitor").rglob("*.py"):
        text = path.read_text()
        flags |= set(re.findall(r'flags\.append\("([a-z_0-9]+)"\)', text))
        flags |= set(re.findall(r'_held\([^,]+, "([a-z_0-9]+)"', text))
    assert len(flags) >= 20
    assert sorted(f for f in flags if f not in FLAG_TEXT) == []
    assert sorted(f for f in flags if f not in FLAG_ADVICE) == []
