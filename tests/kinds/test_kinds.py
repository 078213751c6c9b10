"""Each kind is declared in one place: its facts in ema.model.kinds, its method in its module of ema.kinds; nothing
else compares a kind with a literal or tells one by a signal's name."""

import ast
from pathlib import Path

from ema.kinds import KINDS
from ema.model import kinds as facts

PACKAGE = Path(__file__).resolve().parents[2] / "ema"
OWN = {PACKAGE / "model" / "kinds.py", *(PACKAGE / "kinds" / f"{name}.py" for name in facts.KINDS)}
SIGNALS = {name for kind in facts.KINDS.values() for name in kind.all_signals}


def _literals(node: ast.AST) -> set[str]:
    return {n.value for n in ast.walk(node) if isinstance(n, ast.Constant) and isinstance(n.value, str)}


def test_no_kind_is_compared_with_a_literal_outside_its_own_module():
    found = []
    for path in PACKAGE.rglob("*.py"):
        if path in OWN:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Compare) and _literals(node) & set(facts.KINDS) and "kind" in ast.unparse(node):
                found.append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno}")
            told_by_signal = isinstance(node, ast.Compare) and bool(_literals(node.left) & SIGNALS)
            if told_by_signal and any(isinstance(op, ast.In | ast.NotIn) for op in node.ops):
                found.append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno}")
    assert found == []


def test_every_kind_of_the_documents_has_its_method():
    assert set(KINDS) == set(facts.KINDS)
    assert all(kind.facts is facts.KINDS[name] for name, kind in KINDS.items())


def test_the_documents_kind_field_lists_every_kind():
    from ema.model.actuator import ActuatorDocument
    from ema.model.logmap import LogMap

    for model in (ActuatorDocument, LogMap):
        schema = model.model_json_schema()["properties"]["kind"]
        assert set(schema["enum"]) == set(facts.KINDS)


QUICK = (
    "import glob, sys; from ema.cli.main import main; rig, learned = sys.argv[1:]; "
    "runs = sorted(glob.glob(rig + '/runs/normal_load[24]0_*.csv')); "
    "given = ['--log-map', rig + '/log-map.json', '--json']; "
    "codes = [main(['calibrate', *runs, '--actuator', rig + '/actuator.json', '--out-actuator', learned, *given]), "
    "main(['estimate', rig + '/runs/lackLubrication1_load20_run001.csv', '--actuator', learned, *given])]; "
    "print(*codes, 'torch' in sys.modules, file=sys.stderr)"
)


def test_a_window_no_network_learns_from_never_loads_torch(tmp_path):
    """A ball screw's windows are read quasi-statically: its calibration and its estimate answer without torch's
    second of loading."""
    import subprocess
    import sys

    rig, learned = str(PACKAGE.parent / "examples" / "ballscrew-rig"), str(tmp_path / "rig.json")
    done = subprocess.run([sys.executable, "-c", QUICK, rig, learned], capture_output=True, text=True, check=True)
    assert done.stderr.splitlines()[-1] == "0 0 False"
