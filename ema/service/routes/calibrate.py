from __future__ import annotations

from fastapi import APIRouter, Request
from starlette.concurrency import run_in_threadpool

from ema.calibration.calibrate import Calibrator
from ema.calibration.documents import CalibrationReport
from ema.model.checks import InputError
from ema.model.window import Window
from ema.service.deps import RunnerDep, SettingsDep, StoreDep, actuator_of, stopper
from ema.service.parsing import check_calibration_budget, read_body
from ema.service.schemas import CalibrateIn, json_body, responses

router = APIRouter(tags=["calibrate"])


def _windows_and_truth(body: CalibrateIn) -> tuple[list[Window], dict[str, float] | None]:
    truth = None if body.truth is None else body.truth.model_dump(exclude_none=True)
    return [document.to_window() for document in body.windows], truth


@router.post(
    "/calibrate",
    response_model=CalibrationReport,
    response_model_by_alias=True,
    responses=responses(401, 413, 422, 503),
    openapi_extra=json_body(CalibrateIn, "windows of one actuator, and their truth if synthetic"),
)
async def calibrate(request: Request, settings: SettingsDep, store: StoreDep, runner: RunnerDep) -> CalibrationReport:
    """Trace what the model misses in the windows of one actuator to an effect, add it, re-estimate
    (with the actuator's document, the default where it has none): ema-calibration/1."""
    windows, truth = await read_body(request, runner, CalibrateIn, _windows_and_truth)
    with runner.admit() as ticket:
        check_calibration_budget(windows, settings.pipeline, settings)
        for i, window in enumerate(windows):
            if window.actuator_id != windows[0].actuator_id:
                raise InputError(
                    f"windows.{i}.actuator_id",
                    f"is {window.actuator_id!r}; a calibration reads the "
                    f"windows of one actuator ({windows[0].actuator_id!r})",
                )
        actuator, _ = await actuator_of(store, windows[0].actuator_id)
        calibrator = Calibrator(settings.pipeline, seed=settings.pipeline.seed, actuator=actuator)
        stop = stopper(ticket.cancel)

        def run() -> CalibrationReport:
            return calibrator.fit(windows, truth, on_stage=stop, checkpoint=lambda: stop("")).report_

        report = await runner.run(ticket, request.is_disconnected, run)
        await run_in_threadpool(store.add_calibration, windows[0].actuator_id, report)
        return report
