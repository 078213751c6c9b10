"""Every benchmark still imports: one that only runs on request can rot unseen behind a changed API
(``benchmarks.foreign_history`` imported a ``Thresholds`` the prognosis no longer had, and did not run)."""

import importlib
from pathlib import Path

import pytest

MODULES = sorted(
    p.stem for p in (Path(__file__).resolve().parents[2] / "benchmarks").glob("*.py") if p.stem != "__init__"
)


@pytest.mark.parametrize("name", MODULES)
def test_the_benchmark_imports(name):
    module = importlib.import_module(f"benchmarks.{name}")
    assert module.__doc__, f"benchmarks/{name}.py says what it measures"
