"""The estimator's stages import one way: down the pipeline, never up, and the public documents import no
estimator (an HTTP client that reads an estimate loads neither numpy nor Numba)."""

import ast
import subprocess
import sys
from pathlib import Path

TRAINING = Path(__file__).resolve().parents[2] / "ema" / "estimate"
# Lowest first: a module may import its own rank or a lower one (shared modules are rank 0).
RANKS = {
    "ema.estimate.sizes": 0,
    "ema.estimate.config": 0,
    "ema.estimate.documents": 0,
    "ema.estimate.thread_budget": 0,
    "ema.estimate.stats": 0,
    "ema.estimate.least_squares": 0,
    "ema.estimate.stopwatch": 0,
    "ema.estimate.profile": 0,
    "ema.kinds.rotary.prepare": 2,
    "ema.estimate.simulate": 3,
    "ema.estimate.learn": 4,
    "ema.estimate.assess": 5,
    "ema.estimate.report": 6,
    "ema.estimate.quasistatic.stretches": 1,
    "ema.estimate.quasistatic.drive_torque": 1,
    "ema.estimate.quasistatic.departure": 0,
    "ema.estimate.quasistatic.slow_window": 7,
}


def _rank(module: str) -> int:
    parts = module.split(".")
    for length in range(len(parts), 0, -1):
        if ".".join(parts[:length]) in RANKS:
            return RANKS[".".join(parts[:length])]
    raise AssertionError(f"{module} belongs to no stage")


def _imports(path: Path) -> set[str]:
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("ema.estimate"):
            found |= {f"{node.module}.{a.name}" if node.module == "ema.estimate" else node.module for a in node.names}
    return found


def test_every_module_imports_only_its_own_stage_or_lower_ones():
    upward = []
    for path in TRAINING.rglob("*.py"):
        module = "ema." + ".".join(path.relative_to(TRAINING.parent).with_suffix("").parts).removesuffix(".__init__")
        if module == "ema.estimate":
            continue
        upward += [f"{module} -> {target}" for target in _imports(path) if _rank(target) > _rank(module)]
    assert upward == []


def test_the_stages_are_subpackages_and_few_modules_remain_at_the_top():
    stages = [p.name for p in TRAINING.iterdir() if (p / "__init__.py").exists()]
    assert {"simulate", "learn", "assess"} <= set(stages)  # prepare and physics: each kind's own (its folder)
    assert len([p for p in TRAINING.glob("*.py") if p.name != "__init__.py"]) <= 12


def test_the_documents_load_no_estimator():
    probe = (
        "import sys, ema.estimate.documents, ema.prognosis.documents; print(sorted(m for m in ('numpy', 'numba', "
        "'scipy.optimize', 'ema.kinds.rotary.pipeline', 'ema.kinds.rotary.prepare') if m in sys.modules))"
    )
    loaded = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout
    assert loaded.strip() == "['numpy']"  # prognosis's documents compute with numpy; nothing of the estimator
