"""The ``spectrum`` command: amplitude spectrum, PSD or envelope spectrum with peaks."""

from __future__ import annotations

from pathlib import Path

from ..core.errors import VibMeasureError
from ._common import (add_files, emit_json, plot_module, print_written, Progress, save_figure)


def register(sub) -> None:
    """Add the command's parser to the subparsers ``sub``."""
    sp = sub.add_parser("spectrum", help="amplitude spectrum, PSD or envelope spectrum with peaks",
                        description="Amplitude-correct spectrum, Welch PSD or squared-envelope spectrum of a "
                                    "record; HDF5 records are streamed from disk.")
    add_files(sp, "record: .csv .h5 .wav .mat .lvm")
    sp.add_argument("--kind", choices=("amplitude", "psd", "envelope"), default="amplitude",
                    help="amplitude: peak (or rms) amplitude per line in the channel unit; psd: Welch power spectral "
                         "density (unit^2/Hz); envelope: squared-envelope spectrum after a band-pass (--band), for "
                         "bearing fault lines (default amplitude)")
    sp.add_argument("--channel", action="append", help="channel(s) to analyse (default: all; envelope: first)")
    sp.add_argument("--fs", type=float, help="sampling rate in Hz (required when the file has no timing)")
    sp.add_argument("--unit", help="unit of the data when the file does not say (m, mm/s, g, m/s^2, ...)")
    sp.add_argument("--nperseg", type=int, help="segment length (default: psd 4096, amplitude whole record)")
    sp.add_argument("--window", default="hann", help="window name (hann, flattop, boxcar, hamming, ...)")
    sp.add_argument("--scaling", choices=("peak", "rms", "peak-to-peak"), default="peak",
                    help="amplitude scaling (amplitude and envelope spectra)")
    sp.add_argument("--band", nargs=2, type=float, metavar=("LO", "HI"),
                    help="frequency band (Hz) for peaks and output; for --kind envelope the demodulation band")
    sp.add_argument("--peaks", type=int, default=10, metavar="N", help="report the N strongest peaks (default 10)")
    sp.add_argument("--csv", metavar="OUT.csv", help="write the spectrum as a table")
    sp.add_argument("--json", action="store_true", help="print one JSON document")
    sp.add_argument("--plot", metavar="OUT.png", help="write a picture of the spectrum and its peaks")


def run(args, out, err) -> int:
    """The spectrum and its peaks: printed (or one JSON document), written as a table and a picture."""
    rec, spec, found, band = _spectrum(args, out, err)
    _spectrum_outputs(args, spec, found, band)
    if args.json:
        from ..core.results import jsonable
        doc = {"command": "spectrum", "file": str(args.file), "kind": spec.kind, "unit": spec.unit,
               "df_hz": spec.df, "n_lines": int(spec.freq.size), "channels": list(spec.channels),
               "params": jsonable(dict(spec.params)),
               "peaks": {c: [{"freq_hz": float(f), "amplitude": float(a), "prominence": float(pr)}
                             for f, a, pr in zip(p.freq, p.amplitude, p.prominence)]
                         for c, p in zip(spec.channels, found)}}
        emit_json(doc, out)
    else:
        print(f"{args.file}  {spec.kind} [{spec.unit or '-'}]  df {spec.df:.5g} Hz  "
              f"{spec.params.get('n_averages', 1)} averages  window {spec.params.get('window')}", file=out)
        for c, p in zip(spec.channels, found):
            print(f"channel {c}: {len(p)} peaks", file=out)
            for f, a in zip(p.freq, p.amplitude):
                print(f"  {f:14.6g} Hz  {a:12.5g}", file=out)
    print_written(args, err)
    return 0

def _spectrum(args, out, err):
    from .. import io
    from ..core._validate import time_like_channels
    from ..signal import demod
    from ..signal import peaks as pk
    from ..signal import spectral
    p = Path(args.file)
    if p.suffix.lower() in (".h5", ".hdf5") and args.fs is None:
        check = Progress(err, "verifying checksum")
        try:
            rec = io.open_record(p, unit=args.unit, progress=check)
        except VibMeasureError:
            rec = io.read(p, fs=args.fs, unit=args.unit)
        finally:
            check.close()
    else:
        rec = io.read(p, fs=args.fs, unit=args.unit)
    chans = args.channel
    ramps = time_like_channels(rec) if chans is None else []
    if ramps and len(ramps) < rec.n_channels:   # the rule ringdown and diagnose follow: a time column is no signal
        chans = [n for n in rec.names if n not in ramps]
        print(f"vibmeasure: warning: {', '.join(repr(n) for n in ramps)} look(s) like a time column and is left out "
              "(name it with --channel to analyse it)", file=err)
    bar = Progress(err, args.kind)
    try:
        if args.kind == "psd":
            spec = spectral.psd(rec, nperseg=args.nperseg, window=args.window, channels=chans, progress=bar)
        elif args.kind == "amplitude":
            spec = spectral.amplitude_spectrum(rec, nperseg=args.nperseg, window=args.window, scaling=args.scaling,
                                               channels=chans, progress=bar)
        else:   # a lazy record is streamed in segments (bounded memory, with progress)
            spec = demod.envelope_spectrum(rec, band=args.band, channel=chans[0] if chans else None,
                                           window=args.window, nperseg=args.nperseg,
                                           progress=bar if not hasattr(rec, "data") else None)
    finally:
        bar.close()
    band = tuple(args.band) if args.band and args.kind != "envelope" else None
    found = [pk.pick_peaks(spec, n=args.peaks, band=band, channel=i) for i in range(spec.n_channels)]
    return rec, spec, found, band

def _spectrum_outputs(args, spec, found, band):
    if args.csv:
        from ..io._common import write_table
        df = spec.to_frame()
        if band:
            df = df[(df.freq_hz >= band[0]) & (df.freq_hz <= band[1])]
        write_table(df, args.csv, {c: spec.unit for c in spec.channels})
    if args.plot:
        fig = plot_module().plot_spectrum(spec, peaks=found or None)   # every channel's, in its colour
        if band:
            fig.panels[0].set_xlim(*band)
        save_figure(fig, args.plot)
