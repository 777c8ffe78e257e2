"""The ``batch`` command: many records analysed into a measurement store."""

from __future__ import annotations

import contextlib
import signal

from ._common import emit_json


def register(sub) -> None:
    """Add the command's parser to the subparsers ``sub``."""
    bt = sub.add_parser("batch", help="analyse many records into a measurement store (serially or on Dask)",
                        description="Analyse files, folders and globs (and/or a manifest CSV) into a vm.Store; "
                                    "inputs already in the store are skipped.")
    bt.add_argument("inputs", nargs="*", help="files, folders or globs")
    bt.add_argument("--store", required=True, help="the store: a .db file (SQLite), a postgresql:// URL or an .h5 "
                                                   "file; created when missing")
    bt.add_argument("--manifest", help="CSV: file, asset, point, channel, rpm, bearing, model, time, unit, fs, "
                                       "tach, pulses_per_rev")
    bt.add_argument("--task", default="diagnose",
                    help="ringdown, modes, spectrum, diagnose, compare, or several joined by + (default diagnose)")
    bt.add_argument("--workers", type=int, help="local Dask cluster with this many worker processes")
    bt.add_argument("--scheduler", metavar="tcp://HOST:PORT", help="an existing Dask cluster's scheduler")
    bt.add_argument("--force", action="store_true", help="analyse inputs already in the store again")
    bt.add_argument("--keep-raw", action="store_true", help="store the raw records too")
    bt.add_argument("--fs", type=float, help="sampling rate for files without timing")
    bt.add_argument("--json", action="store_true", help="print one JSON document")


def run(args, out, err) -> int:
    """Analyse the inputs into the store (a tqdm bar on stderr), then count what was done. Exit 0 when
    every input was analysed or skipped as already stored, 1 when any failed, 130 on Ctrl-C (the first
    stops the batch after the input in hand, a second at once)."""
    from tqdm import tqdm

    from ..monitor.batch import batch
    bar = None
    seen = [0, 0]   # inputs stored, inputs to analyse

    def progress(done, total):
        nonlocal bar
        seen[:] = [done, total]
        if bar is None:
            bar = tqdm(total=total, unit="file", file=err, disable=None, leave=False)
        bar.update(done - bar.n)
        if asked:
            raise KeyboardInterrupt
    try:
        with _stop_between_inputs() as asked:
            rep = batch(args.inputs, task=args.task, store=args.store, manifest=args.manifest,
                        workers=args.workers, scheduler=args.scheduler, force=args.force, keep_raw=args.keep_raw,
                        fs=args.fs, progress=progress)
            if asked:   # asked during the last input: what was stored is said as for any interrupt
                raise KeyboardInterrupt
    except KeyboardInterrupt:   # the batch commits what it stored before it lets go of the store
        if bar is not None:
            bar.close()
            bar = None
        print(f"vibmeasure: interrupted: {seen[0]} of {seen[1]} stored", file=err)
        return 130
    finally:
        if bar is not None:
            bar.close()
    counts = rep["status"].value_counts().to_dict()
    errors = rep[rep["status"] == "error"]
    if args.json:
        emit_json({"command": "batch", "store": args.store, "task": args.task, "counts": counts,
                   "errors": errors[["file", "message"]].to_dict(orient="records")}, out, allow_nan=True)
    else:
        print(f"{args.store}: {counts.get('done', 0)} analysed, {counts.get('skipped', 0)} skipped (already stored), "
              f"{counts.get('error', 0)} with errors", file=out)
        for _, r in errors.iterrows():
            print(f"  {r['file']}: {r['message']}", file=out)
    if len(errors):   # 0 only when every input was analysed or skipped as already stored
        print(f"vibmeasure: {len(errors)} of {len(rep)} input(s) failed", file=err)
        return 1
    return 0


@contextlib.contextmanager
def _stop_between_inputs():
    """Yield a list that a first Ctrl-C fills; the progress callback then raises KeyboardInterrupt
    between two inputs. Rule: the interrupt is never raised inside a library's compiled code, where it
    can leave the interpreter to end by SIGINT instead of exit 130 (3 of 16 batches interrupted within
    the first input's diagnosis did) and could cut a write short. A second Ctrl-C interrupts at once;
    a SIGINT the shell ignores (a background job) stays ignored, and off the main thread (no handler
    can be set there) Ctrl-C stays Python's own."""
    asked: list = []
    previous = signal.getsignal(signal.SIGINT)

    def first(signum, frame):
        asked.append(signum)
        signal.signal(signal.SIGINT, previous)

    if previous is signal.SIG_IGN or previous is None:
        yield asked
        return
    try:
        signal.signal(signal.SIGINT, first)
    except ValueError:   # not the main thread
        yield asked
        return
    try:
        yield asked
    finally:
        signal.signal(signal.SIGINT, previous)
