"""ema fleet on a small archive: every window answered once, resumable; and ema history's prognosis plot."""

import csv
import json

import pytest

from ema.cli.main import EXIT_BAD_INPUT, EXIT_OK, main
from ema.cli.workers import Documents
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import THESIS
from ema.model.params import HealthParams
from ema.model.window import window_to_dict

SIZES = ["--sims", "16", "--checks", "8", "--timesteps", "50", "--hidden", "8"]


@pytest.fixture
def archive(tmp_path):
    folder = tmp_path / "archive"
    folder.mkdir()
    for a in range(2):
        for w in range(3):
            window = synthetic_window(HealthParams.single(), seed=10 * a + w, duration_s=0.1, actuator_id=f"tail-{a}")
            (folder / f"{a}-{w}.json").write_text(json.dumps({**window_to_dict(window), "window_id": f"w{w}"}))
    (folder / "9-hold.json").write_text(
        json.dumps(
            {**window_to_dict(window), "window_id": "hold", "signals": {k: [0.0] * 1000 for k in window.signals}}
        )
    )
    return folder


def _rows(path):
    with path.open() as handle:
        return list(csv.DictReader(handle))


def test_local_workers_answer_every_window_once_resume_and_say_where_the_time_went(archive, tmp_path, capsys):
    out, database = tmp_path / "results.csv", tmp_path / "history.sqlite3"
    arguments = ["fleet", str(archive), "--out", str(out), "--workers", "2", "--database", str(database), *SIZES]
    assert main([*arguments, "--json"]) == EXIT_OK
    summary = json.loads(capsys.readouterr().out)
    assert summary["engine"] == "local processes" and summary["answered"] == 6 and summary["refused"] == 1
    phases = summary["phases_s"]
    assert phases["start-up"] > 0 and phases["windows"] >= phases["writing"] >= 0
    assert abs(phases["start-up"] + phases["windows"] - summary["seconds"]) < 1e-6
    rows = _rows(out)
    assert len(rows) == 7 and len({(r["actuator_id"], r["window_id"]) for r in rows}) == 7
    assert main([*arguments, "--verbose"]) == EXIT_OK  # rerun: nothing twice
    printed = capsys.readouterr().out
    assert "7 already in" in printed and "time: start-up" in printed and len(_rows(out)) == 7


def test_one_worker_runs_in_process_and_skips_a_bad_file(archive, tmp_path, capsys):
    (archive / "5-broken.json").write_text("{not json")
    out = tmp_path / "results.csv"
    assert main(["fleet", str(archive), "--out", str(out), "--workers", "1", "--json", *SIZES]) == EXIT_OK
    captured = capsys.readouterr()
    summary = json.loads(captured.out)
    assert summary["engine"] == "in-process" and summary["answered"] == 6
    assert list(summary["bad_files"]) == [str(archive / "5-broken.json")] and "5-broken.json" in captured.err
    assert "[7/7]" in captured.err and "windows/s" in captured.err  # progress: done, rate, time left


def test_a_rerun_left_with_one_window_answers_it_in_process(archive, tmp_path, capsys):
    """Every window but one answered already: nothing to share out, so no worker process starts for it."""
    out = tmp_path / "results.csv"
    arguments = ["fleet", str(archive), "--out", str(out), "--workers", "2", "--json", *SIZES]
    assert main(arguments) == EXIT_OK
    rows = _rows(out)
    with out.open("w", newline="") as handle:  # the run stopped before its last window's row
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows[:-1])
    capsys.readouterr()
    assert main(arguments) == EXIT_OK
    summary = json.loads(capsys.readouterr().out)
    assert summary["engine"] == "in-process: one window" and summary["skipped"] == 6 and len(_rows(out)) == 7


def test_a_pool_that_never_had_a_job_forks_no_worker_and_stops_at_once():
    """Nothing left to answer, or an archive that cannot be read: no worker was forked, and closing waits for no
    loading (the fork server is stopped at once); the one-worker path loads nothing."""
    import multiprocessing.forkserver
    import subprocess
    import sys

    from ema.cli.pool import LocalWorkers

    pool = LocalWorkers(2, 1)
    pool.close()
    assert not pool.pool._processes  # none forked: nothing to stop, nothing to wait for
    assert multiprocessing.forkserver._forkserver._forkserver_pid is None  # type: ignore[attr-defined]
    nothing = "from ema.cli.workers import in_process; import sys; list(in_process([], None, 1, None)); "
    script = nothing + "print('scipy.optimize' in sys.modules)"
    loaded = subprocess.run([sys.executable, "-c", script], capture_output=True)
    assert loaded.stdout.decode().strip() == "False"


def test_the_fork_server_loads_the_pipeline_with_its_collector_set_and_nothing_else_loads_its_module():
    """``ema.cli.fork_server`` is the fork server's program: importing it sets the collector, then loads the
    pipeline's (the network's among them) and the kernels' modules (its workers hold them from their start); no
    module of ema imports it."""
    import pathlib
    import subprocess
    import sys

    from ema.cli import pool
    from ema.model.collector import YOUNG_COLLECTION

    assert pool.PRELOADED == ("ema.cli.fork_server",)
    script = "import gc, sys; import ema.cli.fork_server; print(gc.get_threshold()[0], 'scipy.optimize' in sys.modules)"
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    assert done.stdout.split() == [str(YOUNG_COLLECTION), "True"]
    package = pathlib.Path(pool.__file__).parents[1]
    importers = [
        path.name
        for path in package.rglob("*.py")
        if "import ema.cli.fork_server" in (text := path.read_text()) or "fork_server import" in text
    ]
    assert importers == []


def test_a_cluster_without_ray_says_how_to_install_it_and_writes_nothing(archive, tmp_path, capsys, monkeypatch):
    from ema.cli import fleet

    monkeypatch.setattr(fleet, "ray_installed", lambda: False)
    out = tmp_path / "results.csv"
    assert main(["fleet", str(archive), "--out", str(out), "--ray-address", "auto"]) == EXIT_BAD_INPUT
    assert "--ray-address" in (err := capsys.readouterr().err) and "pip install 'ema[fleet]'" in err
    assert not out.exists()


@pytest.mark.slow
def test_a_local_worker_killed_mid_run_loses_no_window_and_duplicates_none(tmp_path):
    """Two local worker processes; one is killed once two windows are answered: its windows go to a new pool."""
    import os
    import signal
    import threading
    import time

    from ema.cli.fleet import run_fleet
    from ema.cli.pool import LocalWorkers
    from ema.estimate.config import PipelineConfig

    windows = [
        synthetic_window(HealthParams.single(), seed=i, duration_s=0.1, actuator_id=f"tail-{i % 2}", window_id=f"w{i}")
        for i in range(12)
    ]
    out, pool = tmp_path / "results.csv", LocalWorkers(2, 1)
    killed_at: list[int] = []

    def kill_when_two_answered() -> None:
        while not out.exists() or len(_rows(out)) < 2:
            time.sleep(0.02)
        killed_at.append(len(_rows(out)))
        os.kill(next(iter(pool.pool._processes)), signal.SIGKILL)

    killer = threading.Thread(target=kill_when_two_answered, daemon=True)
    killer.start()
    small = PipelineConfig(n_simulations=16, check_simulations=8, n_timesteps=50, hidden_units=8)
    summary = run_fleet(windows, out, config=small, workers=2, address=None, pool=pool)
    killer.join(timeout=5)
    assert killed_at and killed_at[0] < len(windows)  # the worker died with windows still to answer
    rows = _rows(out)
    assert sorted(r["window_id"] for r in rows) == sorted(w.window_id for w in windows)  # each once
    assert summary["answered"] == len(windows)


def test_windows_wanting_what_others_read_are_answered_with_it(tmp_path, capsys):
    """Their files first in the archive: a 0.1 s gust moving one way (current 0.2 A off) waits for the cruise
    window of its flight (a window of another flight does not take that zero), and so does one moving both ways
    that reads the zero less precisely (0.10 A alone), as the service answers it; a doublet that cannot tell
    J_M 1.08x from a weaker motor waits for the thesis window of its actuator."""
    from ema.history.open import open_history
    from tests.foreign.windows import Effects, draw, of_the_same_flight

    folder, database = tmp_path / "archive", tmp_path / "history.sqlite3"
    folder.mkdir()
    one_way = draw(318, "gust", duration_s=0.1, effects=Effects(current_bias_a=0.2))
    cruise, both_ways = of_the_same_flight(one_way, 1318), of_the_same_flight(one_way, 2318, "gust", 0.1)
    flights = (("a", one_way, "f-1"), ("a2", both_ways, "f-1"), ("b", cruise, "f-1"), ("c", one_way, "f-2"))
    for name, drawn, flight_id in flights:
        document = {**drawn.document, "actuator_id": "tail-9", "flight_id": flight_id, "window_id": name}
        (folder / f"{name}.json").write_text(json.dumps(document))
    heavier = draw(403, "doublet", effects=Effects(inertia_factor=1.08))
    for name, drawn in (("d", heavier), ("e", of_the_same_flight(heavier, 1403, "thesis", 0.5))):
        (folder / f"{name}.json").write_text(json.dumps({**drawn.document, "actuator_id": "tail-8", "window_id": name}))
    arguments = ["fleet", str(folder), "--out", str(tmp_path / "r.csv"), "--workers", "1", "--database", str(database)]
    assert main([*arguments, *SIZES, "--json"]) == EXIT_OK
    answers = {s.window_id: s.window for s in open_history(database).history("tail-9")[0]}
    cruise_pieces = {name for name in answers if name.startswith("b#")}  # the archive's windows are cut
    assert answers["a"].sensor_zero_from in cruise_pieces and answers["c"].sensor_zero_from is None
    assert answers["a2"].sensor_zero_from in cruise_pieces and answers["a2"].sensor_zero is None
    drive = {s.window_id: s.window for s in open_history(database).history("tail-8")[0]}
    assert drive["d"].inertia_from == ["e"] and not drive["d"].inertia_undecided
    count = len(answers) + len(drive)
    assert f"[{count}/{count}]" in capsys.readouterr().err


def test_history_plots_a_prognosis_whose_interval_holds_the_truth(tmp_path, capsys):
    import numpy as np

    from ema.estimate.config import PipelineConfig
    from ema.estimate.documents import parameter
    from ema.history.open import open_history
    from ema.kinds.rotary.pipeline import estimate_window
    from tests.servers import free_port, start_server

    small = PipelineConfig(n_simulations=16, check_simulations=8, n_timesteps=50, hidden_units=8)
    base = estimate_window(synthetic_window(HealthParams.single(), seed=1, duration_s=0.1), small, actuator=THESIS)
    rng, store = np.random.default_rng(0), open_history(tmp_path / "history.sqlite3")
    hours = np.sort(rng.uniform(0, 200, 200))
    for i, h in enumerate(hours):  # FDJ rising 1e-4 N·m per flight hour: crosses 0.075 at 250 h
        fdj = 0.05 + 1e-4 * h + 4e-4 * rng.normal()
        estimates = base.estimates.model_copy(update={"FDJ": parameter(fdj, 4e-4, 0.05, unit="N·m")})
        window = base.window.model_copy(update={"flight_hours": float(h)})
        store.add(
            base.model_copy(
                update={"estimates": estimates, "window": window, "actuator_id": "tail-9", "window_id": f"w{i}"}
            )
        )
    store.close()
    port = free_port()
    server = start_server(port, tmp_path / "history.sqlite3")
    try:
        plot = tmp_path / "fdj.png"
        arguments = ["history", "tail-9", "--url", f"http://127.0.0.1:{port}", "--plot", str(plot), "--json"]
        assert main(arguments) == EXIT_OK
    finally:
        server.terminate()
        server.wait(timeout=30)
    life = json.loads(capsys.readouterr().out)["prognosis"]["remaining_life"]["FDJ"]
    assert life["status"] == "crossing predicted"
    assert life["rul_low"] <= 250 - hours.max() <= life["rul_high"]
    assert plot.stat().st_size > 10_000


def test_a_flights_windows_are_given_out_once_the_flight_is_answered_not_at_the_runs_end(monkeypatch):
    """The results CSV is the checkpoint: a window waits for its flight's other windows, not for the run."""
    from dataclasses import replace

    from ema.cli import fleet

    monkeypatch.setattr(fleet._Readings, "add", lambda self, window, answer: None)
    monkeypatch.setattr(fleet._Readings, "lacked", lambda self, window, answer, actuator: None)
    base = synthetic_window(HealthParams.single(), seed=1, duration_s=0.05)
    flights = [("f-1", "a"), ("f-1", "b"), (None, "c"), ("f-2", "d"), ("f-2", "e")]
    windows = [replace(base, flight_id=flight, window_id=name) for flight, name in flights]
    consumed: list[str] = []

    def first():
        for window in windows:
            consumed.append(window.window_id)
            yield window, {"window": {}}

    answers = fleet._with_history(windows, first(), lambda jobs: iter(()), Documents())
    given = [(w.window_id, list(consumed)) for w, _ in answers]
    assert given == [
        ("a", ["a", "b"]),
        ("b", ["a", "b"]),
        ("c", ["a", "b", "c"]),
        ("d", ["a", "b", "c", "d", "e"]),
        ("e", ["a", "b", "c", "d", "e"]),
    ]


def test_an_archive_carries_its_actuators_documents(tmp_path, capsys):
    """actuators.json maps an actuator to its document: its windows are read with it (and the history stores
    it, versioned); an actuator it does not list is read with the default, and said so."""
    from ema.history.open import open_history
    from tests.foreign.actuators import DRIVES, NOMINAL, document
    from tests.foreign.windows import Ground, draw

    folder, database = tmp_path / "archive", tmp_path / "history.sqlite3"
    folder.mkdir()
    bench = draw(31, "sweep", drive=DRIVES["smaller"], nominal=NOMINAL["smaller"], flight=Ground(-100.0, 500.0))
    (folder / "a.json").write_text(json.dumps({**bench.document, "actuator_id": "small-1", "window_id": "b"}))
    thesis = synthetic_window(HealthParams.single(), seed=4, duration_s=0.1, actuator_id="thesis-1")
    (folder / "t.json").write_text(json.dumps(window_to_dict(thesis)))
    (folder / "actuators.json").write_text(json.dumps({"small-1": document("smaller")}))
    arguments = ["fleet", str(folder), "--out", str(tmp_path / "r.csv"), "--workers", "1", "--database", str(database)]
    assert main([*arguments, *SIZES, "--json"]) == EXIT_OK
    assert json.loads(capsys.readouterr().out)["answered"] == 2
    store = open_history(database)
    small = store.history("small-1")[0][0]
    assert small.actuator.version == 1 and store.get_actuator("small-1").document.drive.gear_ratio == 800.0
    assert abs(small.estimates.FDJ.value / bench.truth["FDJ"] - 1) < 0.03
    assert store.history("thesis-1")[0][0].actuator.default and store.get_actuator("thesis-1") is None


@pytest.mark.slow
def test_a_node_that_dies_mid_run_loses_no_window_and_duplicates_none(tmp_path):
    """A Ray cluster of two nodes on this machine; the worker node is removed once two windows are answered."""
    import threading
    import time

    import ray
    from ray.cluster_utils import Cluster

    from ema.cli.fleet import run_fleet
    from ema.estimate.config import PipelineConfig
    from ema.history.open import open_history

    windows = [
        synthetic_window(HealthParams.single(), seed=i, duration_s=0.1, actuator_id=f"tail-{i % 2}", window_id=f"w{i}")
        for i in range(12)
    ]
    cluster = Cluster(initialize_head=True, head_node_args={"num_cpus": 1})
    worker = cluster.add_node(num_cpus=1)
    out, database = tmp_path / "results.csv", tmp_path / "history.sqlite3"

    killed_at: list[int] = []

    def kill_when_two_answered() -> None:
        while not out.exists() or len(_rows(out)) < 2:
            time.sleep(0.05)
        killed_at.append(len(_rows(out)))
        cluster.remove_node(worker, allow_graceful=False)

    killer = threading.Thread(target=kill_when_two_answered, daemon=True)
    killer.start()
    try:
        small = PipelineConfig(n_simulations=16, check_simulations=8, n_timesteps=50, hidden_units=8)
        run_fleet(windows, out, config=small, workers=2, address=cluster.address, database=database)
    finally:
        ray.shutdown()
        cluster.shutdown()
    killer.join(timeout=5)
    assert killed_at and killed_at[0] < len(windows)  # the node died with windows still to answer
    rows = _rows(out)
    assert sorted(r["window_id"] for r in rows) == sorted(w.window_id for w in windows)  # each once
    store = open_history(database)
    stored = [s.window_id for a in ("tail-0", "tail-1") for s in store.history(a)[0]]
    assert sorted(stored) == sorted(w.window_id for w in windows)


def test_one_key_in_two_files_is_one_refused_row_naming_both_whatever_the_workers(tmp_path, capsys):
    """Two files hold (tail-0, w1) with different content, a third a copy of one window: the copy is read once,
    the conflicting key from neither, a row naming both files, the same on every run and worker count."""
    folder = tmp_path / "archive"
    folder.mkdir()
    first = synthetic_window(HealthParams.single(), seed=1, duration_s=0.1, actuator_id="tail-0", window_id="w1")
    other = synthetic_window(HealthParams.single(), seed=2, duration_s=0.1, actuator_id="tail-0", window_id="w1")
    kept = synthetic_window(HealthParams.single(), seed=3, duration_s=0.1, actuator_id="tail-0", window_id="w2")
    for name, window in (("a.json", first), ("b.json", other), ("c.json", kept), ("d.json", kept)):
        (folder / name).write_text(json.dumps(window_to_dict(window)))
    for workers in ("1", "2"):
        out = tmp_path / f"r{workers}.csv"
        assert main(["fleet", str(folder), "--out", str(out), "--workers", workers, *SIZES, "--json"]) == EXIT_OK
        rows = _rows(out)
        assert [(r["window_id"], bool(r["error"])) for r in sorted(rows, key=lambda r: r["window_id"])] == [
            ("w1", True),
            ("w2", False),
        ]
        conflict = next(r for r in rows if r["window_id"] == "w1")["error"]
        assert f"{folder / 'a.json'} and {folder / 'b.json'}" in conflict
        assert main(["fleet", str(folder), "--out", str(out), "--workers", workers, *SIZES]) == EXIT_OK
        assert len(_rows(out)) == 2  # a rerun writes the conflict once
    capsys.readouterr()


def test_a_window_refused_under_a_document_since_changed_is_read_again(tmp_path, capsys):
    """A window refused with the wrong actuator document: rerun with the same one, it stays refused and is not
    tried again; rerun once the document is fixed, it is read (a row of its own)."""
    from tests.foreign.actuators import DRIVES, NOMINAL, document
    from tests.foreign.windows import Ground, draw

    folder = tmp_path / "archive"
    folder.mkdir()
    bench = draw(31, "sweep", drive=DRIVES["smaller"], nominal=NOMINAL["smaller"], flight=Ground(-100.0, 500.0))
    (folder / "a.json").write_text(json.dumps({**bench.document, "actuator_id": "small-1", "window_id": "b"}))
    wrong = {**document("smaller"), "kind": "linear", "screw": {"lead_mm": 5.0}}
    wrong.pop("drive", None)
    wrong["nominal"] = {k: v for k, v in wrong["nominal"].items() if k != "fsj_nm"}  # a ball screw reads no FSJ
    (folder / "actuators.json").write_text(json.dumps({"small-1": wrong}))
    out = tmp_path / "r.csv"
    run = ["fleet", str(folder), "--out", str(out), "--workers", "1", *SIZES, "--json"]
    assert main(run) == EXIT_BAD_INPUT  # refused: nothing answered
    assert main(run) == EXIT_OK and len(_rows(out)) == 1  # the same document: not tried again (already in the CSV)
    (folder / "actuators.json").write_text(json.dumps({"small-1": document("smaller")}))
    assert main(run) == EXIT_OK
    rows = _rows(out)
    assert [bool(r["error"]) for r in rows] == [True, False] and rows[0]["document"] != rows[1]["document"]
    capsys.readouterr()


def test_a_fleet_killed_leaves_no_process_running(tmp_path):
    """kill -9 of ema fleet mid-run: its fork server and its workers die with it (``ema.cli.lifeline``)."""
    import os
    import signal
    import subprocess
    import sys
    import time

    folder = tmp_path / "archive"
    folder.mkdir()
    for i in range(40):
        window = synthetic_window(
            HealthParams.single(), seed=i, duration_s=0.1, actuator_id="tail-0", window_id=f"w{i}"
        )
        (folder / f"{i:02d}.json").write_text(json.dumps(window_to_dict(window)))
    out = tmp_path / "r.csv"
    command = [sys.executable, "-m", "ema.cli.main", "fleet", str(folder), "--out", str(out), "--workers", "2", *SIZES]
    driver = subprocess.Popen(command, stderr=subprocess.DEVNULL, stdout=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not (out.exists() and len(_rows(out)) >= 2):
        time.sleep(0.1)
    family = _descendants(driver.pid)
    assert len(family) >= 3  # the fork server and two workers
    os.kill(driver.pid, signal.SIGKILL)
    driver.wait(timeout=30)
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline and any(_alive(pid) for pid in family):
        time.sleep(0.2)
    assert not [pid for pid in family if _alive(pid)]


def _descendants(root: int) -> set[int]:
    """Every process below ``root``, from /proc."""
    from pathlib import Path

    parents = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        parents[int(stat.parent.name)] = int(fields[1])
    found, frontier = set(), {root}
    while frontier:
        frontier = {pid for pid, parent in parents.items() if parent in frontier} - found
        found |= frontier
    return found


def _alive(pid: int) -> bool:
    """Whether ``pid`` runs (a zombie, dead and not yet reaped, does not)."""
    from pathlib import Path

    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"
