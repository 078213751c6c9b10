"""The service's one settings object, read from the environment (``EMA_*``) and the CLI's flags.

Pipeline sizes come from ``ema.estimate.config.PipelineConfig`` (nested: ``EMA_PIPELINE__N_SIMULATIONS``),
their per-request ceilings and the request budget are here; nothing restates either.
"""

from __future__ import annotations

import difflib
import ipaddress
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Literal

from pydantic import BeforeValidator, Field, SecretStr, field_validator, model_validator
from pydantic_settings import BaseSettings, SettingsConfigDict

from ema.estimate.config import PipelineConfig
from ema.model.bounds import MAX_THREADS
from ema.model.document import refused_by

LOOPBACK_NAMES = ("localhost", "127.0.0.1", "::1")
MIN_KEY_CHARACTERS = 16


def is_loopback(host: str) -> bool:
    if host in LOOPBACK_NAMES:
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def default_database() -> Path:
    """The history's default place: the user's data directory (XDG), never the working directory."""
    home = os.environ.get("XDG_DATA_HOME") or str(Path.home() / ".local" / "share")
    return Path(home) / "ema" / "history.sqlite3"


def _text_setting(setting: object) -> str:
    setting = str(setting) if isinstance(setting, Path) else setting
    if not isinstance(setting, str):
        raise ValueError("must be a file path or a postgresql:// address")
    return setting


def _setting_error(setting: str) -> str | None:
    from ema.history.open import setting_error  # the history's rule, loaded when a setting is read

    return setting_error(setting)


def _read_key(path: Path) -> str:
    try:
        return path.read_text().strip()
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path} cannot be read: {getattr(exc, 'strerror', None) or exc}") from None


class Settings(BaseSettings):
    model_config = SettingsConfigDict(env_prefix="EMA_", env_nested_delimiter="__", frozen=True)

    host: str = "127.0.0.1"  # loopback unless an operator exposes it on purpose (then a key is required)
    port: int = Field(8000, ge=1, le=65535)
    api_key: SecretStr | None = Field(None, description="every /v1 request must carry it in X-API-Key")
    api_key_file: Path | None = Field(None, description="a file holding the key (kept out of the environment)")
    api_prefix: str = Field("/v1", pattern=r"^/[a-z0-9]+$")
    database: Annotated[str, BeforeValidator(_text_setting), refused_by(_setting_error)] = Field(
        default_factory=lambda: str(default_database()),
        description="the history: an SQLite file's path, or a postgresql://user@host:port/db address",
    )
    min_free_bytes: int = Field(50_000_000, ge=0, description="disk room below which new work is refused (SQLite)")
    backend: Literal["local", "ray"] = "local"  # ray: a ground station's service fans out to a cluster
    ray_address: str | None = Field(None, description="'auto' or host:port; none: a local Ray")
    ray_jobs: int = Field(4, ge=1, le=4096, description="with the ray backend: estimates in flight at once")

    pipeline: PipelineConfig = PipelineConfig()
    max_simulations: int = Field(512, ge=16, le=4000, description="ceiling of a request's n_simulations")
    max_timesteps: int = Field(2000, ge=10, le=10_000, description="ceiling of a request's n_timesteps")
    max_hidden_units: int = Field(400, ge=1, le=2000, description="ceiling of a request's hidden_units")
    # The request budget: a window's duration, and its simulation work (simulations × seconds of window).
    max_window_s: float = Field(10.0, gt=0, le=60.0)
    max_simulated_s: float = Field(1500.0, gt=0, description="simulations × window seconds per request")
    max_calibrate_windows: int = Field(4, ge=1, le=16)
    max_calibrate_s: float = Field(
        4.0,
        gt=0,
        le=60.0,
        description="seconds of windows in one calibration, together (its memory and time grow "
        "with them: about 0.6 GB and 8 s a second of window)",
    )

    max_queue: int = Field(4, ge=0, le=1000, description="requests that may wait while one runs")
    queue_timeout_s: float = Field(60.0, gt=0)
    max_body_bytes: int = Field(128_000_000, ge=1000)
    body_timeout_s: float = Field(60.0, gt=0, le=3600, description="a request's body must arrive within this")
    body_grace_s: float = Field(5.0, gt=0, le=600, description="after this, a body must keep min_body_rate_bps")
    min_body_rate_bps: float = Field(1000.0, gt=0, description="slowest average pace of a body past its grace (B/s)")
    max_upload_bytes: int = Field(
        512_000_000, ge=1000, description="bytes of all bodies being received at once (beyond: 503)"
    )
    ui_page_size: int = Field(50, ge=1, le=1000, description="actuators per page of /ui")
    ui_share: float = Field(
        0.2, gt=0, le=1, description="the most of one core the operator's view takes, however many watch it"
    )
    allowed_origins: tuple[str, ...] = Field(
        (), description="origins (scheme://host:port) of web pages allowed to write besides the service's own"
    )
    threads: int | None = Field(None, ge=1, le=MAX_THREADS, description="the thread budget; default: the usable cores")
    warm_up: bool = True

    @field_validator("api_key")
    @classmethod
    def _key_is_a_key(cls, key: SecretStr | None) -> SecretStr | None:
        if key is not None:
            text = key.get_secret_value()
            if len(text.strip()) < MIN_KEY_CHARACTERS or not text.isascii() or not text.isprintable():
                raise ValueError(f"must be at least {MIN_KEY_CHARACTERS} printable ASCII characters")
        return key

    @field_validator("api_key_file")
    @classmethod
    def _file_holds_a_key(cls, path: Path | None) -> Path | None:
        if path is not None:
            cls._key_is_a_key(SecretStr(_read_key(path)))
        return path

    @model_validator(mode="after")
    def _key_from_file(self) -> Settings:
        if self.api_key_file is not None and self.api_key is None:
            object.__setattr__(self, "api_key", SecretStr(_read_key(self.api_key_file)))
        if self.api_key is None and not is_loopback(self.host):
            raise ValueError(
                f"host {self.host} is reachable beyond this machine: give a key (--api-key-file, or EMA_API_KEY or "
                "EMA_API_KEY_FILE), or bind 127.0.0.1"
            )
        return self

    def key_bytes(self) -> bytes | None:
        return None if self.api_key is None else self.api_key.get_secret_value().encode()


def unknown_environment(environ: Mapping[str, str]) -> tuple[str, str] | None:
    """(the first ``EMA_*`` variable that names no setting of ``Settings`` or ``EMA_PIPELINE__<size>``, why), the
    setting it likely misspells said: such a variable would be ignored, and the service run on a default the
    operator meant to replace (another history, another key)."""
    names = {f"EMA_{name.upper()}" for name in Settings.model_fields}
    sizes = [*PipelineConfig.model_fields, *PipelineConfig.model_computed_fields]  # the latter: earlier names
    names |= {f"EMA_PIPELINE__{name.upper()}" for name in sizes}
    for variable in sorted(v for v in environ if v.startswith("EMA_") and v not in names):
        near = difflib.get_close_matches(variable, sorted(names), n=1, cutoff=0.85)
        return variable, "is no setting of the service" + (
            f": did you mean {near[0]}?" if near else " (docs/service.md lists them)"
        )
    return None
