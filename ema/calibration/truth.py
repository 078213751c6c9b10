"""A calibration's errors against a known truth (windows drawn by a simulator): every constant the truth names that
the report carries, before (the document's model) and after (what the windows taught).

Every kind's report carries its constants the same way, its estimates before and after and what it learned
(``CalibrationReport.learned``), so one rule serves them all: a truth is a mapping of those names to their true
values, held to the bounds the actuator's document sets on each (a friction must be positive, an efficiency at most
1) before anything runs, and compared with what the report carries once it is written. A truth that names none of
them is refused: a comparison that silently compared nothing reads as one that found no error.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TypeVar

import numpy as np

from ema.calibration.documents import CalibrationReport
from ema.estimate.information import out_of_bounds
from ema.model.actuator import ActuatorDocument
from ema.model.checks import InputError

FIELD = "truth"  # what an error about a truth names (the command line says --truth, the service body.truth)
Report = TypeVar("Report", bound=CalibrationReport)
NOT_HAD = "no actuator of this document has it"


def refuse_truth(truth: Mapping[str, float], actuator: ActuatorDocument) -> None:
    """InputError naming the first entry of ``truth`` that is not a finite number or lies outside its field's bounds
    in ``actuator``'s document (a name the document has no field for is held to finiteness alone)."""
    if not truth:
        raise InputError(FIELD, "names no constant: give each one compared as its name and true value")
    for name, value in truth.items():
        if not np.isfinite(value):
            raise InputError(f"{FIELD}.{name}", f"must be a finite number, got {value}")
    fields = {name: actuator.facts.document_field(name) for name in truth}
    out_of_bounds(truth, actuator.bounding_classes, FIELD, fields=fields, why=NOT_HAD)


def reported(report: CalibrationReport) -> tuple[dict[str, float], dict[str, float]]:
    """The report's constants before and after, by name: its estimates, and after them what it learned."""
    after = {entry.name: entry.value for entry in report.learned} | report.estimates_after
    return dict(report.estimates_before), after


def with_truth_errors(report: Report, truth: Mapping[str, float] | None) -> Report:
    """``report`` with its absolute and relative errors against ``truth`` (each name it carries; a relative one
    only where the truth is not 0); InputError naming the truth where it names none of the report's constants."""
    if truth is None:
        return report
    before, after = reported(report)
    compared = [name for name in truth if name in after]
    if not compared:
        raise InputError(
            FIELD,
            f"names {', '.join(truth)}; this calibration reports {', '.join(after)}: nothing to compare",
        )
    errors: dict[str, dict[str, float] | None] = {}
    for when, values in (("before", before), ("after", after)):
        absolute = {name: abs(values[name] - float(truth[name])) for name in compared if name in values}
        relative = {name: 100.0 * error / abs(float(truth[name])) for name, error in absolute.items() if truth[name]}
        errors[f"error_{when}"], errors[f"error_pct_{when}"] = absolute or None, relative or None
    return report.model_copy(update=errors)
