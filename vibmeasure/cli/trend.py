"""The ``trend`` command: trends, limits and verdicts of a store."""

from __future__ import annotations

import json

from ..core.errors import VibMeasureError
from ._common import emit_json, plot_module, save_figure


def register(sub) -> None:
    """Add the command's parser to the subparsers ``sub``."""
    tr = sub.add_parser("trend", help="trends, limits and verdicts per asset and point of a store",
                        description="Baseline, watch/alarm limits, trend slope and verdict per metric.")
    tr.add_argument("store", help="the store: a .db file, a postgresql:// URL or an .h5 file")
    tr.add_argument("--asset", help="only this asset (default: all)")
    tr.add_argument("--point", help="only this measurement point (default: all)")
    tr.add_argument("--baseline", type=int, default=8, help="measurements in the baseline (default 8)")
    tr.add_argument("--json", action="store_true", help="print one JSON document")
    tr.add_argument("--plot", metavar="OUT.png", help="trend of the worst metric (needs --asset and --point, or "
                                                      "takes the worst)")


def run(args, out, err) -> int:
    """Each asset's verdict and its metrics' trends (or one JSON document); a picture of the first."""
    from ..monitor.trend import trend
    tr = trend(args.store, asset=args.asset, point=args.point, baseline_count=args.baseline)
    if args.json:
        rows = json.loads(tr.to_json(orient="records", date_format="iso"))
        emit_json({"command": "trend", "store": args.store, "assets": tr.attrs.get("assets", {}),
                   "points": tr.attrs.get("points", {}), "metrics": rows}, out, allow_nan=True)
    else:
        if tr.empty:
            print(f"{args.store}: no metric has more than {args.baseline} measurements yet", file=out)
        for a, v in tr.attrs.get("assets", {}).items():
            print(f"{a}: {v.upper()}", file=out)
            for _, r in tr[tr["asset"] == a].iterrows():
                print(f"  {r['point']:<10} {r['metric']:<20} {r['verdict']:<6} {r['reason']}", file=out)
    if args.plot:
        drawn = tr[tr["baseline_mean"].notna()]   # rows with a baseline to draw against
        if drawn.empty:
            raise VibMeasureError("nothing to plot: no metric has a baseline yet")
        r = drawn.iloc[0]
        fig = plot_module().plot_trend(args.store, asset=r["asset"], point=r["point"], metric=r["metric"],
                                       task=r["task"], baseline_count=args.baseline)
        save_figure(fig, args.plot)
        print(f"vibmeasure: wrote {args.plot}", file=err)
    return 0
