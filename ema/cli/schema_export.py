"""``ema schemas``: the JSON Schema of every public document, exported from the one model that defines it."""

from __future__ import annotations

import json
from pathlib import Path

from pydantic import BaseModel


def documents() -> dict[str, type[BaseModel]]:
    """File stem -> the model (imported here: the CLI's help must not pay for them)."""
    from ema.calibration.documents import CalibrationReport
    from ema.estimate.documents import Estimate
    from ema.model.actuator import ActuatorDocument
    from ema.model.logmap import LogMap
    from ema.model.window import WindowDocument
    from ema.prognosis.documents import ActuatorSummary, EstimateHistory, Prognosis, StoredActuator, Withdrawal

    return {
        "ema-actuator-1": ActuatorDocument,
        "stored-actuator": StoredActuator,
        "ema-window-1": WindowDocument,
        "ema-logmap-1": LogMap,
        "ema-estimate-1": Estimate,
        "ema-calibration-1": CalibrationReport,
        "history": EstimateHistory,
        "prognosis": Prognosis,
        "actuator-summary": ActuatorSummary,
        "withdrawal": Withdrawal,
    }


def export(folder: Path, check: bool = False) -> list[str]:
    """Write (or, with ``check``, compare) one ``<stem>.json`` per document; returns the stale or missing files."""
    if not check:
        folder.mkdir(parents=True, exist_ok=True)
    stale = []
    for stem, model in documents().items():
        text = json.dumps(model.model_json_schema(by_alias=True), indent=2, sort_keys=True) + "\n"
        path = folder / f"{stem}.json"
        if check:
            if not path.exists() or path.read_text() != text:
                stale.append(path.name)
        else:
            path.write_text(text)
    return stale
