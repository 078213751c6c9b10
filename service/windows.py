"""The validated request body as the window every lower layer understands."""

from __future__ import annotations

from service.schemas import WindowIn
from sim.window import Window, window_from_dict


def to_window(body: WindowIn) -> Window:
    """Run the shared ``ema-window/1`` checks (lengths, envelope, ranges); they raise InputError."""
    return window_from_dict(body.model_dump(by_alias=True))
