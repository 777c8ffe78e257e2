"""The ``vibmeasure`` command: parse, call the library, print or write. No analysis here."""

from __future__ import annotations

import argparse
import json
import sys
import warnings
from pathlib import Path

from . import __version__
from .core.errors import QualityWarning, VibMeasureError
from .core.results import FLAG_TEXT

_METHODS = ("ml", "logdec", "hilbert", "halfpower")


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # argparse's own usage errors: same prefix and exit code as ours
        self.print_usage(sys.stderr)
        print(f"vibmeasure: error: {message}", file=sys.stderr)
        raise SystemExit(2)


def _parser() -> argparse.ArgumentParser:
    p = _Parser(prog="vibmeasure", description="Vibration measurements to fn, zeta and FRFs you can trust.")
    p.add_argument("--version", action="version", version=f"vibmeasure {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    r = sub.add_parser("ringdown", help="natural frequency and damping from a free decay",
                       description="Identify fn and zeta (with standard deviations) from a ring-down record.")
    r.add_argument("file", help="record: .csv .h5 .wav .mat .lvm")
    r.add_argument("--channel", help="response channel name (default: the first that is not a force)")
    r.add_argument("--force", metavar="NAME",
                   help="channel holding the hammer/shaker force: the decay is fitted after its pulse")
    r.add_argument("--fs", type=float, help="sampling rate in Hz (required when the file has no timing)")
    r.add_argument("--unit", help="unit of the data when the file does not say (m, mm/s, g, m/s^2, ...)")
    r.add_argument("--quantity", choices=("displacement", "velocity", "acceleration", "force"),
                   help="physical quantity of the data when the file does not say")
    r.add_argument("--modes", default="auto", help="number of modes, or 'auto' (default)")
    r.add_argument("--band", nargs=2, type=float, metavar=("LO", "HI"), help="report modes in this band (Hz)")
    r.add_argument("--method", choices=_METHODS, default="ml",
                   help="ml: maximum likelihood (default); logdec: logarithmic decrement; "
                        "hilbert: Hilbert envelope; halfpower: half-power bandwidth of the decay spectrum")
    r.add_argument("--json", action="store_true", help="print one JSON document")
    r.add_argument("--plot", metavar="OUT.png", help="write a picture of the record, fit and residual")
    return p


def _ringdown(args, out):
    from . import io
    from .identify import damping, ringdown as rd
    rec = io.read(args.file, fs=args.fs, unit=args.unit, quantity=args.quantity)
    if args.force:
        import dataclasses
        i = rec.index(args.force)
        chans = list(rec.channels)
        chans[i] = dataclasses.replace(chans[i], quantity="force", unit="")
        rec = rec.replace(channels=tuple(chans), note=f"channel {args.force!r} marked as force")
    modes = args.modes
    if modes != "auto":
        try:
            modes = int(modes)
        except ValueError:
            raise VibMeasureError(f"--modes={args.modes!r} must be 'auto' or a whole number") from None
    band = tuple(args.band) if args.band else None
    if args.method == "ml":
        est = rd.ringdown(rec, channel=args.channel, n_modes=modes, band=band)
    elif args.method == "logdec":
        est = damping.log_decrement(rec, channel=args.channel, band=band)
    elif args.method == "hilbert":
        est = damping.hilbert_decay(rec, channel=args.channel, band=band)
    else:
        est = damping.half_power(rec, channel=args.channel, band=band)
    if args.plot:
        _save_plot(args.plot, rec, est)
    return rec, est


def _save_plot(path, rec, est):
    import os
    import tempfile
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from .plot import plot_ringdown
    p = Path(path)
    if not p.parent.exists():
        raise VibMeasureError(f"--plot {path!r}: folder {str(p.parent)!r} does not exist")
    ax, _ = plot_ringdown(rec, est)
    fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", suffix=p.suffix or ".png", dir=p.parent)
    os.close(fd)
    try:
        ax.figure.savefig(tmp, dpi=120, bbox_inches="tight")
        os.replace(tmp, p)
    finally:
        plt.close(ax.figure)
        if os.path.exists(tmp):
            os.unlink(tmp)


def _report_text(args, rec, est, caught, out):
    ch = est.extras.get("channel", "")
    print(f"{args.file}  channel {ch}  fs {rec.fs:g} Hz  method {est.method}", file=out)
    print(f"{'mode':>4}  {'fn [Hz]':>12}  {'± std':>10}  {'zeta':>10}  {'± std':>9}  flags", file=out)
    for i in range(est.n_modes):
        m = est.mode(i)
        def f(v, fmt):
            return format(v, fmt) if v is not None else "n/a"
        print(f"{i + 1:>4}  {f(m['fn_hz'], '12.6g')}  {f(m['fn_std_hz'], '10.2g')}  {f(m['zeta'], '10.5g')}  "
              f"{f(m['zeta_std'], '9.2g')}  {','.join(m['flags'])}", file=out)
    if "friction_decay_per_cycle" in est.extras:
        print(f"Coulomb friction: amplitude falls {est.extras['friction_decay_per_cycle']:.4g} {est.unit} per cycle",
              file=out)
    for fl in est.flags:
        print(f"  {fl}: {FLAG_TEXT.get(fl, fl)}", file=out)


def main(argv=None, *, out=None, err=None) -> int:
    """Run the command line; returns the exit code (0 ok, 2 error)."""
    out = out or sys.stdout
    err = err or sys.stderr
    args = _parser().parse_args(argv)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", QualityWarning)
        try:
            rec, est = _ringdown(args, out)
        except (VibMeasureError, OSError) as exc:
            print(f"vibmeasure: error: {exc}", file=err)
            return 2
    msgs = [str(w.message) for w in caught if issubclass(w.category, QualityWarning)]
    if args.json:
        doc = {"command": args.command, "file": str(args.file), "fs_hz": rec.fs, **est.to_dict(),
               "warnings": msgs}
        json.dump(doc, out, indent=2, allow_nan=False)
        out.write("\n")
    else:
        _report_text(args, rec, est, caught, out)
    for m in msgs:
        print(f"vibmeasure: warning: {m}", file=err)
    if args.plot:
        print(f"vibmeasure: wrote {args.plot}", file=err)
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
