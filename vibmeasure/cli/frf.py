"""The ``frf`` and ``modes`` commands: FRFs from force and response records, and modes fitted to them."""

from __future__ import annotations

from pathlib import Path

from ..core.errors import VibMeasureError
from ._common import (MODE_HEADER, add_files, emit_json, mode_row, plot_module, print_warnings, print_written,
                      quality_warnings, save_figure)


def register(sub) -> None:
    """Add the command's parser to the subparsers ``sub``."""
    for name, helptext in (("frf", "frequency response functions from force and response records"),
                           ("modes", "natural frequencies, damping and shapes from FRFs (fit_modes)")):
        q = sub.add_parser(name, help=helptext, description=helptext + "; FILE may hold time data or FRFs "
                                                                    "(UFF 58 function type 4).")
        add_files(q, "record (.csv .h5 .wav .mat .lvm .uff) or FRF file (.uff)")
        q.add_argument("--input", default="force", help="input (force) channel name (default: the force channel)")
        q.add_argument("--output", action="append", help="output channel(s) (default: all others)")
        q.add_argument("--estimator", choices=("H1", "H2", "Hv"), default="H1",
                       help="H1 = Sxf/Sff (noise on the output; the default), H2 = Sxx/Sfx (noise on the input), "
                            "Hv = geometric mean of both (noise on both)")
        q.add_argument("--window", default="hann", help="window for random excitation (default hann)")
        q.add_argument("--nperseg", type=int, help="segment length for random excitation")
        q.add_argument("--impact", action="store_true", help="hammer test: one record per hit, force and "
                                                            "exponential windows (added damping removed)")
        q.add_argument("--fs", type=float, help="sampling rate in Hz (required when the file has no timing)")
        q.add_argument("--variable", help="MATLAB variable holding a complex FRF (e.g. Hf_chan_2)")
        q.add_argument("--quantity", action="append", metavar="[CHANNEL=]QUANTITY",
                       help="physical quantity of a channel when the file does not say: displacement, velocity, "
                            "acceleration or force; CHANNEL= names the channel, without it every response channel "
                            "(repeatable); it sets the FRF form (receptance, mobility, accelerance)")
        q.add_argument("--unit", action="append", metavar="[CHANNEL=]UNIT",
                       help="unit of a channel when the file does not say (m, mm/s, g, m/s^2, N, ...); CHANNEL= "
                            "names the channel, without it every response channel (repeatable)")
        q.add_argument("--csv", metavar="OUT.csv", help="write the FRFs (frf: re, im, magnitude, phase, coherence "
                                                        "per line) or the modes (modes: one row per mode) as a "
                                                        "table whose header carries the units")
        if name == "modes":
            q.add_argument("--band", nargs=2, type=float, metavar=("LO", "HI"), required=True,
                           help="frequency band to fit (Hz)")
            q.add_argument("--modes", type=int, help="number of modes (default: from the stabilisation diagram)")
            q.add_argument("--max-order", type=int, default=40, help="highest LSCF model order (default 40)")
        q.add_argument("--json", action="store_true", help="print one JSON document")
        q.add_argument("--plot", metavar="OUT.png", help="write a picture (Bode + coherence, or the "
                                                         "stabilisation diagram for modes)")


def run(args, out, err) -> int:
    """The FRFs (``frf``) or the modes fitted to them (``modes``): printed (or one JSON document),
    written as a table and a picture."""
    import numpy as np
    with quality_warnings() as msgs:
        frf = get_frf(args)
        est = None
        if args.command == "modes":
            from ..identify.modal import fit_modes
            est = fit_modes(frf, band=tuple(args.band), n_modes=args.modes, max_order=args.max_order)
        if args.plot:
            plot = plot_module()
            if est is not None:
                fig = plot.plot_stabilisation(est, frf=frf)
            else:
                fig = plot.plot_frf(frf)
            save_figure(fig, args.plot)
    if args.csv:
        _frf_csv(args.csv, frf, est)
    from ..core.results import jsonable
    # one average (one hit) makes the coherence 1 at every line: it measures nothing, so none is given
    one = frf.params.get("n_averages") == 1
    coh = None if frf.coherence is None or one else [float(np.mean(c)) for c in frf.coherence]
    info = {"form": frf.form, "estimator": frf.estimator, "outputs": list(frf.outputs), "inputs": list(frf.inputs),
            "df_hz": frf.df, "n_lines": int(frf.freq.size), "n_averages": frf.params.get("n_averages"),
            "mean_coherence": coh, "exp_window_tau_s": frf.params.get("exp_window_tau_s"),
            "frf_flags": list(frf.params.get("flags", ()))}
    if args.json:
        doc = {"command": args.command, "file": str(args.file), **jsonable(info), "warnings": msgs}
        if est is not None:
            d = est.to_dict()
            extras = {k: v for k, v in d["extras"].items() if k not in ("stabilisation",)}
            doc.update({"method": d["method"], "flags": d["flags"], "modes": d["modes"], "extras": extras})
        emit_json(doc, out)
    else:
        print(f"{args.file}  FRF {frf.form} ({frf.estimator}), {frf.n_outputs} output(s), df {frf.df:.4g} Hz, "
              f"{info['n_averages']} averages", file=out)
        if coh:
            print("mean coherence: " + ", ".join(f"{o} {c:.3f}" for o, c in zip(frf.outputs, coh)), file=out)
        elif one and frf.coherence is not None:
            print("coherence: not measured (one average: it is 1 by construction; average several hits)", file=out)
        if est is not None:
            print(f"{MODE_HEADER}  flags", file=out)
            for i in range(est.n_modes):
                m = est.mode(i)
                print(mode_row(i, m["fn_hz"], m["fn_std_hz"], m["zeta"], m["zeta_std"], m["flags"]), file=out)
    print_warnings(msgs, err)
    print_written(args, err)
    return 0

def get_frf(args):
    """The FRF the arguments describe: read from an FRF file (UFF 58 type 4, a MATLAB --variable), or
    estimated from the record's force (--input) and responses (--impact: one record per hit)."""
    from .. import io
    from ..identify import frf as F
    p = Path(args.file)
    if args.variable or (p.suffix.lower() in (".uff", ".unv") and _uff_has_frf(p)):
        return io.read_frf(p, variable=args.variable)
    rec = io.read(p, fs=args.fs)
    if args.input not in rec.names and args.input != "force":
        raise VibMeasureError(f"--input {args.input!r} is not in the file; channels are {rec.names}")
    if args.input in rec.names:
        from ..core.dispatch import mark_force
        rec = mark_force(rec, args.input)
    rec = _label_channels(rec, getattr(args, "quantity", None), getattr(args, "unit", None), args.input)
    if args.impact:
        return F.impact_frf(rec, input=args.input, outputs=args.output, estimator=args.estimator)
    return F.estimate_frf(rec, input=args.input, outputs=args.output, estimator=args.estimator,
                          window=args.window, nperseg=args.nperseg)

def _channel_settings(values, what, rec, default_targets):
    """Parse repeated [CHANNEL=]VALUE options into {channel name: value}."""
    out = {}
    for v in values or ():
        name, sep, val = v.rpartition("=")
        if sep and name:
            if name not in rec.names:
                raise VibMeasureError(f"--{what} {v!r}: channel {name!r} is not in the file; channels are {rec.names}")
            out[name] = val.strip()
        else:
            out.update({n: val.strip() for n in default_targets})
    return out

def _label_channels(rec, quantities, units, input_name):
    """Set the quantity and unit of channels from --quantity/--unit ([CHANNEL=]VALUE, repeatable)."""
    if not quantities and not units:
        return rec
    import dataclasses

    from ..core import units as U
    force = rec.index(input_name) if input_name in rec.names else None
    responses = [c.name for k, c in enumerate(rec.channels) if k != force and c.quantity != "force"]
    q = _channel_settings(quantities, "quantity", rec, responses)
    u = _channel_settings(units, "unit", rec, responses)
    chans = list(rec.channels)
    for k, c in enumerate(chans):
        qk, uk = q.get(c.name, c.quantity), u.get(c.name, c.unit)
        if qk not in ("displacement", "velocity", "acceleration", "force", "unknown"):
            raise VibMeasureError(f"--quantity {qk!r} for channel {c.name!r} must be displacement, velocity, "
                                  "acceleration or force")
        try:
            if qk == "unknown" and uk:
                qk = U.quantity_of(uk)   # --unit g says acceleration
            chans[k] = dataclasses.replace(c, quantity=qk, unit=uk)
        except VibMeasureError as exc:
            raise VibMeasureError(f"channel {c.name!r}: {exc}") from None
    return rec.replace(channels=tuple(chans), note="quantity/unit set on the command line")

def _uff_has_frf(p):
    from ..io.uff import uff_sets
    return any(int(d.get("func_type", 0)) == 4 for d in uff_sets(p))

def _frf_csv(path, frf, est):
    """FRFs (one row per line, output and input) or, with an estimate, the modes as a table with units."""
    from ..io._common import write_table
    if est is None:
        df = frf.to_frame()
        write_table(df, path, {"re": frf.unit, "im": frf.unit, "magnitude": frf.unit, "coherence": "",
                               "random_error": ""})
        return
    df = est.to_frame()
    df.insert(0, "mode", range(1, est.n_modes + 1))
    write_table(df, path, {"mode": None, "zeta": "", "zeta_std": "", "amplitude": est.unit})
