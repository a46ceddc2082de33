"""The ``xfuzzy-rrt`` console script.

Why a custom :func:`main` instead of calling the typer app directly: the contract in SPEC.md is
that *every* bad input (a usage error, a bad scenario, a bad rulebook) produces exactly one line
``error: <where>: <what>`` on stderr and exit code 2, never a traceback or a boxed help panel.
So the app runs in non-standalone mode and this function maps exceptions to exit codes.

Heavy libraries (numba, pandas, plotly) are imported inside the command functions so that
``xfuzzy-rrt --help`` stays fast.
"""

from __future__ import annotations

import os
import sys
from typing import Callable

import typer

from xfuzzy_rrt.errors import InputError, RulebookError

app = typer.Typer(
    name="xfuzzy-rrt",
    help="Fuzzy-RRT motion planning for a 2-DOF surgical arm, with inspectable rulebooks.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)


def _register() -> None:
    from xfuzzy_rrt.cli import bench as bench_cli
    from xfuzzy_rrt.cli import explain as explain_cli
    from xfuzzy_rrt.cli import plan as plan_cli
    from xfuzzy_rrt.cli import rules as rules_cli
    from xfuzzy_rrt.cli import scenarios as scenarios_cli
    from xfuzzy_rrt.cli import train as train_cli

    plan_cli.register(app)
    bench_cli.register(app)
    explain_cli.register(app)
    __import__("xfuzzy_rrt.cli.report", fromlist=["register"]).register(app)
    train_cli.register(app)
    __import__("xfuzzy_rrt.cli.evaluate", fromlist=["register"]).register(app)
    __import__("xfuzzy_rrt.cli.robustness", fromlist=["register"]).register(app)
    __import__("xfuzzy_rrt.cli.tune", fromlist=["register"]).register(app)
    app.add_typer(rules_cli.app, name="rules")
    app.add_typer(scenarios_cli.app, name="scenarios")


_register()


def _print_error(line: str) -> None:
    sys.stderr.write(f"error: {line}\n")
    sys.stderr.flush()


#: Commands that run compiled planners (``rules`` subcommands that plan are listed as pairs).
_PLANNING = {"plan", "bench", "demo", "explain", "train", "tune", ("rules", "coverage"),
             ("rules", "diff"), ("rules", "simplify"), ("scenarios", "generate")}


def _announce_first_compile(args: list[str]) -> Callable[[], None]:
    """One stderr line when numba starts compiling (the first run after an install takes tens
    of seconds: say why rather than look hung). Nothing when the kernels come from its cache.
    Returns what removes the listener again (called when the command ends)."""
    words = [a for a in args if not a.startswith("-")][:2]
    if not words or "--help" in args or not (words[0] in _PLANNING or tuple(words) in _PLANNING):
        return lambda: None
    from xfuzzy_rrt.compile_notice import notify_first_compile

    def say() -> None:
        sys.stderr.write("compiling planners, first run only…\n")
        sys.stderr.flush()

    return notify_first_compile(say)


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; return (and, as a script, exit with) the process exit code."""
    args = sys.argv[1:] if argv is None else list(argv)
    command = typer.main.get_command(app)
    stop_notice = _announce_first_compile(args)
    try:
        rv = command.main(args=args, prog_name="xfuzzy-rrt", standalone_mode=False)
    except RulebookError as exc:
        for line in exc.lines():
            _print_error(line)
        code = 2
    except InputError as exc:
        _print_error(str(exc))
        code = 2
    except OSError as exc:  # an unusable path argument: --out naming a directory or a file, ...
        where = exc.filename2 if exc.filename2 is not None else exc.filename
        _print_error(f"{where}: {exc.strerror or exc}" if where is not None else str(exc))
        code = 2
    except typer.exceptions.TyperException as exc:  # click usage errors live under this base
        name = type(exc).__name__
        if name == "NoArgsIsHelpError":
            ctx = getattr(exc, "ctx", None)
            sys.stdout.write((ctx.get_help() if ctx is not None else "") + "\n")
            code = 0
        else:
            message = exc.format_message().replace("\n", " ").strip()
            _print_error(message)
            code = getattr(exc, "exit_code", 2) or 2
    except typer.Exit as exc:
        code = exc.exit_code
    except typer.Abort:
        _print_error("aborted")
        code = 1
    except KeyboardInterrupt:
        code = 130
    else:
        code = rv if isinstance(rv, int) else 0
    finally:
        stop_notice()
    if argv is None:
        if "ompl" in sys.modules:
            # OMPL 2.0.1's bindings (nanobind) keep some planner objects alive on purpose and
            # list them as "leaked" on stderr while the interpreter shuts down, after our
            # output is complete. Everything is written and flushed by now, so leave without
            # that teardown and keep stderr to what the command said.
            sys.stdout.flush()
            sys.stderr.flush()
            os._exit(code)
        sys.exit(code)
    return code


if __name__ == "__main__":  # pragma: no cover
    main()
