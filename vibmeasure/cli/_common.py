"""What every command shares: the parser class, the warning and JSON policy, pictures and progress."""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from contextlib import contextmanager

from ..core.errors import QualityWarning, VibMeasureError


class Parser(argparse.ArgumentParser):
    """argparse with our error line: argparse's own usage errors get the same prefix and exit code (2)."""

    def error(self, message):
        self.print_usage(sys.stderr)
        print(f"vibmeasure: error: {message}", file=sys.stderr)
        raise SystemExit(2)


@contextmanager
def quality_warnings():
    """Collect the QualityWarnings raised inside the block: yields a list filled with their messages
    when the block ends (other warnings are swallowed: the command line prints only its own lines)."""
    msgs: list = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", QualityWarning)
        yield msgs
    msgs.extend(str(w.message) for w in caught if issubclass(w.category, QualityWarning))


def print_warnings(msgs, err) -> None:
    """One ``vibmeasure: warning: ...`` line on stderr per message."""
    for m in msgs:
        print(f"vibmeasure: warning: {m}", file=err)


def print_written(args, err, what=("csv", "plot")) -> None:
    """One ``vibmeasure: wrote PATH`` line on stderr per output file the command was asked to write."""
    for name in what:
        if getattr(args, name, None):
            print(f"vibmeasure: wrote {getattr(args, name)}", file=err)


def add_files(parser, what: str) -> None:
    """The command's input files: one or several (a quoted glob is expanded by ``main``), one result
    each; the command's own ``run`` sees one file at a time."""
    parser.add_argument("file", nargs="+", help=f"{what} (several files, or a quoted glob: one result each)")


MODE_HEADER = f"{'mode':>4}  {'fn [Hz]':>14}  {'± std':>10}  {'zeta':>10}  {'± std':>9}"


def mode_row(i, fn, fn_std, zeta, zeta_std, flags=(), extra="") -> str:
    """One mode as a table row, each value rounded to its std by the one rule (core.rounding)."""
    from ..core.rounding import with_std
    f, fs = with_std(fn, fn_std)
    z, zs = with_std(zeta, zeta_std)
    return f"{i + 1:>4}  {f:>14}  {fs:>10}  {z:>10}  {zs:>9}  {extra}{','.join(flags)}"


def emit_json(doc: dict, out, *, allow_nan: bool = False) -> None:
    """The command's one JSON document on stdout (NaN refused: JSON has none, ``jsonable`` maps it)."""
    json.dump(doc, out, indent=2, allow_nan=allow_nan)
    out.write("\n")


def plot_module():
    """vibmeasure.plot with matplotlib's file backend selected: the command line only writes pictures."""
    from .. import plot
    plot.file_backend()
    return plot


def save_figure(fig, path) -> None:
    """Write the figure atomically, then close it (also when writing fails)."""
    from ..plot import save_figure as _save
    try:
        _save(fig, path)
    except ValueError as exc:
        raise VibMeasureError(str(exc)) from None


class Progress:
    """A progress bar on stderr that appears only once work has taken more than a moment."""

    def __init__(self, err, label, after_s=1.5):
        self.err, self.label, self.after, self.t0, self.shown = err, label, after_s, time.time(), False
        self.last = -1

    def __call__(self, fraction):
        if time.time() - self.t0 < self.after and not self.shown:
            return
        pct = int(100 * fraction)
        if pct == self.last:
            return
        self.last, self.shown = pct, True
        bar = "#" * (pct // 4) + "." * (25 - pct // 4)
        self.err.write(f"\r{self.label} [{bar}] {pct:3d}%")
        self.err.flush()

    def close(self):
        if self.shown:
            self.err.write("\n")
            self.err.flush()
