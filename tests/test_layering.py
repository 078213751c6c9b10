"""The package's layers import one way (the README's table): model ← estimate ← calibration ← kinds ← prognosis ←
history ← service ← cli. A module may import its own layer or a lower one, never a higher one, at module level or
inside a function; and no module imports another in a circle at import time."""

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "ema"
RANKS = {"model": 0, "estimate": 1, "calibration": 2, "kinds": 3, "prognosis": 4, "history": 5, "service": 6, "cli": 7}


def _layer(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[0] == "ema" and parts[1] in RANKS else None


def _imported(path: Path) -> set[str]:
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module:
            found |= {node.module} | {f"{node.module}.{a.name}" for a in node.names if node.module == "ema"}
        elif isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
    return found


def test_every_layer_imports_only_its_own_or_lower_ones():
    upward = []
    for path in PACKAGE.rglob("*.py"):
        layer = _layer("ema." + ".".join(path.relative_to(PACKAGE).parts))
        if layer is None:
            continue
        for target in _imported(path):
            other = _layer(target)
            if other is not None and RANKS[other] > RANKS[layer]:
                upward.append(f"{path.relative_to(PACKAGE.parent)} -> {target}")
    assert upward == []


def test_every_subpackage_has_a_layer():
    packages = {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").exists()}
    assert packages == set(RANKS)


def _module(path: Path) -> str:
    return ".".join(("ema", *path.relative_to(PACKAGE).with_suffix("").parts)).removesuffix(".__init__")


def _top_level_imports(path: Path) -> set[str]:
    """The ema modules a file imports when it is imported (its top-level statements)."""
    found = set()
    for node in ast.parse(path.read_text()).body:
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name.startswith("ema.")}
        elif isinstance(node, ast.ImportFrom) and node.module == "ema":
            found |= {f"ema.{a.name}" for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("ema."):
            found.add(node.module)
    return found


def test_no_module_imports_another_in_a_circle():
    modules = {_module(path): path for path in PACKAGE.rglob("*.py")}

    def resolved(target: str) -> str | None:  # a name imported from a package's __init__ may be its submodule
        while target and target not in modules:
            target = target.rpartition(".")[0]
        return target or None

    graph = {
        name: {t for t in map(resolved, _top_level_imports(path)) if t and t != name} for name, path in modules.items()
    }
    state: dict[str, int] = {}  # 1: on the path being walked, 2: done
    cycles: list[list[str]] = []

    def walk(name: str, path: list[str]) -> None:
        state[name] = 1
        for nxt in sorted(graph[name]):
            if state.get(nxt) == 1:
                cycles.append([*path[path.index(nxt) :], nxt])
            elif nxt not in state:
                walk(nxt, [*path, nxt])
        state[name] = 2

    for name in sorted(graph):
        if name not in state:
            walk(name, [name])
    assert cycles == []
