"""The process set-up: the budget goes to the simulator, the network trains on NumPy's one BLAS thread, and no
module of ema imports torch (the network is NumPy and SciPy's)."""

import ast
import json
import subprocess
import sys
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "ema"

ESTIMATE = (
    "import json, sys; from ema.estimate import thread_budget; from ema.estimate.config import PipelineConfig; "
    "from ema.kinds.rotary.pipeline import estimate_window; from ema.model.actuator import THESIS; "
    "from ema.model.params import HealthParams; from ema.kinds.rotary.synthetic import synthetic_window; "
    "thread_budget.configure({threads}); "
    "config = PipelineConfig(n_simulations=16, check_simulations=8, n_timesteps=20, hidden_units=4); "
    "e = estimate_window(synthetic_window(HealthParams.single(), seed=3, duration_s=0.05), config, actuator=THESIS); "
    "from threadpoolctl import threadpool_info; "
    "print(json.dumps([e.estimates.FDJ.value, e.estimates.FDJ.std, e.learned.epochs, "
    "[pool['num_threads'] for pool in threadpool_info() if pool['user_api'] == 'blas'], "
    "sorted(m for m in ('torch', 'tensorflow', 'jax') if m in sys.modules)]))"
)


def _run(threads: int) -> list:
    # A fresh interpreter each: what is imported and the BLAS limit are process-wide and last.
    script = ESTIMATE.format(threads=threads)
    return json.loads(subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout)


def test_a_configured_process_learns_on_one_blas_thread_without_a_framework_whatever_its_budget():
    one, two = _run(1), _run(2)
    assert one[2] > 0  # a network was trained
    assert one[3] and set(one[3]) == {1} and set(two[3]) == {1}  # every BLAS loaded, SciPy's too, on one thread
    assert one[4] == two[4] == []
    assert one[:3] == two[:3]  # the budget changes who computes, never the answer


def test_no_module_of_ema_imports_torch():
    importers = []
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else []
            if isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module]
            if any(name.split(".")[0] == "torch" for name in names):
                importers.append(str(path.relative_to(PACKAGE)))
    assert importers == []
