"""``vibmeasure store migrate``: an HDF5 store copied into a database store, ids and raw records kept."""

from __future__ import annotations

from ...core.errors import ParameterError
from .schema import _dumps, _mnum, _tables, is_sql_target
from .store import SQLStore


def migrate(source, target, *, raw_dir=None, progress=None) -> dict:
    """Copy an HDF5 store into a database store (SQLite file or PostgreSQL URL), ids and raw records kept.

    Parameters
    ----------
    source : str or os.PathLike
        The HDF5 store (.h5), read only.
    target : str or os.PathLike
        The database store to create; it must hold no measurement yet.
    raw_dir : str or os.PathLike, optional
        Where the raw records go (default beside a SQLite target).
    progress : callable, optional
        Called with (done, total) after each measurement.

    Returns
    -------
    dict
        Counts copied: assets, points, measurements, results, raw.

    Raises
    ------
    ParameterError
        For a source that is not an HDF5 store, or a target that already holds measurements.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import vibmeasure as vm
    >>> from vibmeasure.io.sql import migrate
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> with vm.Store(d / "old.h5", writable=True) as st:
    ...     _ = st.add_asset("fan-3"); _ = st.add_point("fan-3", "DE")
    ...     st.add_result(st.add_measurement("fan-3", "DE", time=0.0), "diagnose", {"top": "none"})
    >>> migrate(d / "old.h5", d / "plant.db")["results"]
    1
    """
    import sqlalchemy as sa

    from ..store import Store
    if is_sql_target(source):
        raise ParameterError(f"source={str(source)!r} must be an HDF5 store (.h5)")
    if not is_sql_target(target):
        raise ParameterError(f"target={str(target)!r} must be a database: a .db, .sqlite or .sqlite3 file or a URL")
    old = Store(source)
    counts = dict.fromkeys(("assets", "points", "measurements", "results", "raw"), 0)
    with SQLStore(target, writable=True, raw_dir=raw_dir) as new:
        if new.n_measurements:
            raise ParameterError(f"target={str(target)!r} already holds measurements: migrate into a new store")
        t = _tables()
        for a in old._assets.values():
            new.add_asset(a["asset"], kind=a.get("kind", "machine"), bearing=a.get("bearing"), gear=a.get("gear"),
                          model=a.get("model"), iso_group=a.get("iso_group"), foundation=a.get("foundation"),
                          meta=a.get("meta"))
            counts["assets"] += 1
        for p in old._points.values():
            new.add_point(p["asset"], p["point"], channel=p.get("channel"), direction=p.get("direction"),
                          unit=p.get("unit"))
            counts["points"] += 1
        rows = list(old._each("measurements"))
        for i, r in enumerate(rows, 1):
            raw = new._write_raw(old.record(r["id"])) if r.get("raw") else None
            new._run(t["measurements"].insert().values(
                id=_mnum(r["id"]), asset=r["asset"], point=r["point"], time=r["time"], rpm=r.get("rpm"),
                sha256=r.get("sha256"), file=r.get("file"), raw=raw, meta=_dumps(r.get("meta") or {})))
            counts["measurements"] += 1
            counts["raw"] += raw is not None
            if progress is not None:
                progress(i, len(rows))
        for r in old._each("results"):
            new._run(t["results"].insert().values(
                measurement=_mnum(r["measurement"]), task=r["task"], version=r.get("version"), created=None,
                params=_dumps(r.get("params") or {}), summary=_dumps(r.get("summary") or {}),
                result=_dumps(r.get("result"))))
            counts["results"] += 1
        if new._conn.dialect.name == "postgresql" and counts["measurements"]:
            # ids were given explicitly: the sequence continues after the largest
            new._run(sa.text("SELECT setval(pg_get_serial_sequence('measurements', 'id'), "
                             "(SELECT max(id) FROM measurements))"))
    return counts
