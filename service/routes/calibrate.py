from __future__ import annotations

from typing import Any

from fastapi import APIRouter

from service.deps import RunnerDep, SettingsDep, pipeline_config
from service.schemas import CalibrateIn
from service.windows import to_window
from training.calibration.calibrate import Calibrator

router = APIRouter(prefix="/v1", tags=["calibrate"])


@router.post("/calibrate")
async def calibrate(body: CalibrateIn, settings: SettingsDep, runner: RunnerDep) -> dict[str, Any]:
    """Compare the model with the windows, trace the residual to a missing effect, add it: ema-calibration/1."""
    windows = [to_window(window) for window in body.windows]
    config = pipeline_config(settings)
    truth = None if body.truth is None else body.truth.model_dump(exclude_none=True)

    def run() -> dict[str, Any]:
        return Calibrator(config, seed=settings.seed).fit(windows, truth).report_

    return await runner.run(run)
