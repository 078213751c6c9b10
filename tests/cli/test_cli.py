import json
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from ema.cli.main import EXIT_BAD_INPUT, EXIT_OK, main
from ema.model.window import read_window

SIZES = ["--sims", "16", "--checks", "8", "--timesteps", "50", "--hidden", "8"]


def test_simulate_writes_a_valid_window_and_the_truth(tmp_path, capsys):
    out, truth = tmp_path / "w.json", tmp_path / "t.json"
    code = main(
        [
            "simulate",
            "--out",
            str(out),
            "--fdj",
            "0.055",
            "--duration",
            "0.05",
            "--truth-out",
            str(truth),
            "--command",
            "cruise",
            "--json",
        ]
    )
    assert code == EXIT_OK
    report = json.loads(capsys.readouterr().out)
    assert report["truth"]["FDJ"] == 0.055 and report["command"] == "cruise"
    assert read_window(out).n_samples == 500
    assert json.loads(truth.read_text())["FDJ"] == 0.055


def test_simulate_names_each_window_by_its_content(tmp_path, capsys):
    """Two windows that differ only in FDJ never share a window_id (a service would answer the second with the
    first's estimates); the same options give the same window, and its name."""
    names = []
    for fdj in ("0.05", "0.06", "0.06"):
        out = tmp_path / f"w{len(names)}.json"
        assert main(["simulate", "--out", str(out), "--fdj", fdj, "--duration", "0.05"]) == EXIT_OK
        names.append(read_window(out).window_id)
    assert names[0] != names[1] and names[1] == names[2] and names[0].startswith("synthetic-")


def test_simulate_and_estimate_another_actuator_on_a_bench(tmp_path, capsys):
    """ema simulate --actuator --ground --load-ramp writes a bench window of that actuator (no flight condition);
    ema estimate --actuator reads it with the same document."""
    from tests.foreign.actuators import document

    actuator = tmp_path / "heavier.json"
    actuator.write_text(json.dumps(document("heavier")))
    window = tmp_path / "bench.json"
    arguments = [
        "simulate",
        "--out",
        str(window),
        "--actuator",
        str(actuator),
        "--ground",
        "--load",
        "-100",
        "--load-ramp",
        "400",
        "--command",
        "cruise",
        "--duration",
        "0.3",
        "--json",
    ]
    assert main(arguments) == EXIT_OK
    written = json.loads(capsys.readouterr().out)
    assert written["truth"]["FDJ"] == 0.08 and written["load"] == "ground" and written["actuator"].startswith("foreign")
    assert json.loads(window.read_text())["flight_condition"] is None and read_window(window).on_ground
    assert main(["estimate", str(window), "--actuator", str(actuator), *SIZES, "--json"]) == EXIT_OK
    result = json.loads(capsys.readouterr().out)
    assert abs(result["estimates"]["FDJ"]["value"] / 0.08 - 1) < 0.03 and result["estimates"]["eta_O"] is not None
    assert main(["estimate", str(window), *SIZES]) == EXIT_BAD_INPUT  # the thesis's document: another gear ratio
    assert "actuator.drive.gear_ratio" in capsys.readouterr().err


def test_simulate_with_an_effect_and_a_table(tmp_path, capsys):
    code = main(
        ["simulate", "--out", str(tmp_path / "w.json"), "--duration", "0.05", "--effect", "cogging:amplitude_nm=0.02"]
    )
    assert code == EXIT_OK
    assert "cogging" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("arguments", "named"),
    [
        (["--altitude", "20000"], "--altitude"),
        (["--effect", "cogging:amplitude_nm=x"], "--effect cogging.amplitude_nm"),
        (["--effect", "cog:amplitude_nm=x"], "--effect: unknown effect 'cog'"),  # the name before its numbers
        (["--effect", "cogging:amp=0.01"], "--effect cogging: unknown parameter(s) ['amp']"),
        (["--effect", "cogging:amplitude_nm=9"], "--effect cogging.amplitude_nm: 9 is outside"),
        (["--rate", "50"], "--rate"),
        (["--command", "loop"], "--command"),
    ],
)
def test_bad_input_exits_2_naming_the_flag_typed(tmp_path, capsys, arguments, named):
    assert main(["simulate", "--out", str(tmp_path / "w.json"), *arguments]) == EXIT_BAD_INPUT
    assert named in capsys.readouterr().err


def test_estimate_prints_one_json_document_and_progress_on_stderr(tmp_path, capsys):
    window = tmp_path / "w.json"
    assert main(["simulate", "--out", str(window), "--duration", "0.1", "--fdj", "0.056"]) == EXIT_OK
    capsys.readouterr()
    assert main(["estimate", str(window), *SIZES, "--json"]) == EXIT_OK
    captured = capsys.readouterr()
    result = json.loads(captured.out)
    assert result["schema"] == "ema-estimate/1" and result["estimates"]["FDJ"]["value"] > 0
    assert "learning" in captured.err


def test_estimate_table_and_bad_inputs(tmp_path, capsys):
    window = tmp_path / "w.json"
    main(["simulate", "--out", str(window), "--duration", "0.1"])
    capsys.readouterr()
    assert main(["estimate", str(window), *SIZES]) == EXIT_OK
    assert "eta_O" in capsys.readouterr().out
    assert main(["estimate", str(window), "--sims", "5"]) == EXIT_BAD_INPUT
    assert "--sims" in capsys.readouterr().err
    (tmp_path / "broken.json").write_text('{"schema": "ema-window/1"}')
    assert main(["estimate", str(tmp_path / "broken.json")]) == EXIT_BAD_INPUT
    assert "broken.json" in capsys.readouterr().err
    assert main(["estimate", str(tmp_path / "missing.json")]) == EXIT_BAD_INPUT


def test_estimate_reads_other_windows_results_as_history_and_names_a_bad_one(tmp_path, capsys):
    window, result = tmp_path / "w.json", tmp_path / "r.json"
    main(["simulate", "--out", str(window), "--duration", "0.1"])
    capsys.readouterr()
    assert main(["estimate", str(window), *SIZES, "--json"]) == EXIT_OK
    document = json.loads(capsys.readouterr().out)
    assert document["window"]["sensor_zero"]["window_id"] == document["window_id"]
    result.write_text(json.dumps(document))
    assert main(["estimate", str(window), *SIZES, "--history", str(result), "--history", str(result)]) == EXIT_OK
    other = tmp_path / "other.json"
    other.write_text(json.dumps({**document, "actuator_id": "another/elevator"}))
    broken = tmp_path / "broken.json"
    broken.write_text(json.dumps(document)[:-40])
    for bad, named in (
        (window, "w.json is not an ema-estimate/1 result (schema: Input should be 'ema-estimate/1')"),  # a window
        (broken, "broken.json cannot be read as JSON"),
        (other, "another/elevator"),
    ):
        assert main(["estimate", str(window), "--history", str(bad)]) == EXIT_BAD_INPUT
        assert "--history" in (err := capsys.readouterr().err) and named in err


def test_calibrate_writes_a_figure_only_when_asked_and_names_a_bad_truth_file(tmp_path, capsys, monkeypatch):
    window, truth = tmp_path / "w.json", tmp_path / "t.json"
    main(["simulate", "--out", str(window), "--duration", "0.15", "--truth-out", str(truth)])
    capsys.readouterr()
    monkeypatch.chdir(tmp_path)
    arguments = ["calibrate", str(window), "--truth", str(truth), "--copies", "8", *SIZES]
    assert main([*arguments, "--json"]) == EXIT_OK
    assert json.loads(capsys.readouterr().out)["figure"] is None
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.json", "w.json"]  # nothing written unasked
    figure = tmp_path / "cal.png"
    assert main([*arguments, "--figure", str(figure), "--json"]) == EXIT_OK
    captured = capsys.readouterr()
    report = json.loads(captured.out)
    assert report["schema"] == "ema-calibration/1" and figure.stat().st_size > 1000
    assert "noise-only copies" in captured.err  # progress on stderr
    (tmp_path / "bad.json").write_text("{}")
    assert main(["calibrate", str(window), "--truth", str(tmp_path / "bad.json"), *SIZES]) == EXIT_BAD_INPUT
    assert "bad.json" in capsys.readouterr().err


def test_help_is_quick_and_version_is_printed():
    # Quick because it loads none of the heavy libraries (a wall-clock bound flaked on a busy machine).
    probe = "\n".join(
        [
            "import sys",
            "from ema.cli.main import main",
            "try:",
            "    main(['--help'])",
            "except SystemExit:",
            "    pass",
            "print('loaded:', sorted(m for m in ('scipy.optimize', 'numba', 'numpy', 'pydantic') if m in sys.modules))",
        ]
    )
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    assert "estimate" in done.stdout and done.stdout.rstrip().endswith("loaded: []"), done.stdout[-200:]
    version = subprocess.run([sys.executable, "-m", "ema.cli.main", "--version"], capture_output=True, text=True)
    assert version.stdout.startswith("ema ")


def test_a_closed_pipe_and_an_interrupt_end_quietly(tmp_path):
    command = f"{sys.executable} -m ema.cli.main simulate --out {tmp_path / 'w.json'} --duration 0.05 | head -1"
    done = subprocess.run(["bash", "-o", "pipefail", "-c", command], capture_output=True, text=True)
    assert done.returncode == 0 and "Traceback" not in done.stderr
    # The largest dataset, interrupted once its first stage is announced: a fixed sleep raced both the
    # start-up (an interrupt during imports) and a job that finished first on a busy machine.
    job = [sys.executable, "-m", "ema.cli.main", "estimate", str(tmp_path / "w.json"), "--sims", "4000"]
    process = subprocess.Popen(job, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    assert process.stderr is not None
    announced = [process.stderr.readline() for _ in range(3)]  # preparing, fitting, simulating
    assert "simulating" in announced[-1], announced
    process.send_signal(2)  # SIGINT: Ctrl-C
    _, err = process.communicate(timeout=60)
    assert process.returncode == 130 and "Traceback" not in err, err


def test_schemas_in_docs_match_the_code():
    from pathlib import Path

    from ema.cli.schema_export import export

    assert export(Path(__file__).resolve().parents[2] / "docs" / "schemas", check=True) == []


@pytest.mark.parametrize(
    ("arguments", "environment", "named"),
    [
        ([], {"EMA_API_KEY": ""}, "EMA_API_KEY"),
        (["--host", "0.0.0.0"], {}, "EMA_HOST"),
        (["--database", "/proc/no-such-folder/h.sqlite3"], {}, "h.sqlite3"),
    ],
)
def test_serve_refuses_unsafe_or_unusable_settings_naming_them(
    tmp_path, capsys, monkeypatch, arguments, environment, named
):
    monkeypatch.delenv("EMA_API_KEY", raising=False)
    for key, value in environment.items():
        monkeypatch.setenv(key, value)
    assert main(["serve", "--database", str(tmp_path / "h.sqlite3"), *arguments]) == EXIT_BAD_INPUT
    assert named in capsys.readouterr().err


@pytest.mark.parametrize(
    ("variable", "said"),
    [("EMA_DATABSE", ": did you mean EMA_DATABASE?"), ("EMA_PIPELINE__SIMS", " (docs/service.md lists them)")],
)
def test_serve_refuses_an_environment_variable_that_names_no_setting(tmp_path, capsys, monkeypatch, variable, said):
    """Ignored, it would run a default the operator meant to replace (another history, fewer simulations)."""
    monkeypatch.setenv(variable, "64")
    with socket.create_server(("127.0.0.1", 0)) as taken:  # a variable let through is refused here, never served
        port = str(taken.getsockname()[1])
        assert main(["serve", "--database", str(tmp_path / "h.sqlite3"), "--port", port]) == EXIT_BAD_INPUT
    assert f"{variable}: is no setting of the service{said}" in capsys.readouterr().err


def test_serve_names_a_short_key_file_and_a_port_in_use(tmp_path, capsys, monkeypatch):
    monkeypatch.delenv("EMA_API_KEY", raising=False)
    key = tmp_path / "key"
    key.write_text("short")
    assert main(["serve", "--database", str(tmp_path / "h.sqlite3"), "--api-key-file", str(key)]) == EXIT_BAD_INPUT
    assert "--api-key-file" in (err := capsys.readouterr().err) and "16" in err
    with socket.create_server(("127.0.0.1", 0)) as taken:
        port = str(taken.getsockname()[1])
        assert main(["serve", "--database", str(tmp_path / "h.sqlite3"), "--port", port]) == EXIT_BAD_INPUT
    assert "--port" in capsys.readouterr().err


def test_schemas_are_written_only_where_asked(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["schemas"]) == EXIT_BAD_INPUT and "--out" in capsys.readouterr().err
    assert not (tmp_path / "docs").exists()
    assert main(["schemas", "--check"]) == EXIT_OK  # the repository's, where this ema was installed from
    assert not (tmp_path / "docs").exists()
    monkeypatch.chdir(Path(__file__).resolve().parents[2])
    assert main(["schemas", "--check"]) == EXIT_OK  # the repository's own, alone
    assert main(["schemas", "--out", str(tmp_path / "s")]) == EXIT_OK
    assert (tmp_path / "s" / "ema-window-1.json").exists()


def test_serve_refuses_a_file_that_is_not_a_database(tmp_path, capsys):
    broken = tmp_path / "broken.sqlite3"
    broken.write_text("not a database" * 100)
    assert main(["serve", "--database", str(broken)]) == EXIT_BAD_INPUT
    assert "broken.sqlite3" in capsys.readouterr().err
    assert broken.read_text().startswith("not a database")


def test_simulate_stamps_a_time_and_draws_a_degrading_series(tmp_path, capsys):
    from ema.model.window import read_window

    one = tmp_path / "one.json"
    assert (
        main(
            [
                "simulate",
                "--out",
                str(one),
                "--duration",
                "0.05",
                "--recorded-at",
                "2026-11-01T08:00:00",
                "--flight-hours",
                "120",
            ]
        )
        == EXIT_OK
    )
    window = read_window(one)
    assert window.recorded_at == "2026-11-01T08:00:00+00:00" and window.flight_hours == 120.0
    folder = tmp_path / "series"
    args = [
        "simulate",
        "--out",
        str(folder),
        "--duration",
        "0.05",
        "--series",
        "4",
        "--every",
        "25",
        "--fdj-end",
        "0.065",
        "--json",
    ]
    capsys.readouterr()
    assert main(args) == EXIT_OK
    result = json.loads(capsys.readouterr().out)
    windows = [read_window(path) for path in sorted(folder.glob("*.json"))]
    assert [w.flight_hours for w in windows] == [0.0, 25.0, 50.0, 75.0]
    assert [t["FDJ"] for t in result["truth"]] == pytest.approx([0.05, 0.055, 0.06, 0.065])
    assert len({w.window_id for w in windows}) == 4


def test_a_first_run_says_it_compiles_and_a_warm_one_says_nothing(tmp_path, capsys, monkeypatch):
    from ema.cli.options import say_if_compiling
    from ema.kinds.rotary.simulator import kernels
    from ema.kinds.rotary.synthetic import synthetic_window
    from ema.model.params import HealthParams

    window = synthetic_window(HealthParams.single(), seed=1, duration_s=0.05)
    cache = kernels.run_group._cache._cache_file  # type: ignore[attr-defined]
    monkeypatch.setattr(cache, "_index_path", str(tmp_path / "absent.nbi"))
    say_if_compiling([window])
    assert "compiling the simulation kernels" in capsys.readouterr().err
    (tmp_path / "absent.nbi").write_bytes(b"")
    say_if_compiling([window])
    assert capsys.readouterr().err == ""


EMPS = Path(__file__).resolve().parents[2] / "examples" / "emps"


def test_each_command_says_the_kinds_it_serves_from_their_facts(capsys):
    from ema.model.kinds import KINDS, kinds_with

    assert main(["estimate", "--help"]) == EXIT_OK
    assert main(["estimate", "--help"]) == EXIT_OK  # asked twice in one process: said once each time
    said = capsys.readouterr().out
    assert all(said.count(f"{name}: {kind.summary}") == 2 for name, kind in KINDS.items())
    assert main(["simulate", "--help"]) == EXIT_OK
    said = capsys.readouterr().out
    assert [name for name in KINDS if f"{name}: " in said] == list(kinds_with("simulated")) == ["rotary"]


def test_another_kind_s_log_without_its_document_or_with_a_flag_it_has_not_is_named(tmp_path, capsys):
    log = [str(EMPS / "DATA_EMPS.mat"), "--log-map", str(EMPS / "log-map.json")]
    assert main(["estimate", *log]) == EXIT_BAD_INPUT  # a servo's log: the thesis's document is no default for it
    said = capsys.readouterr().err
    assert "--actuator: is needed" in said and "servo" in said
    out = tmp_path / "w.json"
    assert main(["simulate", "--out", str(out), "--actuator", str(EMPS / "actuator.json")]) == EXIT_BAD_INPUT
    assert "is a servo actuator's document: ema simulate draws rotary windows only" in capsys.readouterr().err
    assert not out.exists()


def test_a_servo_s_calibration_states_its_error_against_any_constant_it_reports(tmp_path, capsys):
    """EMPS's servo: its mass and FDJ compared with a truth (here the values its published identification reads,
    ~95 kg and ~20 N), a name it does not report refused naming the flag, never silently compared with nothing."""
    truth = tmp_path / "truth.json"
    calibrate = [
        "calibrate",
        str(EMPS / "DATA_EMPS.mat"),
        "--log-map",
        str(EMPS / "log-map.json"),
        "--actuator",
        str(EMPS / "actuator.json"),
        "--truth",
        str(truth),
    ]
    truth.write_text('{"mass": 95.0, "FDJ": 20.0, "flight_hours": null}')
    assert main([*calibrate, "--json"]) == EXIT_OK
    report = json.loads(capsys.readouterr().out)
    learned = {entry["name"]: entry["value"] for entry in report["learned"]}
    assert report["error_after"] == pytest.approx(
        {"mass": abs(learned["mass"] - 95.0), "FDJ": abs(learned["FDJ"] - 20)}
    )
    assert set(report["error_before"]) == {"FDJ"}  # the mass has no value before: the document holds none
    assert report["error_pct_after"]["mass"] == pytest.approx(100 * report["error_after"]["mass"] / 95.0)
    assert main(calibrate) == EXIT_OK
    said = capsys.readouterr()
    assert "mass error against the truth: — -> " in said.out and "--truth: not compared" not in said.err
    truth.write_text('{"mass": 95.0, "eta_A": 0.9}')
    assert main(calibrate) == EXIT_OK
    assert "ema: --truth: not compared, the report carries no eta_A" in capsys.readouterr().err
    truth.write_text('{"massa": 95.0}')
    assert main(calibrate) == EXIT_BAD_INPUT
    said = capsys.readouterr().err
    assert "--truth: names massa; this calibration reports" in said and "mass" in said
    truth.write_text('{"FDJ": -20.0}')
    assert main(calibrate) == EXIT_BAD_INPUT
    assert (
        "--truth FDJ: reads -20, where the actuator's document allows ≥ 1e-06: no actuator" in capsys.readouterr().err
    )
