"""Each kind is declared in one place: its facts in ema.model.kinds, its method in its module of ema.kinds; nothing
else compares a kind with a literal or tells one by a signal's name; and a kind whose windows train no network
never has the network's modules (SciPy's optimizers) loaded for them."""

import ast
import csv
import json
from pathlib import Path

from ema.cli.main import EXIT_OK, main
from ema.kinds import REGISTRY
from ema.model import kinds as facts

PACKAGE = Path(__file__).resolve().parents[2] / "ema"
OWN = {PACKAGE / "model" / "kinds.py"}  # beside each kind's own folder (``_in_a_kinds_folder``)
SIGNALS = {name for kind in facts.KINDS.values() for name in kind.all_signals}


def _in_a_kinds_folder(path: Path) -> bool:
    parts = path.relative_to(PACKAGE).parts
    return len(parts) > 2 and parts[0] == "kinds" and parts[1] in facts.KINDS


def _shared_modules() -> list[Path]:
    """Every module of the package outside a kind's folder (the registry, ``ema/kinds/__init__.py``, included)."""
    return [path for path in sorted(PACKAGE.rglob("*.py")) if not _in_a_kinds_folder(path)]


def _literals(node: ast.AST) -> set[str]:
    return {n.value for n in ast.walk(node) if isinstance(n, ast.Constant) and isinstance(n.value, str)}


def test_no_kind_is_compared_with_a_literal_outside_its_own_module():
    found = []
    for path in PACKAGE.rglob("*.py"):
        if path in OWN or _in_a_kinds_folder(path):
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Compare) and _literals(node) & set(facts.KINDS) and "kind" in ast.unparse(node):
                found.append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno}")
            told_by_signal = isinstance(node, ast.Compare) and bool(_literals(node.left) & SIGNALS)
            if told_by_signal and any(isinstance(op, ast.In | ast.NotIn) for op in node.ops):
                found.append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno}")
    assert found == []


# The window part's fields only the rotary's reading sets (``RotaryWindowInfo``'s own): its prepare stage's repairs
# and departures, its sensors' zero and J_M
ROTARY_READING = {
    "glitches_repaired",
    "stale_samples",
    "read_span",
    "sensor_zero",
    "sensor_zero_from",
    "inertia_read",
    "inertia_undecided",
    "inertia_from",
    "hinge_aircraft_ratio",
    "hinge_aircraft_ratio_std",
    "hinge_lag_s",
    "hinge_offset_nm",
    "hinge_gain",
    "current_lag_s",
    "current_offset_a",
    "torque_scale",
    "inertia_factor",
    "viscous_factor",
    "kinematic_gain",
}


def test_no_shared_module_imports_a_kind_or_reads_what_only_one_kind_has():
    """Outside its folder a kind is reached through the registry (``ema.kinds``): no shared module imports a kind's
    module (the registry imports each at its call), reads a signal only one kind's window carries, or a field only
    one kind's document has (its section, the rotary's airframe and sensors' noise). The modules that declare them (the
    documents' classes, the windows' signals and their bounds) are the exception."""
    from ema.estimate.documents.window_facts import HistoryReadings, RotaryWindowInfo, WindowInfo
    from ema.model.actuator import ActuatorDocument, RotaryActuator
    from ema.prognosis.documents import KINDS_PROGNOSES, own_parts

    kinds_modules = tuple(f"ema.kinds.{name}" for name in facts.KINDS)
    counts: dict[str, int] = {}
    for kind in facts.KINDS.values():
        for name in kind.all_signals:
            counts[name] = counts.get(name, 0) + 1
    one_kinds_signals = {name for name, n in counts.items() if n == 1}
    own_fields = {kind.section for kind in facts.KINDS.values()}
    own_fields |= set(RotaryActuator.model_fields) - set(ActuatorDocument.model_fields)
    own_fields |= ROTARY_READING
    own_fields |= set(HistoryReadings.model_fields)  # what the rotary's windows borrow: a sensor zero, J_M
    own_fields |= {field for cls in KINDS_PROGNOSES for field in own_parts(cls)}  # a rotary prognosis's J_M
    assert set(RotaryWindowInfo.model_fields) - set(WindowInfo.model_fields) == ROTARY_READING  # its class's own
    declared_in = {PACKAGE / "model" / "actuator.py", PACKAGE / "model" / "window.py"}
    declared_in |= {PACKAGE / "estimate" / "documents" / "window_facts.py", PACKAGE / "prognosis" / "documents.py"}
    found = []
    for path in _shared_modules():
        at = path.relative_to(PACKAGE.parent)
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith(kinds_modules):
                # the registry alone: each kind's object (its package) on load, the kind's modules at their call
                registry = path == PACKAGE / "kinds" / "__init__.py"
                if not registry or (node.col_offset == 0 and node.module not in kinds_modules):
                    found.append(f"{at}:{node.lineno} imports {node.module}")
            if path in declared_in:
                continue
            key = node.slice if isinstance(node, ast.Subscript) else None
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "get":
                key = node.args[0] if node.args else None
            if isinstance(key, ast.Constant) and key.value in one_kinds_signals:
                found.append(f"{at}:{node.lineno} reads {key.value}")
            if isinstance(node, ast.Attribute) and node.attr in own_fields and isinstance(node.ctx, ast.Load):
                found.append(f"{at}:{node.lineno} reads .{node.attr}")  # a table's column too: kept for every kind
    assert found == []


def test_every_kind_of_the_documents_has_its_method():
    from ema.model.window import WINDOW_CLASSES

    assert set(REGISTRY) == set(facts.KINDS) == set(WINDOW_CLASSES)  # its method, and its window's class
    assert all(kind.facts is facts.KINDS[name] for name, kind in REGISTRY.items())


def test_the_documents_kind_field_lists_every_kind():
    from ema.model.actuator import actuator_schema
    from ema.model.logmap import ROLES, logmap_schema

    def by_kind(schema: dict) -> dict[str, dict]:
        members = [schema["$defs"][ref["$ref"].rpartition("/")[2]] for ref in schema["oneOf"]]
        return {member["properties"]["kind"]["const"]: member for member in members}

    actuators, log_maps = by_kind(actuator_schema()), by_kind(logmap_schema())
    assert set(actuators) == set(log_maps) == set(facts.KINDS)  # one class per kind, joined on kind
    for name, member in actuators.items():
        section = facts.KINDS[name].section
        assert section in member["required"]  # its own section, and no other kind's
        assert not ({other.section for other in facts.KINDS.values()} - {section}) & set(member["properties"])
    for name, member in log_maps.items():  # its kind's roles, and no other kind's
        roles = facts.KINDS[name].roles
        assert {r for r in ROLES if r in member["properties"]} == {*roles, "error"}
        assert {r for r in member["required"] if r in ROLES} == {
            r for r, role in roles.items() if role.required and r != "position"
        }


def test_each_kinds_window_signals_are_its_facts_signals():
    """ema-window/1's signals are one class per kind, joined by which signals a window carries: each class's
    required and optional signals are its facts' own, so a kind's row is the one place they are declared."""
    from ema.model.window import GearedSignals, LinearSignals, RotarySignals, ServoSignals

    classes = {cls.kind: cls for cls in (RotarySignals, LinearSignals, ServoSignals, GearedSignals)}
    assert set(classes) == set(facts.KINDS)
    for name, cls in classes.items():
        fields = cls.model_fields
        assert tuple(fields) == facts.KINDS[name].all_signals
        assert {f for f, info in fields.items() if info.is_required()} == set(facts.KINDS[name].signals)


QUICK = (
    "import glob, sys; from ema.cli.main import main; rig, learned = sys.argv[1:]; "
    "runs = sorted(glob.glob(rig + '/runs/normal_load[24]0_*.csv')); "
    "given = ['--log-map', rig + '/log-map.json', '--json']; "
    "codes = [main(['calibrate', *runs, '--actuator', rig + '/actuator.json', '--out-actuator', learned, *given]), "
    "main(['estimate', rig + '/runs/lackLubrication1_load20_run001.csv', '--actuator', learned, *given])]; "
    "print(*codes, 'scipy.optimize' in sys.modules, file=sys.stderr)"
)


def test_every_signal_says_its_unit_in_its_name():
    """A log map's units come from the signal's name alone (``ema.model.units.units_of``): every role of every kind
    resolves, and its own unit (the name's) is the factor 1."""
    from ema.model.units import units_of

    for kind in facts.KINDS.values():
        for role in kind.roles.values():
            assert 1.0 in role.units.values(), (kind.name, role.signal)
    assert units_of("position_mm")["m"] == 1000.0 and units_of("set_point_m")["mm"] == 1e-3
    assert units_of("hinge_moment_nm") is not units_of("load_n")


def test_a_window_no_network_learns_from_never_loads_the_network(tmp_path):
    """A ball screw's windows are read quasi-statically: its calibration and its estimate answer without loading
    the network's modules (SciPy's optimizers, half a second)."""
    import subprocess
    import sys

    rig, learned = str(PACKAGE.parent / "examples" / "ballscrew-rig"), str(tmp_path / "rig.json")
    done = subprocess.run([sys.executable, "-c", QUICK, rig, learned], capture_output=True, text=True, check=True)
    assert done.stderr.splitlines()[-1] == "0 0 False"


def test_an_archive_no_network_learns_from_is_read_in_process_whatever_the_workers(tmp_path, capsys):
    """A ball screw's runs are read in milliseconds: no worker process is kept to load the network for them, and the
    rows are those one worker writes."""
    rig = PACKAGE.parent / "examples" / "ballscrew-rig"
    given = ["--log-map", str(rig / "log-map.json")]
    learned = tmp_path / "rig.json"
    healthy = sorted(str(p) for p in (rig / "runs").glob("normal_load[24]0_*.csv"))
    calibrate = ["calibrate", *healthy, "--actuator", str(rig / "actuator.json"), "--out-actuator", str(learned)]
    assert main([*calibrate, *given]) == EXIT_OK
    folder = tmp_path / "runs"
    folder.mkdir()
    for run in sorted((rig / "runs").glob("*_run00[12].csv"))[:6]:
        (folder / run.name).write_bytes(run.read_bytes())
    capsys.readouterr()
    rows, engines = {}, {}
    for workers in ("2", "1"):
        out = tmp_path / f"{workers}.csv"
        arguments = ["fleet", str(folder), "--out", str(out), "--workers", workers, "--actuator", str(learned)]
        assert main([*arguments, *given, "--json"]) == EXIT_OK
        summary = json.loads(capsys.readouterr().out)
        with out.open() as handle:
            rows[workers] = sorted((r["window_id"], r["FDJ"]) for r in csv.DictReader(handle))
        engines[workers] = summary["engine"]
        assert summary["answered"] == 6
    assert engines == {"2": "in-process: no window learns a network", "1": "in-process"} and rows["2"] == rows["1"]


def test_a_warmed_process_loads_nothing_new_for_the_first_window_of_any_kind():
    """The service warms every kind before it answers: a servo's first window then imports no module (its filters'
    scipy.signal took 0.6 s of EMPS's first window's 0.8) and compiles or loads no kernel of its simulator."""
    import subprocess
    import sys

    probe = "\n".join(
        [
            "import sys",
            "from ema.kinds import warm_up",
            "warm_up()",
            "from ema.kinds import estimate",
            "from ema.model.actuator import read_actuator",
            "from ema.model.logmap import read_logmap, read_mapped",
            "from ema.kinds.servo.closed_loop import run_lanes",
            "from ema.model.window import window_from_dict",
            "emps = sys.argv[1]",
            "window = window_from_dict(read_mapped(emps + '/DATA_EMPS.mat', read_logmap(emps + '/log-map.json')))",
            "actuator = read_actuator(emps + '/actuator.json')",
            "before, signatures = set(sys.modules), list(run_lanes.signatures)",
            "estimate(window, actuator=actuator)",
            "print(sorted(set(sys.modules) - before), run_lanes.signatures == signatures, file=sys.stderr)",
        ]
    )
    emps = str(PACKAGE.parent / "examples" / "emps")
    done = subprocess.run([sys.executable, "-c", probe, emps], capture_output=True, text=True, check=True)
    assert done.stderr.splitlines()[-1] == "[] True"


def test_the_shared_method_names_no_kinds_document_class():
    """The estimate's and the calibration's shared modules take the document every kind's class extends: a kind's
    own class, and its section read through it, are its folder's (a quasi-static reading hands its own in)."""
    from ema.model.actuator import ActuatorDocument

    own = {cls.__name__ for cls in ActuatorDocument.__subclasses__()}
    sections = {kind.section for kind in facts.KINDS.values()}
    found = []
    for folder in ("estimate", "calibration"):
        for path in (PACKAGE / folder).rglob("*.py"):
            tree = ast.parse(path.read_text())
            names = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
            names |= {alias.name for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) for alias in n.names}
            reads = {  # a section read off a document (``actuator.screw``), not any attribute of that name
                n.attr for n in ast.walk(tree) if isinstance(n, ast.Attribute) and "actuator" in ast.unparse(n.value)
            }
            if names & own or reads & sections:
                found.append(f"{path.relative_to(PACKAGE.parent)}: {sorted(names & own | reads & sections)}")
    assert own and found == []
