"""Logging for the command lines: the one place that decides how library messages reach a terminal.

Library code never prints a diagnostic, progress or status message: each module logs through
``logger = logging.getLogger(__name__)`` and leaves the output to whoever runs it. A program that embeds the library
configures :mod:`logging` as it likes; a command line (a ``main()``) calls :func:`cli_logging` once, so that those
messages reach the user as plain lines on stderr, while the program's results (tables, JSON) stay on stdout.
"""

from __future__ import annotations

import functools
import io
import logging
import os
import sys
from collections.abc import Callable

from affordplan.errors import AffordplanError

Main = Callable[[list[str] | None], int]  # a command line's ``main(argv) -> exit status``

# The loggers a command line turns up: the three packages, and ``__main__``, the name a module run with
# ``python -m package.module`` logs under.
CLI_LOGGERS = ("affordplan", "primitives", "planner", "__main__")


def cli_logging(verbose: bool = False) -> None:
    """Show the library's log messages on stderr as plain lines (``%(message)s``), for a command line's ``main()``.

    Does nothing when the root logger already has a handler: logging configured by the program that called
    ``main()`` (or by pytest, whose capture handlers are installed during a test) is left as it is, so calling this
    twice, or from an embedding program, changes nothing.

    Otherwise installs one stderr handler on the root logger and lets the loggers of ``affordplan``, ``primitives``,
    ``planner`` and ``__main__`` through from INFO (from DEBUG if ``verbose``); other libraries' loggers keep the
    root's WARNING, so their chatter stays out of the output while their warnings still show.

    Args:
        verbose: also show DEBUG messages of the three packages.
    """
    root = logging.getLogger()
    if root.handlers:
        return
    logging.basicConfig(level=logging.WARNING, format="%(message)s")
    level = logging.DEBUG if verbose else logging.INFO
    for name in CLI_LOGGERS:
        logging.getLogger(name).setLevel(level)


def _silence_stdout() -> None:
    """Point stdout's file descriptor at the null device, so that the interpreter's flush at exit does not fail on the
    pipe its reader closed (the recipe of Python's documentation on SIGPIPE)."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError, io.UnsupportedOperation):  # stdout replaced (tests), or closed
        pass


def one_line_errors(prog: str, *errors: type[BaseException]) -> Callable[[Main], Main]:
    """Decorate a command line's ``main(argv) -> int``: an :class:`~affordplan.errors.AffordplanError`, or one of
    ``errors``, raised in it is printed as one line, ``{prog}: error: {message}``, on stderr, and ``main`` returns 2,
    argparse's status for a refused command line. Output cut off by its reader (``affordplan ... | head``) ends ``main``
    quietly with status 1, as a closed pipe ends other tools. Anything else propagates with its traceback (a bug is
    not bad input)."""
    caught = (AffordplanError, *errors)

    def decorate(main: Main) -> Main:
        @functools.wraps(main)
        def run(argv: list[str] | None = None) -> int:
            try:
                return main(argv)
            except BrokenPipeError:  # before OSError, which some commands catch as bad input
                _silence_stdout()
                return 1
            except caught as exc:
                print(f"{prog}: error: {exc}", file=sys.stderr)
                return 2

        return run

    return decorate
