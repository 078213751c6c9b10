"""The service's one settings object, read from the environment (prefix ``EMA_``)."""

from __future__ import annotations

import os
from functools import lru_cache
from pathlib import Path

from pydantic import Field
from pydantic_settings import BaseSettings, SettingsConfigDict


class Settings(BaseSettings):
    model_config = SettingsConfigDict(env_prefix="EMA_", frozen=True)

    host: str = "127.0.0.1"  # loopback unless an operator exposes it on purpose
    port: int = Field(8000, ge=1, le=65535)
    api_key: str | None = None  # when set, /v1 requires the X-API-Key header
    database: Path = Path("ema-history.sqlite3")

    # pipeline sizes: defaults, and the bounds a request may override them within
    n_simulations: int = Field(500, ge=20, le=20_000)
    n_timesteps: int = Field(1000, ge=10, le=10_000)
    hidden_units: int = Field(100, ge=1, le=2000)
    members: int = Field(1, ge=1, le=20)
    check_windows: int = Field(16, ge=8, le=1000)
    seed: int = 0
    max_simulations: int = Field(2000, ge=20, le=20_000)
    max_timesteps: int = Field(5000, ge=10, le=10_000)
    max_hidden_units: int = Field(400, ge=1, le=2000)

    # load: pipelines run one at a time on all cores; a few may wait, the rest get 503
    max_queue: int = Field(4, ge=0, le=1000)
    queue_timeout_s: float = Field(60.0, gt=0)  # a queued request not started by then gets 503
    max_body_bytes: int = Field(50_000_000, ge=1000)
    threads: int = Field(default_factory=lambda: os.cpu_count() or 1, ge=1)
    warm_up: bool = True  # compile (or load) the kernels at start-up, not in the first request


@lru_cache
def get_settings() -> Settings:
    return Settings()
