"""``ema schemas``: the JSON Schema of every public document, exported from the one model that defines it."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from pydantic import BaseModel


def schemas() -> dict[str, dict[str, Any]]:
    """File stem -> the JSON Schema of that document (its model imported here: the CLI's help must not pay for
    them). ``ema-actuator/1`` is one kind's document, chosen by its ``kind`` (``ema.model.actuator.AnyActuator``)."""
    from ema.calibration.documents import calibration_schema
    from ema.estimate.documents import Estimate
    from ema.model.actuator import actuator_schema
    from ema.model.logmap import logmap_schema
    from ema.model.window import WindowDocument
    from ema.prognosis.documents import ActuatorSummary, EstimateHistory, StoredActuator, Withdrawal, prognosis_schema

    models: dict[str, type[BaseModel]] = {
        "stored-actuator": StoredActuator,
        "ema-window-1": WindowDocument,
        "ema-estimate-1": Estimate,
        "history": EstimateHistory,
        "actuator-summary": ActuatorSummary,
        "withdrawal": Withdrawal,
    }
    exported = {stem: model.model_json_schema(by_alias=True) for stem, model in models.items()}
    return {
        "ema-actuator-1": actuator_schema(),
        "ema-logmap-1": logmap_schema(),
        "ema-calibration-1": calibration_schema(),
        "prognosis": prognosis_schema(),
        **exported,
    }


def export(folder: Path, check: bool = False) -> list[str]:
    """Write (or, with ``check``, compare) one ``<stem>.json`` per document; returns the stale or missing files."""
    if not check:
        folder.mkdir(parents=True, exist_ok=True)
    stale = []
    for stem, schema in schemas().items():
        text = json.dumps(schema, indent=2, sort_keys=True) + "\n"
        path = folder / f"{stem}.json"
        if check:
            if not path.exists() or path.read_text() != text:
                stale.append(path.name)
        else:
            path.write_text(text)
    return stale
