"""The ``compare`` command: a measurement identified and compared with a model or a baseline."""

from __future__ import annotations

from ..core.errors import VibMeasureError
from ._common import add_files, emit_json, plot_module, print_warnings, quality_warnings, save_figure
from .frf import get_frf
from .model import predict


def register(sub) -> None:
    """Add the command's parser to the subparsers ``sub``."""
    cp = sub.add_parser("compare", help="identify a measurement and compare it with a model or a baseline",
                        description="Identify the record (ring-down by default; FRF + fit_modes with --input) "
                                    "and compare with a model (--model) or a healthy baseline history (--baseline). "
                                    "Exit status: 0 ok or watch, 1 alarm, 2 bad input, 3 a defect of vibmeasure.")
    add_files(cp, "measurement record")
    ref = cp.add_mutually_exclusive_group(required=True)
    ref.add_argument("--model", help="model.toml")
    ref.add_argument("--baseline", help="baseline history (.h5 written by vm.History.save)")
    cp.add_argument("--fs", type=float, help="sampling rate in Hz (required when the file has no timing)")
    cp.add_argument("--unit", help="unit of the data when the file does not say (e.g. g)")
    cp.add_argument("--channel", help="response channel for a ring-down")
    cp.add_argument("--input", help="force channel: identify from FRFs with fit_modes instead of a ring-down")
    cp.add_argument("--band", nargs=2, type=float, metavar=("LO", "HI"), help="band for fit_modes / ringdown")
    cp.add_argument("--modes", type=int, default=3, help="modes of a continuum model (default 3)")
    cp.add_argument("--rtol-fn", type=float, default=0.02, help="frequency tolerance for an alarm (default 0.02)")
    cp.add_argument("--json", action="store_true", help="print one JSON document")
    cp.add_argument("--plot", metavar="OUT.png", help="picture of measured versus predicted")


def run(args, out, err) -> int:
    """Identify (ring-down, or FRF + fit_modes with --input), compare, print the verdict; exit 1 on an
    alarm, for scripts and monitoring jobs."""
    from .. import io
    from ..identify import ringdown as rd
    from ..models import load
    from ..monitor.compare import History, compare
    with quality_warnings() as msgs:
        ref = History.load(args.baseline) if args.baseline else load(args.model)
        pred = ref if isinstance(ref, History) else predict(ref, args.modes)
        band = tuple(args.band) if args.band else None
        if args.input:
            args.variable, args.impact, args.output = None, False, None
            args.estimator, args.window, args.nperseg = "H1", "hann", None
            args.quantity, args.unit = None, [args.unit] if args.unit else None   # frf's [CHANNEL=]UNIT form
            frf = get_frf(args)
            from ..identify.modal import fit_modes
            if band is None:
                raise VibMeasureError("--band LO HI is required with --input (the fit_modes band)")
            est = fit_modes(frf, band=band)
        else:
            rec = io.read(args.file, fs=args.fs, unit=args.unit)
            est = rd.ringdown(rec, channel=args.channel, band=band)
        cmp = compare(est, pred, rtol_fn=args.rtol_fn)
        if args.plot:
            fig = plot_module().plot_comparison(cmp, rtol_fn=args.rtol_fn,
                                                against="baseline" if args.baseline else "model")
            save_figure(fig, args.plot)
    if args.json:
        emit_json({"command": "compare", "file": str(args.file), **cmp.to_dict(),
                   "measured": est.to_dict()["modes"], "warnings": msgs}, out)
    else:
        print(f"{args.file}: verdict {cmp.verdict.upper()} - {cmp.reason}", file=out)
        for r in cmp.rows:
            print(f"  {r['fn_predicted_hz']:10.5g} Hz predicted  {r['fn_measured_hz']:10.5g} Hz measured  "
                  f"{r['fn_dev_pct']:+7.2f} %  dk/k {r['implied_stiffness_change_pct']:+7.2f} %  {r['verdict']}",
                  file=out)
    print_warnings(msgs, err)
    return 1 if cmp.verdict == "alarm" else 0  # scripts and monitoring jobs act on the exit status
