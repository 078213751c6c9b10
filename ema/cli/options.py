"""Options shared by several commands, their defaults read from the one config (never restated)."""

from __future__ import annotations

import contextlib
import importlib.util
import json
import os
import sys
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any, TypeVar

import click

from ema.estimate.sizes import SIZES as PIPELINE_SIZES
from ema.model.bounds import MAX_THREADS

F = TypeVar("F", bound=Callable[..., Any])
EXISTING = click.Path(exists=True, dir_okay=False, path_type=Path)  # a file that must be there


class _Output(click.Path):
    """A file the command writes (its folder made as the flag is read, as a results CSV's always was) or a folder it
    writes into (made): one that cannot be made is said naming the flag before any work, never after a
    calibration's minutes."""

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        path = super().convert(value, param, ctx)
        written = Path(os.fsdecode(path))
        folder, which = (written, "it") if self.dir_okay else (written.parent, "its folder")
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as error:
            self.fail(f"{value}: {which} cannot be made ({error.strerror})", param, ctx)
        if not os.access(folder, os.W_OK | os.X_OK):
            self.fail(f"{value}: {which} cannot be written to", param, ctx)
        return path


class _Figure(_Output):
    """A PNG the command draws: refused as the flag is read where the ``plots`` extra (matplotlib) is missing,
    never after the work it would draw."""

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        if importlib.util.find_spec("matplotlib") is None:
            self.fail(f"{value}: drawing needs the optional extra 'plots': pip install 'ema[plots]'", param, ctx)
        return super().convert(value, param, ctx)


OUTPUT_FILE = _Output(dir_okay=False, path_type=Path)
OUTPUT_FOLDER = _Output(file_okay=False, path_type=Path)
FIGURE_FILE = _Figure(dir_okay=False, path_type=Path)
FLAG_SIZES = {  # flag -> PipelineConfig field
    "--sims": "n_simulations",
    "--checks": "check_simulations",
    "--timesteps": "n_timesteps",
    "--hidden": "hidden_units",
    "--members": "members",
    "--seed": "seed",
}
SIZE_FLAGS = {f"{field}": flag for flag, field in FLAG_SIZES.items()}  # an InputError's field -> the flag typed


def sizes(function: F) -> F:
    """--sims, --checks, --timesteps, --hidden, --members, --seed with PipelineConfig's defaults."""
    for flag, field in reversed(FLAG_SIZES.items()):
        size = PIPELINE_SIZES[field]
        kind = click.IntRange(size.low, size.high)
        function = click.option(flag, field, type=kind, default=size.default, help=size.description)(function)
    return function


def actuator(function: F) -> F:
    return click.option(
        "--actuator",
        "actuator_file",
        type=EXISTING,
        default=None,
        metavar="A.json",
        help="the actuator's ema-actuator/1 document [default: the thesis's, examples/actuator.json]",
    )(function)


def actuator_document(path: Path | None) -> Any:
    """The document in ``path``, or the default (``ema.model.actuator.THESIS``) where none was given."""
    from ema.model.actuator import THESIS, read_actuator

    return THESIS if path is None else read_actuator(path)


def say_if_compiling(windows: Any) -> None:
    """Where a window will be simulated and Numba's cache does not hold the simulator's kernel yet (a fresh install),
    say on standard error that this first run compiles (about 30 s, once), rather than sit silent in *prepare*."""
    from ema.kinds import learns

    if not any(learns(window) for window in windows):
        return
    from ema.kinds import thesis_kernel_cached

    if thesis_kernel_cached() is False:
        print("ema: first run: compiling the simulation kernels into Numba's cache (about 30 s, once)", file=sys.stderr)


def kind_given(windows: Any, path: Path | None) -> None:
    """Where no --actuator was given, an InputError naming the flag for a window of another kind than the default
    document's: only the default kind has a document ema can assume (the thesis's); a ball screw's, a servo's or a
    geared servo's constants are its own, and reading its log with another's would answer confidently and wrongly."""
    if path is not None:
        return
    from ema.model.actuator import THESIS
    from ema.model.checks import InputError

    for window in windows:
        if window.kind != THESIS.kind:
            raise InputError(
                "--actuator",
                f"is needed: window {window.window_id} is a {window.kind} actuator's "
                f"({', '.join(window.signal_names)}), and only a {THESIS.kind} one has a default document (the "
                "thesis's): give the actuator's own ema-actuator/1 document",
            )


def log_map(function: F) -> F:
    return click.option(
        "--log-map",
        "log_map_file",
        type=EXISTING,
        default=None,
        metavar="M.json",
        help="an ema-logmap/1 document: read logs (CSV, MATLAB, NPZ) in their own columns and units",
    )(function)


def span(bounds: tuple[float, float]) -> str:
    """A range for the help, as the model bounds it: "90–215"."""
    return "–".join(f"{bound:g}" for bound in bounds)


WINDOW_S_RANGE = (0.1, 3600.0)


class _WindowOption(click.Option):
    """``--window-s``, its default read from the kinds' facts when help is shown (they load pydantic: a command's
    help is read rarely, ``ema --help`` often, and must stay quick)."""

    def get_help_record(self, ctx: click.Context) -> tuple[str, str] | None:
        from ema.model.kinds import KINDS

        cut = "; ".join(f"a {f.name} recording {f.cut_s:g} s" for f in KINDS.values() if f.cut_s is not None)
        self.help = f"cut recordings into windows of this length [s]  [default: {cut}; any other kind's log whole]"
        return super().get_help_record(ctx)


def window_s(function: F) -> F:
    return click.option("--window-s", cls=_WindowOption, type=click.FloatRange(*WINDOW_S_RANGE), default=None)(function)


def log_map_document(path: Path | None) -> Any:
    """The log map in ``path``, or None."""
    from ema.model.logmap import read_logmap

    return None if path is None else read_logmap(path)


def as_json(function: F) -> F:
    return click.option("--json", "as_json", is_flag=True, help="print one JSON document")(function)


def threads(function: F) -> F:
    return click.option(
        "--threads",
        type=click.IntRange(1, MAX_THREADS),
        default=None,
        help="thread budget [default: EMA_THREADS, else cores]",
    )(function)


def pipeline_config(values: Mapping[str, Any]) -> Any:
    """The PipelineConfig from a command's size options; a bad value names its flag."""
    from ema.estimate.config import PipelineConfig
    from ema.model.checks import validated

    with flags_named(SIZE_FLAGS):
        return validated(PipelineConfig, {field: values[field] for field in FLAG_SIZES.values()}, "sizes")


@contextlib.contextmanager
def flags_named(flags: Mapping[str, str]) -> Iterator[None]:
    """Re-raise an InputError about an internal field as one about the flag the user typed (a field below one the
    flag sets named after it: ``effects.viscous`` -> ``--effect viscous``)."""
    from ema.model.checks import InputError

    try:
        yield
    except InputError as exc:
        flag = flags.get(exc.field) or next((f for field, f in flags.items() if exc.field.endswith(field)), None)
        if flag is None:
            below = next(((field, f) for field, f in flags.items() if exc.field.startswith(f"{field}.")), None)
            if below is None:
                raise
            flag = f"{below[1]} {exc.field[len(below[0]) + 1 :]}"
        raise InputError(flag, exc.message) from None


@contextlib.contextmanager
def about_file(path: Path) -> Iterator[None]:
    """Re-raise an InputError about a window's field as one about that field of the file the user gave."""
    from ema.model.checks import InputError

    try:
        yield
    except InputError as exc:
        if exc.field.startswith(str(path)):
            raise
        raise InputError(f"{path}: {exc.field}", exc.message) from None


def progress(text: str) -> None:
    print(f"ema: {text}…", file=sys.stderr, flush=True)


class NothingAnsweredError(Exception):
    """A batch command ran, but no window of its input was answered: exit 2 after its report."""


class PipeClosedError(Exception):
    """The reader of our output went away (``| head``): not an OSError, so that click leaves it to us."""


def emit(result: Any, as_json_flag: bool, show: Callable[[Any], None]) -> None:
    """One JSON document on stdout with --json, else the human table."""
    try:
        if as_json_flag:
            document = result.model_dump(mode="json", by_alias=True) if hasattr(result, "model_dump") else result
            click.echo(json.dumps(document))
        else:
            show(result)
        sys.stdout.flush()
    except BrokenPipeError:
        raise PipeClosedError from None


SERVICE_URL = "http://127.0.0.1:8000"  # where ema serve listens by default


def service(function: F) -> F:
    """``--url``, the service's root address (checked as the flag is read: an http(s) address with a host), and
    ``--api-key-file``, its key."""
    keyed = click.option(
        "--api-key-file", type=EXISTING, default=None, help="file holding the API key [default: EMA_API_KEY]"
    )(function)
    return click.option("--url", default=SERVICE_URL, callback=_http_address, help="the service's root address")(keyed)


def _http_address(_: click.Context, parameter: click.Parameter, value: str) -> str:
    import urllib.parse

    parts = urllib.parse.urlsplit(value)
    if parts.scheme not in ("http", "https") or not parts.hostname:
        raise click.BadParameter(f"{value!r} is not an http(s) address such as {SERVICE_URL}", param=parameter)
    return value.rstrip("/")


def database_setting(_: click.Context, parameter: click.Parameter, value: str | None) -> str | None:
    """A history setting checked as the flag is read: a malformed address is exit 2 naming the flag, before any
    work (``ema.history.open.setting_error``)."""
    if value is None:
        return None
    from ema.history.open import setting_error

    error = setting_error(value)
    if error is not None:
        raise click.BadParameter(error, param=parameter)
    return value
