"""affordplan.log: a command line shows the library's messages as plain lines on stderr and leaves logging that
someone else configured alone (cli_logging); its bad input ends it with one line and status 2 (one_line_errors)."""

from __future__ import annotations

import logging
from contextlib import contextmanager

import pytest

from affordplan.errors import InputError
from affordplan.log import CLI_LOGGERS, cli_logging, one_line_errors


@contextmanager
def bare_logging():
    """Logging as a fresh ``python -m ...`` process has it: no handler on the root logger, restored afterwards.
    (pytest installs its capture handlers there for each phase of a test, so this runs inside the test's body.)"""
    root = logging.getLogger()
    handlers, level = root.handlers[:], root.level
    levels = {name: logging.getLogger(name).level for name in CLI_LOGGERS}
    root.handlers.clear()
    try:
        yield root
    finally:
        for handler in root.handlers[:]:
            root.removeHandler(handler)
            handler.close()
        root.handlers.extend(handlers)
        root.setLevel(level)
        for name, lvl in levels.items():
            logging.getLogger(name).setLevel(lvl)


def test_library_messages_reach_stderr_as_plain_lines_and_stdout_stays_clean(capsys):
    with bare_logging() as root:
        cli_logging()
        assert len(root.handlers) == 1
        logging.getLogger("primitives.training.train").info("no checkpoint in %s yet", "runs/push")
        logging.getLogger("planner.plan").warning("warning: %d steps", 3)
        logging.getLogger("__main__").info("from python -m")  # a module run as a program logs under __main__
        logging.getLogger("primitives.training.train").debug("not without verbose")
    out, err = capsys.readouterr()
    assert out == ""
    assert err.splitlines() == ["no checkpoint in runs/push yet", "warning: 3 steps", "from python -m"]


def test_other_libraries_show_warnings_only(capsys):
    with bare_logging():
        cli_logging()
        logging.getLogger("some_other_library").info("chatter")
        logging.getLogger("some_other_library").warning("a real problem")
    assert capsys.readouterr().err.splitlines() == ["a real problem"]


def test_verbose_shows_debug_messages_of_the_packages(capsys):
    with bare_logging():
        cli_logging(verbose=True)
        logging.getLogger("affordplan.sim").debug("detail")
        logging.getLogger("some_other_library").debug("not ours")
    assert capsys.readouterr().err.splitlines() == ["detail"]


def test_a_second_call_adds_nothing(capsys):
    with bare_logging() as root:
        cli_logging()
        cli_logging(verbose=True)  # already configured: the first call's settings stand
        assert len(root.handlers) == 1
        logging.getLogger("primitives").debug("hidden")
        logging.getLogger("primitives").info("once")
    assert capsys.readouterr().err.splitlines() == ["once"]


def test_logging_configured_by_the_caller_is_left_alone():
    with bare_logging() as root:
        handler = logging.NullHandler()
        root.addHandler(handler)
        before = {name: logging.getLogger(name).level for name in CLI_LOGGERS}
        cli_logging(verbose=True)
        assert root.handlers == [handler]
        assert {name: logging.getLogger(name).level for name in CLI_LOGGERS} == before



def test_a_command_lines_bad_input_is_one_line_and_status_2_and_a_bug_is_a_traceback(capsys):
    @one_line_errors("prog", OSError)
    def main(argv=None):
        if argv == ["bad"]:
            raise InputError("--x must be positive, got -1")
        if argv == ["missing"]:
            raise FileNotFoundError("no file runs/x.npz")
        if argv == ["bug"]:
            raise KeyError("a bug")
        return 0

    assert main([]) == 0 and main.__name__ == "main"
    assert main(["bad"]) == 2 and capsys.readouterr().err == "prog: error: --x must be positive, got -1\n"
    assert main(["missing"]) == 2 and capsys.readouterr().err == "prog: error: no file runs/x.npz\n"
    with pytest.raises(KeyError):
        main(["bug"])


def test_output_cut_off_by_its_reader_ends_a_command_line_quietly_with_status_1(capsys):
    """``affordplan bench compare ... | head -2`` closed the pipe: no traceback, no 'error:' line (a broken pipe is an
    OSError, which a command may catch as bad input)."""
    @one_line_errors("prog", OSError)
    def main(argv=None):
        raise BrokenPipeError(32, "Broken pipe")

    assert main([]) == 1
    assert capsys.readouterr().err == ""
