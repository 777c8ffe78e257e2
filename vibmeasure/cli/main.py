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
    if isinstance(getattr(args, "file", None), list):
        return _each_file(args, _expand(args.file), out, err)
    return _run(args, out, err)


def _expand(files) -> list:
    """The files as given, a quoted glob (one the shell did not expand: Windows, a script) expanded in
    sorted order; a pattern that matches nothing stays, and its command says the file does not exist."""
    import glob
    out = []
    for f in files:
        hits = sorted(glob.glob(f)) if any(c in f for c in "*?[") and not os.path.exists(f) else []
        out += hits or [f]
    return out


def _each_file(args, files, out, err) -> int:
    """The command on each file in turn, as if run once per file: with --json one array of their
    documents (an error's document in its place), in the order given; a file's pictures and tables
    are named FILE-STEM inserted before the ending; the exit code is the worst of them (Ctrl-C stops)."""
    import copy
    import io
    import json
    from pathlib import Path
    if len(files) == 1:
        args.file = files[0]
        return _run(args, out, err)
    codes, docs = [], []
    for f in files:
        a = copy.copy(args)
        a.file = f
        for opt in ("plot", "csv"):
            if getattr(args, opt, None):
                p = Path(getattr(args, opt))
                setattr(a, opt, str(p.with_name(f"{p.stem}-{Path(f).stem}{p.suffix}")))
        if args.json:
            buf = io.StringIO()
            code = _run(a, buf, err)
            try:
                doc = json.loads(buf.getvalue())
            except ValueError:
                doc = {"error": "the command printed no JSON document", "exit_code": code}
            docs.append({"file": f, **doc} if isinstance(doc, dict) else {"file": f, "result": doc})
        else:
            print(f"== {f}", file=out)
            code = _run(a, out, err)
        codes.append(code)
        if code == 130:
            break
    if args.json:
        json.dump(docs, out, indent=2)
        out.write("\n")
    return max(codes)


def _run(args, out, err) -> int:
    """One command on one input, every failure turned into its line and exit code."""
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
