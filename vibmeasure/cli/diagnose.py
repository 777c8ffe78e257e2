"""The ``diagnose`` command: machine fault diagnosis of a vibration record."""

from __future__ import annotations

from ..core.errors import VibMeasureError
from ._common import add_files, emit_json, plot_module, print_warnings, print_written, quality_warnings, save_figure


def register(sub) -> None:
    """Add the command's parser to the subparsers ``sub``."""
    dg = sub.add_parser("diagnose", help="machine fault diagnosis from a vibration record",
                        description="Fault frequencies, envelope analysis, evidence per fault family and "
                                    "ISO 10816-3 severity.")
    add_files(dg, "acceleration record")
    dg.add_argument("--rpm", type=float, help="declared shaft speed (default: the file's rpm variable)")
    g = dg.add_mutually_exclusive_group()
    g.add_argument("--bearing", help="catalogue bearing: 6205-2RS, 6203-2RS (CWRU), MFPT, ZA-2115 (IMS), UER204 "
                                     "(XJTU-SY), ER16K (Ottawa), or a nominal 6200-6212 / 6300-6312")
    g.add_argument("--bearing-geometry", metavar="N,d,D,angle", help="balls, ball and pitch diameter, angle (deg)")
    dg.add_argument("--gear", type=int, metavar="TEETH", help="teeth of a gear on this shaft")
    dg.add_argument("--line-frequency", type=float, choices=(50.0, 60.0), help="mains frequency: check 2 x line")
    dg.add_argument("--group", type=int, choices=(1, 2), default=2, help="ISO 10816-3 machine group (default 2)")
    dg.add_argument("--foundation", choices=("rigid", "flexible"), default="rigid",
                    help="ISO 10816-3 support class: rigid when the machine's lowest support mode is above its "
                         "running speed, else flexible (default rigid)")
    dg.add_argument("--fs", type=float, help="sampling rate in Hz (required when the file has no timing)")
    dg.add_argument("--unit", default=None, help="unit of the data when the file does not say (e.g. g)")
    dg.add_argument("--channel", action="append", help="channel to diagnose; repeat to name several (the first gives "
                                                       "speed, severity and shaft orders; bearing faults are searched in "
                                                       "all named). Default: every channel of the file")
    dg.add_argument("--prewhitening", nargs="+", choices=("cepstral", "ar"), default=["cepstral"],
                    help="pre-whitening before envelope analysis (default cepstral)")
    dg.add_argument("--tach", metavar="CHANNEL", help="tachometer or encoder channel: the speed is measured from its "
                                                      "pulses and, when it varies, the analysis runs in orders")
    dg.add_argument("--pulses-per-rev", type=int, default=1, metavar="N",
                    help="tachometer pulses per shaft revolution (default 1)")
    dg.add_argument("--json", action="store_true", help="print one JSON document")
    dg.add_argument("--plot", metavar="OUT.png", help="spectra with the fault lines and a severity gauge")


def run(args, out, err) -> int:
    """Diagnose, print the answer and its evidence (or one JSON document), write the picture."""
    from ..monitor.diagnosis import diagnose
    rec, primary = _record(args)
    bearing = _bearing(args)
    with quality_warnings() as msgs:
        diag = diagnose(rec, rpm=args.rpm, bearing=bearing, gear=args.gear, machine_group=args.group,
                        foundation=args.foundation, channel=primary, line_frequency=args.line_frequency,
                        prewhitening=tuple(args.prewhitening), tach=args.tach, pulses_per_rev=args.pulses_per_rev)
    if args.plot:
        save_figure(plot_module().plot_diagnosis(rec, diag), args.plot)
    print_warnings(msgs, err)
    if args.json:
        emit_json({"command": "diagnose", "file": str(args.file), **diag.to_dict(), "warnings": msgs}, out)
    else:
        _print_text(args, rec, diag, out)
    print_written(args, err, ("plot",))
    return 0


def _record(args):
    """The record with the named channels (and the tachometer), and the primary channel's index."""
    from .. import io
    wanted = args.channel
    if args.tach and wanted and args.tach not in wanted:
        wanted = wanted + [args.tach]
    rec = io.read(args.file, fs=args.fs, unit=args.unit, quantity="acceleration" if args.unit else None,
                  channels=wanted)
    if args.tach and args.tach not in rec.names:
        raise VibMeasureError(f"--tach {args.tach!r} is not a channel of {args.file}: {rec.names}")
    primary = next((i for i, n in enumerate(rec.names) if n != args.tach), None)
    if primary is None:
        raise VibMeasureError(f"{args.file} holds only the tachometer channel {args.tach!r}")
    return rec, primary


def _bearing(args):
    """--bearing (a catalogue name) or --bearing-geometry N,d,D,angle as a vm.Bearing."""
    from ..models.bearing import Bearing
    if not args.bearing_geometry:
        return args.bearing
    try:
        n, d, D, ang = (float(v) for v in args.bearing_geometry.split(","))
    except ValueError:
        raise VibMeasureError(f"--bearing-geometry {args.bearing_geometry!r} must be N,d,D,angle") from None
    return Bearing(int(n), d, D, ang)


def _print_text(args, rec, diag, out) -> None:
    """The answer, its reason, the speed, the severity and one line per fault family."""
    sev = diag.severity
    where = f" in {diag.channel}" if diag.top not in ("none", "undetermined") else ""
    contradicted = "speed_contradicted" in diag.flags
    scope = ("; NO FAULT CHECKED: the declared speed is contradicted (give the measured --rpm or --tach)"
             if contradicted else
             " among the shaft-order faults; bearing faults NOT CHECKED" if not diag.bearing_checked else "")
    healthy = (f", healthy with probability {diag.p_healthy:.2f}"
               if diag.top == "undetermined" and diag.p_healthy is not None else "")
    print(f"{args.file}: {diag.top.upper()} (confidence {diag.confidence:.2f}{healthy}){where}{scope}", file=out)
    print(f"  {diag.reason}", file=out)
    if not diag.bearing_checked and not contradicted:
        print("  bearing faults: not checked (give --bearing or --bearing-geometry)", file=out)
    est, dec = diag.speed.get("estimated_rpm"), diag.speed.get("declared_rpm")
    if diag.speed.get("source"):
        print(f"  speed: {est:.1f} rpm mean, {diag.speed['min_rpm']:.1f}-{diag.speed['max_rpm']:.1f} rpm "
              f"(from the {diag.speed['source']}{'' if dec is None else f'; declared {dec:g} rpm'}) "
              f"{diag.speed['note']}", file=out)
    else:
        print(f"  speed: declared {dec:g} rpm, estimated "
              f"{'n/a' if est is None else format(est, '.1f')} rpm {diag.speed['note']}", file=out)
    if sev.get("velocity_rms_mm_s") is None and "unit_unknown" in diag.flags:
        print("  severity: not computed, the unit is unknown (give --unit): level-gated shaft-order faults "
              "are named as patterns, not called", file=out)
    if sev.get("velocity_rms_mm_s") is not None:
        print(f"  severity: {sev['velocity_rms_mm_s']:.2f} mm/s RMS ({sev['band_hz'][0]:g}-1000 Hz), ISO 10816-3 "
              f"group {sev['group']} {sev['foundation']}: zone {sev['zone']} {sev['note']}", file=out)
    tops = diag.extras.get("measured_top_hz") or {}
    cut = {k: v for k, v in tops.items() if v < 0.99 * rec.fs / 2}
    if cut:
        print("  measured band: " + ", ".join(f"{k} up to {v:.0f} Hz" for k, v in cut.items())
              + f" (Nyquist {rec.fs / 2:g} Hz; above: a filter's stop band, left out of the envelope bands)",
              file=out)
    for _, r in diag.faults.iterrows():
        p = r.get("p_value")
        extra = f"  p = {p:.2g} ({r.channel}, {r.preprocessing})" if p is not None and p == p and p < 1 else ""
        pat = r.get("pattern")
        if pat is not None and pat == pat and pat > 0:
            extra += f"  pattern {pat:.2f} (not called: unit unknown)"
        print(f"  {r.fault:20s} expected {r.expected_hz:9.2f} Hz  score {r.confidence:.2f}{extra}", file=out)
