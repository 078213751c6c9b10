from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Query, Request

from ema.estimate.config import bounds
from ema.model.window import Window, WindowDocument
from ema.prognosis.documents import Stored
from ema.service.deps import RunnerDep, SettingsDep, StoreDep
from ema.service.estimates import answered
from ema.service.parsing import read_body
from ema.service.schemas import json_body, responses

router = APIRouter(tags=["estimate"])


def _query(name: str, what: str) -> object:
    low, high = bounds(name)
    return Query(ge=low, le=high, description=f"{what} (default and ceiling: the service's settings)")


def _window_and_digest(document: WindowDocument) -> tuple[Window, str]:
    window = document.to_window()
    return window, window.content_sha256()


@router.post(
    "/estimate",
    response_model=Stored,
    response_model_by_alias=True,
    responses=responses(401, 409, 410, 413, 415, 422, 503),
    openapi_extra=json_body(WindowDocument, "one ema-window/1 window"),
)
async def estimate(
    request: Request,
    *,
    settings: SettingsDep,
    store: StoreDep,
    runner: RunnerDep,
    n_simulations: Annotated[int | None, _query("n_simulations", "simulations to train on")] = None,
    n_timesteps: Annotated[int | None, _query("n_timesteps", "network input timesteps")] = None,
    hidden_units: Annotated[int | None, _query("hidden_units", "hidden neurons")] = None,
    seed: Annotated[int | None, _query("seed", "seed of the dataset and the training")] = None,
) -> Stored:
    """Estimate FDJ, η_O, η_A (FSJ where the window shows it) of one window; store and answer.

    A window already stored for its (actuator_id, window_id) is answered from the history
    (``replay: true``) without recomputing; other content under a stored key is another window: 409; a window an
    operator withdrew stays withdrawn: 410, naming the withdrawal.
    What the stored windows of the actuator read that this one may not (its ``flight_id``'s sensor
    zero, the actuator's J_M: ``ema.kinds.rotary.other_windows``) is read with it, and so is the actuator's latest
    ``ema-actuator/1`` document (the default where it has none; the answer records which).
    Budget: the window's duration and its simulation work (simulations × seconds) are limited by the
    service's settings; over it, 422 naming the limit.
    """
    window, digest = await read_body(request, runner, WindowDocument, _window_and_digest)
    sizes = {"n_simulations": n_simulations, "n_timesteps": n_timesteps, "hidden_units": hidden_units, "seed": seed}
    keeper = request.app.state.keeper
    return await answered(
        window,
        digest,
        sizes,
        settings=settings,
        store=store,
        runner=runner,
        keeper=keeper,
        gone=request.is_disconnected,
    )
