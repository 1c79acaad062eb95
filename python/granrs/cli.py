"""The ``granrs`` command line.

Usage::

    granrs --version
    granrs reproduce [--out DIR] [--dt DT] [--chapter KEY ...] [--quiet]
    granrs bench accuracy [--out DIR] [--quick] [--repeats N] [--quiet]

Each subcommand is one ``_add_<name>`` function that declares its arguments and one
``_cmd_<name>`` function that runs it and returns the exit code; :data:`_COMMANDS` lists
them (``run``, ``bench`` and ``calibrate`` are meant to be added the same way).

Exit codes: 0 on success; 2 for invalid input (a usage error, or any
:class:`~granrs.errors.GranrsError`: one line on stderr, no traceback); 1 when a file
cannot be written; 130 on Ctrl-C.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence

from . import __version__
from .errors import GranrsError

__all__ = ["main"]

PROG = "granrs"
#: Exit code of invalid input (argparse's usage errors use the same).
EXIT_INVALID = 2
#: Exit code of an operating-system error (e.g. the output directory is not writable).
EXIT_OS_ERROR = 1
#: Exit code after Ctrl-C.
EXIT_INTERRUPTED = 130


def _add_reproduce(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Declare ``granrs reproduce``."""
    from .report import CHAPTERS

    parser = sub.add_parser(
        "reproduce",
        help="run the thesis's cases and write the reproduction report",
        description=(
            "Run the thesis's cases, compare them with its tables and write DIR/README.md "
            "(Markdown) with its PNG figures in DIR/figures/. Nothing is written if a run "
            "fails."
        ),
    )
    parser.add_argument(
        "--out",
        metavar="DIR",
        default="granrs-report",
        help="output directory (default: ./granrs-report)",
    )
    parser.add_argument(
        "--dt",
        type=float,
        default=1e-4,
        metavar="DT",
        help="integration step in seconds (default: 1e-4, the thesis's 10 kHz)",
    )
    parser.add_argument(
        "--chapter",
        dest="chapters",
        action="append",
        choices=list(CHAPTERS),
        metavar="KEY",
        help=f"chapter to run, repeatable (available: {', '.join(CHAPTERS)}; default: all)",
    )
    parser.add_argument("--quiet", action="store_true", help="no progress output")
    parser.set_defaults(handler=_cmd_reproduce)


def _cmd_reproduce(args: argparse.Namespace) -> int:
    """Run ``granrs reproduce``."""
    from .report import CHAPTERS, reproduce

    chapters = tuple(args.chapters) if args.chapters else tuple(CHAPTERS)
    path = reproduce(args.out, chapters=chapters, dt=args.dt, progress=not args.quiet)
    if not args.quiet:
        print(f"report written to {path}")
    return 0


def _add_bench(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Declare ``granrs bench``."""
    parser = sub.add_parser(
        "bench",
        help="run a benchmark (accuracy: error against time of each integrator setting)",
        description=(
            "Run a benchmark. 'accuracy' compares RK4 (each sign model, a sweep of dt) and "
            "dopri5 (a sweep of rtol) with a fine reference on three free-link scenes and "
            "writes DIR/accuracy.csv, DIR/accuracy.png and DIR/accuracy.md."
        ),
    )
    parser.add_argument("name", choices=["accuracy"], help="benchmark to run")
    parser.add_argument(
        "--out",
        metavar="DIR",
        default="granrs-bench",
        help="output directory (default: ./granrs-bench)",
    )
    parser.add_argument(
        "--quick", action="store_true", help="shorter sweeps and a coarser reference"
    )
    parser.add_argument(
        "--repeats", type=int, default=3, metavar="N", help="timing repeats (default: 3)"
    )
    parser.add_argument("--quiet", action="store_true", help="no progress output")
    parser.set_defaults(handler=_cmd_bench)


def _cmd_bench(args: argparse.Namespace) -> int:
    """Run ``granrs bench``."""
    from .bench import work_precision

    work_precision(args.out, quick=args.quick, repeats=args.repeats, progress=not args.quiet)
    if not args.quiet:
        print(f"benchmark written to {args.out}")
    return 0


#: The subcommands, in help order: each adds its parser and sets ``handler``.
_COMMANDS: tuple[Callable[[argparse._SubParsersAction[argparse.ArgumentParser]], None], ...] = (
    _add_reproduce,
    _add_bench,
)


def build_parser() -> argparse.ArgumentParser:
    """The ``granrs`` argument parser with every subcommand."""
    parser = argparse.ArgumentParser(
        prog=PROG,
        description="granrs: rods, linkages and feet sinking into sand.",
    )
    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for add in _COMMANDS:
        add(sub)
    return parser


def _one_line(exc: BaseException) -> str:
    """The exception's message on one line, naming the offending field if it has one."""
    message = " ".join(str(exc).split()) or type(exc).__name__
    field = getattr(exc, "field", None)
    if field and field not in message:
        message += f" (field: {field})"
    return message


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``granrs`` command line with ``argv`` (default: ``sys.argv[1:]``).

    Returns the exit code instead of exiting (also for ``--help``, ``--version`` and usage
    errors), so that it can be called from Python and tests.
    """
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, usage errors
        return exc.code if isinstance(exc.code, int) else EXIT_INVALID
    try:
        return int(args.handler(args))
    except GranrsError as exc:
        print(f"{PROG}: error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_INVALID
    except OSError as exc:
        print(f"{PROG}: error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_OS_ERROR
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
