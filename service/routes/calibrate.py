from __future__ import annotations

from fastapi import APIRouter, Request

from calibration.calibrate import Calibrator
from calibration.documents import CalibrationReport
from service.deps import RunnerDep, SettingsDep, stopper
from service.parsing import check_budget, parse
from service.schemas import CalibrateIn, json_body, responses
from sim.checks import InputError

router = APIRouter(tags=["calibrate"])


@router.post(
    "/calibrate",
    response_model=CalibrationReport,
    response_model_by_alias=True,
    responses=responses(401, 413, 422, 503),
    openapi_extra=json_body(CalibrateIn, "windows of one actuator, and their truth if synthetic"),
)
async def calibrate(request: Request, settings: SettingsDep, runner: RunnerDep) -> CalibrationReport:
    """Trace what the model misses in the windows to an effect, add it, re-estimate: ema-calibration/1."""
    with runner.admit() as ticket:
        body = await parse(CalibrateIn, await request.body())
        if len(body.windows) > settings.max_calibrate_windows:
            raise InputError("windows", f"{len(body.windows)} windows; this service's limit is "
                                        f"{settings.max_calibrate_windows} (EMA_MAX_CALIBRATE_WINDOWS)")  # fmt: skip
        windows = [document.to_window() for document in body.windows]
        for i, window in enumerate(windows):
            check_budget(window, settings.pipeline, settings, field=f"windows.{i}.signals")
        truth = None if body.truth is None else body.truth.model_dump(exclude_none=True)
        calibrator = Calibrator(settings.pipeline, seed=settings.pipeline.seed)

        def run() -> CalibrationReport:
            return calibrator.fit(windows, truth, on_stage=stopper(ticket.cancel)).report_

        return await runner.run(ticket, request.is_disconnected, run)
