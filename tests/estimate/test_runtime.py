"""The process set-up: torch's optimizers run without loading torch's compiler, and learn exactly what they did."""

import json
import subprocess
import sys

ESTIMATE = (
    "import json, sys, torch; from ema.estimate import runtime; from ema.estimate.config import PipelineConfig; "
    "from ema.estimate.pipeline import estimate_window; from ema.model.actuator import THESIS; "
    "from ema.model.params import HealthParams; from ema.model.synthetic import synthetic_window; "
    "{setup}; "
    "config = PipelineConfig(n_simulations=16, check_windows=8, n_timesteps=20, hidden_units=4); "
    "e = estimate_window(synthetic_window(HealthParams.single(), seed=3, duration_s=0.05), config, actuator=THESIS); "
    "print(json.dumps([e.estimates.FDJ.value, e.estimates.FDJ.std, 'torch._dynamo' in sys.modules]))"
)


def _run(setup: str) -> list:
    # A fresh interpreter each: what is imported is process-wide and lasts.
    script = ESTIMATE.format(setup=setup)
    return json.loads(subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout)


def test_a_configured_process_trains_without_torchs_compiler_and_learns_the_same():
    configured = _run("runtime.configure(1)")
    plain = _run("torch.set_num_threads(1); torch.set_num_interop_threads(1)")
    assert configured[2] is False and plain[2] is True  # the guard is what loads the compiler, and it is skipped
    assert configured[:2] == plain[:2]  # bit for bit the same answer


LATE = (
    "import json, sys; from ema.estimate import runtime; runtime.configure(1); loaded = 'torch' in sys.modules; "
    "import torch; from ema.estimate.config import PipelineConfig; from ema.estimate.pipeline import estimate_window; "
    "from ema.model.actuator import THESIS; from ema.model.params import HealthParams; "
    "from ema.model.synthetic import synthetic_window; "
    "config = PipelineConfig(n_simulations=16, check_windows=8, n_timesteps=20, hidden_units=4); "
    "e = estimate_window(synthetic_window(HealthParams.single(), seed=3, duration_s=0.05), config, actuator=THESIS); "
    "print(json.dumps([e.estimates.FDJ.value, e.estimates.FDJ.std, 'torch._dynamo' in sys.modules, loaded, "
    "torch.get_num_threads(), torch.get_num_interop_threads()]))"
)


def test_a_budget_set_before_torch_is_loaded_holds_when_the_learn_stage_loads_it():
    """configure does not load torch (a slow log's reading never needs it); the first training applies its part."""
    late = json.loads(subprocess.run([sys.executable, "-c", LATE], capture_output=True, text=True, check=True).stdout)
    assert late[3] is False and late[2] is False and late[4:] == [1, 1]
    assert late[:2] == _run("runtime.configure(1)")[:2]
