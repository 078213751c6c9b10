"""``ema serve``: the HTTP service, its settings checked (the port, the history) before anything loads."""

from __future__ import annotations

import os
from typing import Any

import click

from ema.cli.options import EXISTING, flags_named


@click.command()
@click.option("--host", default=None, help="bind address [default: EMA_HOST, else 127.0.0.1]")
@click.option("--port", type=click.IntRange(1, 65535), default=None, help="port [default: EMA_PORT, else 8000]")
@click.option(
    "--database",
    default=None,
    help="the history: an SQLite file, or a postgresql://user@host:port/db address [default: EMA_DATABASE, else "
    "$XDG_DATA_HOME/ema/history.sqlite3]",
)
@click.option("--api-key-file", type=EXISTING, default=None, help="a file holding the API key (or EMA_API_KEY)")
def serve(**flags: Any) -> None:
    """Run the HTTP service (all settings: EMA_* environment variables; the flags win)."""
    import uvicorn
    from pydantic import ValidationError

    from ema.model.checks import InputError, from_validation
    from ema.service.config import Settings, unknown_environment
    from ema.service.main import create_app

    unknown = unknown_environment(os.environ)
    if unknown is not None:
        raise InputError(*unknown)
    try:
        settings = Settings(**{k: v for k, v in flags.items() if v is not None})
    except ValidationError as exc:
        error = from_validation(exc)
        field = "host" if error.field == "document" else error.field  # the one check across fields: host vs key
        raise InputError(f"--{field.replace('_', '-')} / EMA_{field.upper()}", error.message) from None
    _check_port_free(settings.host, settings.port)  # before the history: a busy port creates no file
    with flags_named({"database": "--database / EMA_DATABASE"}):
        _check_history(settings.database, settings.min_free_bytes)
    uvicorn.run(create_app(settings), host=settings.host, port=settings.port, log_level="info")


def _check_history(database: str, min_free_bytes: int) -> None:
    """InputError naming --database where the history cannot be opened or cannot take a write now."""
    from ema.history.open import open_history
    from ema.history.refusals import StorageError
    from ema.model.checks import InputError

    try:
        history = open_history(database, min_free_bytes)
        try:
            history.probe()
        finally:
            history.close()
    except StorageError as exc:
        raise InputError("--database / EMA_DATABASE", str(exc)) from None


def _check_port_free(host: str, port: int) -> None:
    """InputError naming --port where the address is taken (uvicorn would exit 3 after loading everything)."""
    import socket

    from ema.model.checks import InputError

    try:
        with socket.create_server((host, port)):
            pass
    except OSError as exc:
        raise InputError("--port / EMA_PORT", f"{host}:{port} cannot be bound ({exc.strerror})") from None


COMMANDS = (serve,)
