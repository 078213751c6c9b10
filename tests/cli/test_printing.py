"""What `ema history` prints: each parameter's level and slope in the unit its estimates were read in."""

from pathlib import Path

from ema.cli.printing import print_prognosis
from ema.estimate.documents import parameter
from ema.kinds.rotary.pipeline import estimate_window
from ema.kinds.rotary.synthetic import synthetic_window
from ema.model.actuator import THESIS, read_actuator
from ema.model.params import HealthParams
from ema.prognosis.documents import EstimateHistory, Stored
from ema.prognosis.prognose import prognose
from tests.service.conftest import SMALL

EMPS = Path(__file__).resolve().parents[2] / "examples" / "emps" / "actuator.json"


def test_a_servos_friction_is_printed_in_newtons_and_a_rotarys_in_newton_metres(capsys):
    base = estimate_window(synthetic_window(HealthParams.single(), seed=1, duration_s=0.1), SMALL, actuator=THESIS)
    servo = read_actuator(EMPS)
    servo = servo.model_copy(update={"thresholds": servo.thresholds.model_copy(update={"fdj_above_n": 30.0})})
    for actuator, unit, start in ((servo, "N", 20.0), (THESIS, "N·m", 0.05)):
        stored = []
        for i in range(6):
            fdj = parameter(start * (1 + 0.02 * i), start * 0.004, None, unit=unit)
            window = base.window.model_copy(update={"flight_hours": 20.0 * i})
            entry = base.model_copy(
                update={
                    "window_id": f"w{i}",
                    "window": window,
                    "estimates": base.estimates.model_copy(update={"FDJ": fdj}),
                }
            )
            stored.append(Stored(**entry.model_dump(by_alias=True), id=i + 1, stored_at="2026-11-27T10:00:00+00:00"))
        history = EstimateHistory(actuator_id="a", estimates=stored)
        print_prognosis(history, prognose("a", stored, actuator, backtested=False), None)
        fdj_line = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("FDJ"))
        assert f" {unit}, slope " in fdj_line and f" {unit} per flight hour" in fdj_line
