"""The process's one thread budget: the simulator's pool, and NumPy's BLAS on one thread."""

import os
import subprocess
import sys
import tempfile

import pytest


def test_configure_puts_every_blas_numpy_loaded_on_one_thread():
    # A fresh interpreter: the limit is process-wide and lasts, so it is not set inside the test run.
    script = (
        "import numpy as np; from threadpoolctl import threadpool_info; from ema.model import runtime; "
        "np.linalg.lstsq(np.eye(3), np.ones(3), rcond=None); "
        "runtime.configure_simulator(2); "
        "blas = [p for p in threadpool_info() if p['user_api'] == 'blas']; "
        "print(len(blas), max(p['num_threads'] for p in blas), runtime.threads())"
    )
    found = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout.split()
    assert int(found[0]) >= 1 and found[1:] == ["1", "2"]  # a BLAS found, on one thread; the pool on two


def test_a_kernel_run_without_configure_is_compiled_interleaved():
    """Whoever runs a kernel first compiles it into the shared cache: the dispatchers set the compiler's options
    before any kernel they run, configured or not (``runtime.compiler_options``)."""
    script = (
        "import numpy as np; from ema.model import runtime; "
        "runtime.run_rows(lambda a, b: None, 1); print(runtime._BUDGET.interleaved)"
    )
    found = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout
    assert found.strip() == "True"


def test_map_on_pool_keeps_the_items_order_and_raises_a_pieces_error():
    from ema.model import runtime
    from ema.model.checks import InputError

    before = runtime.threads()
    try:
        for threads in (1, 2):
            runtime.set_threads(threads)
            assert runtime.map_on_pool(lambda x: x * x, list(range(7))) == [x * x for x in range(7)]

            def fails_on_three(x: int) -> int:
                if x == 3:
                    raise InputError("x", "three")
                return x

            with pytest.raises(InputError, match="three"):
                runtime.map_on_pool(fails_on_three, [1, 2, 3, 4])
    finally:
        runtime.set_threads(before)


def test_the_collector_is_set_by_the_program_that_starts_never_at_import():
    """Importing ema (its CLI, its simulator) leaves the collector as Python set it; the entry points' one call
    collects the youngest generation less often, the older ones as they were."""
    import json

    from ema.model.collector import YOUNG_COLLECTION

    script = (
        "import gc, json; before = gc.get_threshold(); import ema.cli.main, ema.model.runtime as r; "
        "imported = gc.get_threshold(); r.configure_simulator(1); "
        "print(json.dumps([before, imported, gc.get_threshold()]))"
    )
    found = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout
    before, imported, configured = json.loads(found)
    assert imported == before and configured == [YOUNG_COLLECTION, *before[1:]]


NESTED = """
from ema.model import runtime

def rows_squared(n):
    out = [0] * n
    runtime.run_rows(lambda a, b: out.__setitem__(slice(a, b), [i * i for i in range(a, b)]), n)
    return out

runtime.set_threads(2)
found = runtime.map_on_pool(lambda x: runtime.map_on_pool(rows_squared, [x, x + 20]), [16, 32, 48])
assert found == [[[i * i for i in range(n)] for n in (x, x + 20)] for x in (16, 32, 48)], found
"""


def test_work_the_pool_runs_may_use_the_pool_again_without_waiting_for_ever():
    """Each of the two pool threads maps (and splits rows) again: done in the pool thread itself, not queued
    behind the two threads that wait for it. In a process of its own, so that a deadlock fails the test."""
    try:
        done = subprocess.run([sys.executable, "-c", NESTED], capture_output=True, text=True, timeout=60)
    except subprocess.TimeoutExpired:
        pytest.fail("the nested map waited for ever")
    assert done.returncode == 0, done.stderr


@pytest.mark.slow
def test_the_interleaved_lane_loop_computes_what_the_plain_one_does():
    """``configure_simulator`` has LLVM interleave three vectors of lanes an iteration: the same arithmetic per lane, so
    48 lanes record what one lane at a time records, and what a kernel compiled without the option records
    (each process compiles afresh in a cache of its own: the plain kernel never reaches the shared cache)."""
    script = (
        "import sys, numpy as np; from ema.model import runtime; from ema.model.actuator import THESIS; "
        "from ema.kinds.rotary.simulator.batch import simulate_batch; "
        "from ema.kinds.rotary.simulator.commands import random_command_knots; "
        "from ema.model.params import DEFAULT_RANGES, HealthParams; "
        "runtime.configure_simulator(1) if sys.argv[1] == 'configured' "
        "else setattr(runtime._BUDGET, 'compiler_set', True); "
        "rng = np.random.default_rng(5); health = HealthParams.uniform(48, DEFAULT_RANGES, rng); "
        "knots = random_command_knots(300, 10_000.0, rng)[0]; "
        "runs = [simulate_batch(knots, health, lanes=k, drive=THESIS.params) for k in (48, 1)]; "
        "np.save(sys.argv[2], np.stack([np.stack([r.loss_torque_nm, *r.signals.values()]) for r in runs]))"
    )
    import numpy as np

    recorded = {}
    for mode in ("configured", "plain"):
        path = f"{tempfile.mkdtemp()}/{mode}.npy"
        cache = {"NUMBA_CACHE_DIR": tempfile.mkdtemp()}
        subprocess.run([sys.executable, "-c", script, mode, path], check=True, env={**os.environ, **cache})
        recorded[mode] = np.load(path)
    assert np.array_equal(recorded["configured"][0], recorded["configured"][1])  # 48 lanes == 1 lane at a time
    assert np.array_equal(recorded["configured"], recorded["plain"])
