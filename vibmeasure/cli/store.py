"""The ``store`` command: migrate an HDF5 store to a database, or say what a store holds."""

from __future__ import annotations

from ._common import emit_json


def register(sub) -> None:
    """Add the command's parser to the subparsers ``sub``."""
    st = sub.add_parser("store", help="migrate an HDF5 store to SQLite/PostgreSQL, or count what a store holds",
                        description="vibmeasure store migrate OLD.h5 PLANT.db (or postgresql://user@host/db); "
                                    "vibmeasure store info STORE; vibmeasure store alarms STORE.")
    ops = st.add_subparsers(dest="op", required=True, help="migrate, info or alarms")
    mg = ops.add_parser("migrate", help="copy an HDF5 store into a new database store (ids and raw records kept)")
    mg.add_argument("source", help="the HDF5 store (.h5)")
    mg.add_argument("target", help="the database: a .db/.sqlite file or a postgresql:// URL")
    mg.add_argument("--raw-dir", help="where raw records go (default beside a SQLite file; needed for PostgreSQL)")
    mg.add_argument("--json", action="store_true", help="print one JSON document")
    info = ops.add_parser("info", help="assets, points, measurements and results in a store")
    info.add_argument("store", help="an HDF5 store (.h5), a .db/.sqlite file or a database URL")
    info.add_argument("--json", action="store_true", help="print one JSON document")
    al = ops.add_parser("alarms", help="the alarm history: each change of a trend verdict (database stores)")
    al.add_argument("store", help="a .db/.sqlite file or a database URL")
    al.add_argument("--asset", help="only this asset")
    al.add_argument("--json", action="store_true", help="print one JSON document")


def run(args, out, err) -> int:
    """Migrate (with a progress bar on the terminal) or count."""
    if args.op == "migrate":
        from tqdm import tqdm

        from ..io.sql import migrate
        bar = tqdm(total=0, unit="measurement", file=err, disable=args.json or not err.isatty())

        def progress(done, total):
            bar.total = total
            bar.update(done - bar.n)
        try:
            counts = migrate(args.source, args.target, raw_dir=args.raw_dir, progress=progress)
        finally:
            bar.close()
        if args.json:
            emit_json({"command": "store migrate", "source": args.source, "target": args.target, **counts}, out)
        else:
            print(f"{args.target}: {counts['assets']} assets, {counts['points']} points, {counts['measurements']} "
                  f"measurements ({counts['raw']} with raw records), {counts['results']} results copied from "
                  f"{args.source}", file=out)
        return 0
    from ..io.store import Store
    if args.op == "alarms":
        return _alarms(args, out, Store)
    st = Store(args.store)
    try:
        n = {"assets": len(st.assets()), "points": len(st.points()), "measurements": st.n_measurements,
             "errors": len(st.errors())}
    finally:
        st.close()
    if args.json:
        emit_json({"command": "store info", "store": args.store, **n}, out)
    else:
        print(f"{args.store}: {n['assets']} assets, {n['points']} points, {n['measurements']} measurements, "
              f"{n['errors']} inputs that failed", file=out)
    return 0


def _alarms(args, out, Store) -> int:
    """The alarm history, oldest first: one line (or JSON row) per change of verdict."""
    from ..core.labels import label
    from ..core.rounding import plain
    st = Store(args.store)
    try:
        h = st.alarms(asset=args.asset)
    finally:
        st.close()
    if args.json:
        rows = [{**r, "time": None if r["time"] is None or r["time"] != r["time"] else r["time"].isoformat(),
                 "created": r["created"].isoformat()} for r in h.to_dict(orient="records")]
        from ..core.results import jsonable
        emit_json({"command": "store alarms", "store": args.store, "alarms": jsonable(rows)}, out)
        return 0
    if not len(h):
        print(f"{args.store}: no alarm history (vm.batch records it in a database store)", file=out)
    for r in h.itertuples():
        when = "" if r.time is None or r.time != r.time else r.time.strftime("%Y-%m-%d %H:%M")
        print(f"{when:16s}  {r.asset}/{r.point}  {label(r.metric)}: {r.verdict}  ({plain(r.value, 4)}; "
              f"{r.reason})", file=out)
    return 0
