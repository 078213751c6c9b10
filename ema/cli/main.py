"""The ``ema`` command line: one click group, heavy imports inside the commands (``ema --help`` stays fast).

Exit status: 0 success, 2 bad input (the message names the flag or file given), 3 the service could not be
reached or failed (not the input's fault, nor ema's here), 1 internal error, 130 interrupted. With ``--json``
standard output holds exactly one JSON document; progress and warnings go to standard error. A closed pipe
(``ema simulate ... | head``) ends quietly.
"""

from __future__ import annotations

import gc
import inspect
import os
import sys
from collections.abc import Sequence

import click

from ema.cli import commands_fleet, commands_local, commands_remote, commands_serve
from ema.cli.options import NothingAnsweredError, PipeClosedError
from ema.model.collector import collect_less_often

EXIT_OK, EXIT_INTERNAL, EXIT_BAD_INPUT, EXIT_SERVICE, EXIT_INTERRUPTED = 0, 1, 2, 3, 130


@click.group(context_settings={"help_option_names": ["-h", "--help"], "show_default": True})
@click.version_option(package_name="ema", message="%(prog)s %(version)s")
def ema() -> None:
    """Onboard health monitor for electromechanical actuators (EMAs) of several kinds: the thesis's rotary EMA on a
    gear train, a ball screw, servo axes; each command's --help names the kinds it serves and what each one is."""


for module in (commands_local, commands_serve, commands_remote, commands_fleet):
    for command in module.COMMANDS:
        ema.add_command(command)

# The kinds a command serves where not every kind (none: the command reads no actuator's windows), by a kind's fact
SERVES_ONLY = {"simulate": "simulated", "bench": "default", "schemas": None}


def say_kinds() -> None:
    """Each command's help closed by the kinds it serves, from the kinds' facts: loaded only for a help page, as the
    facts load the documents (``ema --help`` stays quick)."""
    from ema.model.kinds import DEFAULT_KIND, KINDS, kinds_with

    for name, command in ema.commands.items():
        fact = SERVES_ONLY.get(name, "all")
        if fact is None or "\n\nKinds:\n" in (command.help or ""):  # none served, or said already (in one process)
            continue
        served = (DEFAULT_KIND,) if fact == "default" else tuple(KINDS) if fact == "all" else kinds_with(fact)
        said = "\n".join(f"  {kind}: {KINDS[kind].summary}" for kind in served)
        command.help = f"{inspect.cleandoc(command.help or '')}\n\nKinds:\n\n\b\n{said}"


EXTRAS = {  # a module an optional extra brings -> the extra
    "fastapi": "service",
    "uvicorn": "service",
    "pydantic_settings": "service",
    "fastapi_offline": "service",
    "sqlalchemy": "history",
    "alembic": "history",
    "matplotlib": "plots",
    "ray": "fleet",
    "psycopg": "postgres",
}


def _bad_input(exc: BaseException) -> str | None:
    """The message for an error that is the user's input (named field, flag or file), else None."""
    if isinstance(exc, ModuleNotFoundError) and (exc.name or "").split(".")[0] in EXTRAS:
        extra = EXTRAS[(exc.name or "").split(".")[0]]
        return f"this needs the optional extra '{extra}': pip install 'ema[{extra}]'"
    from ema.history.refusals import StorageError
    from ema.model.checks import InputError

    if isinstance(exc, InputError):
        return f"bad input: {exc}"
    if isinstance(exc, StorageError):
        return f"bad input: {exc}"
    if isinstance(exc, OSError) and exc.filename is not None:
        return f"{exc.filename}: {exc.strerror}"
    return None


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``ema`` and return its exit status (never a traceback for input errors or interruptions); the
    simulator's threads end with it, however it ends."""
    try:
        return _run(list(sys.argv[1:] if argv is None else argv))
    finally:
        simulator = sys.modules.get("ema.model.runtime")
        if simulator is not None:
            simulator.shutdown()


def _run(arguments: list[str]) -> int:
    name = next((a for a in arguments if not a.startswith("-")), "")
    if name and {"-h", "--help"} & set(arguments):
        say_kinds()
    try:
        ema.main(args=arguments, prog_name="ema", standalone_mode=False)
        return EXIT_OK
    except click.exceptions.Abort:
        print("\nema: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except click.ClickException as exc:
        exc.show()
        return exc.exit_code
    except KeyboardInterrupt:
        print("\nema: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except NothingAnsweredError as exc:
        print(f"ema {name}: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except PipeClosedError:
        # The reader stopped reading (| head): nothing left to say, and Python must not try at exit.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    except Exception as exc:
        from ema.cli.replay import ServiceError

        message = _bad_input(exc)
        if message is not None:
            print(f"ema {name}: {message}", file=sys.stderr)
            return EXIT_BAD_INPUT
        if isinstance(exc, ServiceError):
            print(f"ema {name}: {exc}", file=sys.stderr)
            return EXIT_SERVICE
        print(f"ema {name}: internal error: {type(exc).__name__}: {exc}", file=sys.stderr)
        return EXIT_INTERNAL


def console() -> int:
    """``main`` as the ``ema`` program runs it: the cyclic collector set for a program that loads
    NumPy, SciPy and Numba (``ema.model.collector``), and what the command built is freed by the process's end, so the
    collector is told not to walk it at exit (the loaded modules' objects)."""
    collect_less_often()  # before the command loads the pipeline and the kernels
    status = main()
    gc.freeze()
    return status


if __name__ == "__main__":
    sys.exit(console())
