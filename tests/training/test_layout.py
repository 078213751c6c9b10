"""The estimator's stages import one way: down the pipeline, never up, and the public documents import no
estimator (an HTTP client that reads an estimate loads neither numpy nor Numba)."""

import ast
import subprocess
import sys
from pathlib import Path

TRAINING = Path(__file__).resolve().parents[2] / "training"
# Lowest first: a module may import its own rank or a lower one (shared modules are rank 0).
RANKS = {
    "training.sizes": 0, "training.config": 0, "training.documents": 0, "training.runtime": 0, "training.stats": 0,
    "training.physics": 1, "training.prepare": 2, "training.simulate": 3, "training.learn": 4, "training.assess": 5,
    "training.report": 6, "training.history": 6, "training.pipeline": 7, "training.remote": 8,
}  # fmt: skip


def _rank(module: str) -> int:
    parts = module.split(".")
    for length in range(len(parts), 0, -1):
        if ".".join(parts[:length]) in RANKS:
            return RANKS[".".join(parts[:length])]
    raise AssertionError(f"{module} belongs to no stage")


def _imports(path: Path) -> set[str]:
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("training"):
            found |= {f"{node.module}.{a.name}" if node.module == "training" else node.module for a in node.names}
    return found


def test_every_module_imports_only_its_own_stage_or_lower_ones():
    upward = []
    for path in TRAINING.rglob("*.py"):
        module = ".".join(path.relative_to(TRAINING.parent).with_suffix("").parts).removesuffix(".__init__")
        if module == "training":
            continue
        upward += [f"{module} -> {target}" for target in _imports(path) if _rank(target) > _rank(module)]
    assert upward == []


def test_the_stages_are_subpackages_and_few_modules_remain_at_the_top():
    stages = [p.name for p in TRAINING.iterdir() if (p / "__init__.py").exists()]
    assert {"physics", "prepare", "simulate", "learn", "assess"} <= set(stages)
    assert len([p for p in TRAINING.glob("*.py") if p.name != "__init__.py"]) <= 12


def test_the_documents_load_no_estimator():
    probe = "import sys, training.documents, prognosis.documents; print(sorted(m for m in ('numpy', 'numba', " \
        "'torch', 'training.pipeline', 'training.prepare') if m in sys.modules))"  # fmt: skip
    loaded = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout
    assert loaded.strip() == "['numpy']"  # prognosis's documents compute with numpy; nothing of the estimator
