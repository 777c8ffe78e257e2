"""``vibmeasure``: the parser assembled from one module per command, and the one exit-code policy."""

from __future__ import annotations

import os
import sys

from .. import __version__
from ..core.errors import VibMeasureError
from . import batch, compare, diagnose, frf, model, oma, report, ringdown, spectrum, srs, store, trend
from ._common import Parser

# command -> module; each module has register(sub) and run(args, out, err); "modes" is frf's second command
COMMANDS = {"ringdown": ringdown, "spectrum": spectrum, "frf": frf, "modes": frf, "model": model,
            "compare": compare, "diagnose": diagnose, "batch": batch, "trend": trend, "demo": report,
            "report": report, "srs": srs, "oma": oma, "store": store}


def build_parser() -> Parser:
    """The whole command line: one subparser per command, in the order ``--help`` lists them."""
    p = Parser(prog="vibmeasure", description="Vibration measurements to fn, zeta and FRFs you can trust.")
    p.add_argument("--version", action="version", version=f"vibmeasure {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=Parser)
    for mod in (ringdown, spectrum, frf, model, compare, diagnose, batch, trend, store, report, srs, oma):
        mod.register(sub)
    return p


def _writes_fail_not_kill() -> None:
    """A file-size limit (ulimit -f) makes a write fail with an error the command names, not SIGXFSZ,
    whose default kills the process mid-file."""
    import signal
    import threading
    if hasattr(signal, "SIGXFSZ") and threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)


def main(argv=None, *, out=None, err=None) -> int:
    """Run the command line and return its exit code.

    Parameters
    ----------
    argv : list of str, optional
        The arguments (default ``sys.argv[1:]``).
    out, err : file, optional
        Where results and messages go (default stdout and stderr).

    Returns
    -------
    int
        0 ok, 1 an alarm (``compare``), 2 an error in the input or the usage, 3 a defect of vibmeasure.
        A user never sees a Python traceback (VIBMEASURE_DEBUG=1 shows it for a report).

    Examples
    --------
    >>> from vibmeasure.cli import main
    >>> main(["model", "--help"])  # doctest: +SKIP
    """
    out = out or sys.stdout
    err = err or sys.stderr
    _writes_fail_not_kill()
    args = build_parser().parse_args(argv)
    try:
        return COMMANDS[args.command].run(args, out, err)
    except BrokenPipeError:  # the reader of our output went away (| head)
        return 0
    except KeyboardInterrupt:   # Ctrl-C: said in one line; what a store committed before it stays
        return _failed(args, out, err, "interrupted", 130)
    except (VibMeasureError, OSError) as exc:
        return _failed(args, out, err, f"error: {exc}", 2)
    except Exception as exc:  # noqa: BLE001 - the last net: a defect, said as one
        if os.environ.get("VIBMEASURE_DEBUG"):
            raise
        return _failed(args, out, err, f"error: unexpected {type(exc).__name__}: {exc}. This is a defect of "
                       "vibmeasure; please report it with the command (VIBMEASURE_DEBUG=1 shows the traceback)", 3)


def _failed(args, out, err, message: str, code: int) -> int:
    """Say a failure in one line on stderr and, with --json, as the one JSON document on stdout too
    (a script reading stdout always gets JSON: the results, or {"error": ..., "exit_code": ...})."""
    print(f"vibmeasure: {message}", file=err)
    if getattr(args, "json", False):
        import json
        print(json.dumps({"error": message.removeprefix("error: "), "exit_code": code}), file=out)
    return code
