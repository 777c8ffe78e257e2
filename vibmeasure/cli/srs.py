"""The ``srs`` command: shock response spectrum of a base acceleration record."""

from __future__ import annotations

from ..core.errors import VibMeasureError
from ._common import add_files, emit_json, plot_module, print_warnings, print_written, quality_warnings, save_figure


def register(sub) -> None:
    """Add the command's parser to the subparsers ``sub``."""
    sr = sub.add_parser("srs", help="shock response spectrum of a base acceleration record",
                        description="Shock response spectrum (maximax, primary, residual) by the ramp-invariant "
                                    "recursive filter (Smallwood); 1/12-octave natural frequencies by default.")
    add_files(sr, "record of the base acceleration: .csv .h5 .wav .mat .lvm .uff")
    sr.add_argument("--channel", help="acceleration channel (default: the first that is not a force)")
    sr.add_argument("--fs", type=float, help="sampling rate in Hz (required when the file has no timing)")
    sr.add_argument("--unit", help="unit of the acceleration when the file does not say (g, m/s^2)")
    damp = sr.add_mutually_exclusive_group()
    damp.add_argument("--zeta", type=float, help="damping ratio of the oscillators (default 0.05)")
    damp.add_argument("--q", type=float, help="quality factor Q = 1/(2 zeta) (Q 10 is zeta 0.05)")
    sr.add_argument("--fmin", type=float, help="lowest natural frequency, Hz (default max(fs/16384, 1))")
    sr.add_argument("--fmax", type=float, help="highest natural frequency, Hz (default fs/4)")
    sr.add_argument("--octave", type=float, default=1 / 12, help="spacing in octaves (default 1/12)")
    sr.add_argument("--kind", choices=("maximax", "primary", "residual"), default="maximax",
                    help="peak response shown first (all three are computed)")
    sr.add_argument("--output", choices=("acceleration", "pseudo_velocity", "relative_displacement"),
                    default="acceleration", help="response quantity (default absolute acceleration)")
    sr.add_argument("--pulse-end", type=float, metavar="SECONDS",
                    help="end of the pulse: primary before, residual after (default: the record's end)")
    sr.add_argument("--csv", metavar="OUT.csv", help="write the spectrum as a table")
    sr.add_argument("--json", action="store_true", help="print one JSON document")
    sr.add_argument("--plot", metavar="OUT.png", help="write a tripartite (pseudo-velocity) plot")


def run(args, out, err) -> int:
    """The shock response spectrum: printed (or one JSON document), written as a table and a picture."""
    import numpy as np

    from .. import io
    from ..signal.shock import srs
    rec = io.read(args.file, fs=args.fs, unit=args.unit, quantity="acceleration" if args.unit else None)
    fn = None
    if args.fmin is not None or args.fmax is not None:
        lo = args.fmin if args.fmin is not None else max(rec.fs / 16384, 1.0)
        hi = args.fmax if args.fmax is not None else rec.fs / 4
        if not 0 < lo < hi:
            raise VibMeasureError(f"--fmin {lo:g} and --fmax {hi:g} must satisfy 0 < fmin < fmax")
        fn = lo * 2 ** (args.octave * np.arange(int(np.floor(np.log2(hi / lo) / args.octave)) + 1))
    with quality_warnings() as msgs:   # said as vibmeasure's own lines, never a raw Python warning
        sp = srs(rec, fn=fn, zeta=args.zeta, Q=args.q, kind=args.kind, output=args.output, channel=args.channel,
                 octave=args.octave, pulse_end=args.pulse_end)
    print_warnings(msgs, err)
    if args.csv:
        from ..io._common import write_table
        df = sp.to_frame()
        write_table(df, args.csv, {c: sp.unit for c in df.columns if c != "fn_hz"})
    if args.json:
        doc = {"command": "srs", "file": str(args.file), "channel": sp.channel, "output": sp.output, "unit": sp.unit,
               "zeta": sp.zeta, "q": (1 / (2 * sp.zeta)) if sp.zeta > 0 else None, "input_peak": sp.input_peak,
               "fn_hz": sp.fn.tolist(), **{k: v.tolist() for k, v in sp.values.items()}}
        emit_json(doc, out)
    else:
        k0 = next(iter(sp.values))
        i = int(np.argmax(sp.values[k0]))
        print(f"{args.file}: channel {sp.channel}, input peak {sp.input_peak:.4g}, zeta {sp.zeta:g} "
              f"(Q {1 / (2 * sp.zeta) if sp.zeta > 0 else float('inf'):.3g}); {sp.output} [{sp.unit or 'unit of the input, not stated'}]", file=out)
        print(f"  largest {k0}: {sp.values[k0][i]:.4g} {sp.unit} at {sp.fn[i]:.4g} Hz", file=out)
        print(f"  {'fn Hz':>10}  " + "  ".join(f"{k:>12}" for k in sp.values), file=out)
        for j in range(0, sp.fn.size, max(1, sp.fn.size // 24)):
            print(f"  {sp.fn[j]:10.4g}  " + "  ".join(f"{v[j]:12.4g}" for v in sp.values.values()), file=out)
    if args.plot:
        save_figure(plot_module().plot_srs(sp), args.plot)
    print_written(args, err)
    return 0
