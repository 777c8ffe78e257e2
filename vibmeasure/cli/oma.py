"""The ``oma`` command: output-only modal analysis (SSI-cov or FDD)."""

from __future__ import annotations

from ._common import (MODE_HEADER, add_files, emit_json, mode_row, plot_module, print_warnings, quality_warnings,
                      save_figure)


def register(sub) -> None:
    """Add the command's parser to the subparsers ``sub``."""
    om = sub.add_parser("oma", help="output-only modal analysis (SSI-cov or FDD) of ambient responses",
                        description="Natural frequencies, damping (with std) and shapes from responses to ambient "
                                    "or operating excitation: covariance-driven SSI (default) or FDD/EFDD.")
    add_files(om, "record of the responses: .csv .h5 .wav .mat .lvm .uff")
    om.add_argument("--method", choices=("ssi", "fdd", "both"), default="ssi",
                    help="ssi: covariance-driven stochastic subspace identification (default); fdd: frequency-"
                         "domain decomposition with EFDD damping; both: SSI's modes, each checked against FDD "
                         "(flags methods_disagree, not_confirmed)")
    om.add_argument("--band", nargs=2, type=float, metavar=("LO", "HI"),
                    help="frequency band (Hz); default the whole range")
    om.add_argument("--channel", action="append", help="output channel(s) (default: all that are not forces)")
    om.add_argument("--fs", type=float, help="sampling rate in Hz (required when the file has no timing)")
    om.add_argument("--unit", help="unit of the data when the file does not say (e.g. g)")
    om.add_argument("--max-order", type=int, default=40, help="ssi: highest model order (default 40)")
    om.add_argument("--block-rows", type=int, help="ssi: block rows (covariance lags; default max(30, order))")
    om.add_argument("--nperseg", type=int, help="fdd: segment length of the cross-spectra")
    om.add_argument("--json", action="store_true", help="print one JSON document")
    om.add_argument("--plot", metavar="OUT.png",
                    help="write the stabilisation diagram (ssi) or the singular values (fdd)")


def run(args, out, err) -> int:
    """The modes (with stds and MPC) and the poles refused: printed (or one JSON document), and the
    stabilisation diagram or singular values as a picture."""
    from .. import io
    from ..identify.oma import oma_cross_check, oma_fdd, oma_ssi
    rec = io.read(args.file, fs=args.fs, unit=args.unit, channels=args.channel)
    band = tuple(args.band) if args.band else None
    with quality_warnings() as msgs:
        if args.method in ("ssi", "both"):
            est = oma_ssi(rec, band=band, max_order=args.max_order, block_rows=args.block_rows)
        if args.method in ("fdd", "both"):
            fdd = oma_fdd(rec, band=band, nperseg=args.nperseg)
            est = fdd if args.method == "fdd" else oma_cross_check(est, fdd)
    rejected = est.extras.get("rejected_modes", [])
    if args.json:
        from ..core.results import jsonable
        doc = {"command": "oma", "file": str(args.file), "fs_hz": rec.fs, **est.to_dict(), "warnings": msgs}
        doc["extras"] = {k: jsonable(est.extras[k]) for k in ("band_hz", "outputs", "mpc", "std_method", "cross_check",
                                                              "unresolved_close_modes_hz") if k in est.extras}
        doc["shapes"] = [[[float(v.real), float(v.imag)] for v in col] for col in est.shapes.T]
        doc["rejected"] = jsonable(rejected)
        emit_json(doc, out)
    else:
        print(f"{args.file}: {est.method}, {rec.n_channels} outputs, {est.n_modes} mode(s)"
              f" ({est.extras.get('std_method', '')})", file=out)
        print(f"{MODE_HEADER}  {'MPC':>5}  flags", file=out)
        for i in range(est.n_modes):
            print(mode_row(i, est.fn[i], est.fn_std[i], est.zeta[i], est.zeta_std[i], est.mode_flags[i],
                           f"{est.extras['mpc'][i]:5.3f}  "), file=out)
        for r in rejected:
            f0 = r.get("fn_hz", r.get("f"))
            print(f"  not a mode: {f0:.6g} Hz: {r['reason']}", file=out)
    print_warnings(msgs, err)
    if args.plot:
        pm = plot_module()
        fig = pm.plot_singular_values(est) if args.method == "fdd" else pm.plot_stabilisation(est)
        save_figure(fig, args.plot)
        print(f"vibmeasure: wrote {args.plot}", file=err)
    return 0
