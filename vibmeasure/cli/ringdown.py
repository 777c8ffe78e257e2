"""The ``ringdown`` command: fn and zeta (with stds) from a free decay."""

from __future__ import annotations

from ..core.errors import VibMeasureError
from ..core.results import FLAG_TEXT
from ._common import (MODE_HEADER, add_files, emit_json, mode_row, plot_module, print_warnings, print_written,
                      Progress, quality_warnings, save_figure)

_METHODS = ("ml", "logdec", "hilbert", "halfpower")


def register(sub) -> None:
    """Add the command's parser to the subparsers ``sub``."""
    r = sub.add_parser("ringdown", help="natural frequency and damping from a free decay",
                       description="Identify fn and zeta (with standard deviations) from a ring-down record.")
    add_files(r, "record: .csv .h5 .wav .mat .lvm")
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


def run(args, out, err) -> int:
    """Identify, then print the modes (or one JSON document) and write the picture."""
    with quality_warnings() as msgs:
        rec, est = _ringdown(args, out, err)
    if args.json:
        emit_json({"command": args.command, "file": str(args.file), "fs_hz": rec.fs, **est.to_dict(),
                   "warnings": msgs}, out)
    else:
        _report_text(args, rec, est, out)
    print_warnings(msgs, err)
    print_written(args, err, ("plot",))
    return 0


def _ringdown(args, out, err=None):
    from .. import io
    from ..identify import damping
    from ..identify import ringdown as rd
    rec = io.read(args.file, fs=args.fs, unit=args.unit, quantity=args.quantity)
    if args.force:
        from ..core.dispatch import mark_force
        rec = mark_force(rec, args.force)
    modes = args.modes
    if modes != "auto":
        try:
            modes = int(modes)
        except ValueError:
            raise VibMeasureError(f"--modes={args.modes!r} must be 'auto' or a whole number") from None
    band = tuple(args.band) if args.band else None
    if args.method == "ml":
        bar = Progress(err, "ringdown", after_s=2.0) if err is not None else None
        try:
            est = rd.ringdown(rec, channel=args.channel, n_modes=modes, band=band, progress=bar)
        finally:
            if bar is not None:
                bar.close()
    elif args.method == "logdec":
        est = damping.log_decrement(rec, channel=args.channel, band=band)
    elif args.method == "hilbert":
        est = damping.hilbert_decay(rec, channel=args.channel, band=band)
    else:
        from ..identify.halfpower import half_power
        est = half_power(rec, channel=args.channel, band=band)
    if args.plot:
        _save_plot(args.plot, rec, est)
    return rec, est

def _save_plot(path, rec, est):
    save_figure(plot_module().plot_ringdown(rec, est), path)

def _report_text(args, rec, est, out):
    ch = est.extras.get("channel", "")
    print(f"{args.file}  channel {ch}  fs {rec.fs:g} Hz  method {est.method}", file=out)
    print(f"{MODE_HEADER}  flags", file=out)
    for i in range(est.n_modes):
        m = est.mode(i)
        print(mode_row(i, m["fn_hz"], m["fn_std_hz"], m["zeta"], m["zeta_std"], m["flags"]), file=out)
    if "friction_decay_per_cycle" in est.extras:
        print(f"Coulomb friction: amplitude falls {est.extras['friction_decay_per_cycle']:.4g} {est.unit} per cycle",
              file=out)
    for fl in est.flags:
        print(f"  {fl}: {FLAG_TEXT.get(fl, fl)}", file=out)
