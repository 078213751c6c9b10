from __future__ import annotations

from fastapi import APIRouter, Request
from starlette.concurrency import run_in_threadpool

from ema import kinds
from ema.calibration.documents import AnyCalibration, CalibrationReport
from ema.calibration.truth import refuse_truth
from ema.model.window import Window
from ema.service.deps import RunnerDep, SettingsDep, StoreDep, actuator_of, stopper, stored_kind
from ema.service.parsing import check_calibration_budget, read_body
from ema.service.schemas import CalibrateIn, json_body, responses

router = APIRouter(tags=["calibrate"])


def _windows_and_truth(body: CalibrateIn) -> tuple[list[Window], dict[str, float] | None]:
    return [document.to_window() for document in body.windows], body.truth


@router.post(
    "/calibrate",
    response_model=AnyCalibration,
    response_model_by_alias=True,
    responses=responses(401, 413, 422, 503),
    openapi_extra=json_body(CalibrateIn, "windows of one actuator, and their truth if synthetic"),
)
async def calibrate(request: Request, settings: SettingsDep, store: StoreDep, runner: RunnerDep) -> CalibrationReport:
    """Trace what the model misses in the windows of one actuator to an effect, add it, re-estimate (with the
    actuator's document, the default where it has none), by the actuator's kind: ema-calibration/1, with the
    document completed where the windows taught what it lacked."""
    windows, truth = await read_body(request, runner, CalibrateIn, _windows_and_truth)
    with runner.admit() as ticket:
        check_calibration_budget(windows, settings.pipeline, settings)
        actuator, version = await actuator_of(store, windows[0].actuator_id)
        stored_kind(windows, actuator, version, listed=True)
        if truth is not None:
            refuse_truth(truth, actuator)  # before the run is queued, as its windows are
        stop = stopper(ticket.cancel)
        asked = kinds.CalibrationRequest(settings.pipeline, actuator, truth, on_stage=stop, checkpoint=lambda: stop(""))
        report = await runner.run(ticket, request.is_disconnected, lambda: kinds.calibrate(windows, asked).report)
        await run_in_threadpool(store.add_calibration, windows[0].actuator_id, report)
        return report
