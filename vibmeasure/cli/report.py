"""The ``report`` and ``demo`` commands: self-contained HTML reports."""

from __future__ import annotations


def register(sub) -> None:
    """Add the command's parser to the subparsers ``sub``."""
    dm = sub.add_parser("demo", help="synthesise demo inputs, analyse them, write an HTML report",
                        description="The main job: a ring-down, a hammer test, a machine with a bearing fault and "
                                    "a small fleet, analysed into DIR/report.html and DIR/results.db.")
    dm.add_argument("--out", default="vibmeasure-demo", help="folder for the inputs, report and store "
                                                             "(default vibmeasure-demo)")
    rp = sub.add_parser("report", help="a self-contained HTML report of records and/or a store",
                        description="Ring-down, FRF/modes or machine diagnosis per file (by what it holds), "
                                    "fleet trends from a store; one HTML file with inline pictures.")
    rp.add_argument("inputs", nargs="*", help="records (.csv .h5 .wav .mat .lvm)")
    rp.add_argument("-o", "--out", default="report.html", help="output HTML (default report.html)")
    rp.add_argument("--store", help="a vm.Store: its fleet trends are reported too")
    rp.add_argument("--fs", type=float, help="sampling rate in Hz of files that carry no timing")
    rp.add_argument("--unit", help="unit of the data when the files do not say (e.g. g)")
    rp.add_argument("--channel", action="append", help="channel to analyse; repeat to name several (default every "
                                                       "channel)")
    rp.add_argument("--input", metavar="CHANNEL", help="force channel of a hammer or shaker test: reported as FRFs "
                                                       "and modes")
    rp.add_argument("--rpm", type=float, help="shaft speed: records are diagnosed as machines")
    rp.add_argument("--bearing", help="catalogue bearing for the diagnosis")
    rp.add_argument("--band", nargs=2, type=float, metavar=("LO", "HI"), help="band for ringdown / fit_modes (Hz)")
    rp.add_argument("--model", help="TOML model: each ring-down or modal estimate is compared with it")
    rp.add_argument("--title", default="Vibration measurement report", help="the report's title")


def run(args, out, err) -> int:
    """``demo`` or ``report``."""
    return _demo(args, out, err) if args.command == "demo" else _report(args, out, err)


def _report(args, out, err) -> int:
    from ..reporting import report
    failures: list = []
    path = report(args.inputs, args.out, store=args.store, title=args.title, rpm=args.rpm, bearing=args.bearing,
                  band=tuple(args.band) if args.band else None, model=args.model, failures=failures, fs=args.fs,
                  unit=args.unit, channels=args.channel, input=args.input)
    for name, message in failures:
        print(f"vibmeasure: not analysed: {name}: {message}", file=err)
    print(f"vibmeasure: wrote {path}", file=err)
    if failures:   # the report stands, but a script must see that inputs are missing from it
        print(f"vibmeasure: {len(failures)} of {len(args.inputs) + (args.store is not None)} input(s) not analysed",
              file=err)
        return 1
    return 0

def _demo(args, out, err) -> int:
    from ..reporting import demo
    res = demo(args.out, progress=lambda m: print(f"vibmeasure: {m}", file=err, flush=True))
    print(f"report:  {res['report']}  ({res['size_bytes'] / 1e6:.1f} MB)", file=out)
    print(f"store:   {res['store']}", file=out)
    print(f"done in {res['seconds']:.0f} s; open the report in a browser", file=out)
    return 0
