"""The measurement store on a relational database: SQLite for one machine, PostgreSQL for a plant.

One schema (SQLAlchemy Core, ``schema._schema``) on both engines: assets, points, measurements and
results, each result with the vibmeasure version and the parameters that produced it; JSON documents
(meta, params, summary, result) are text columns, so a result's shape can grow without a migration.
Raw records are not in the database: each is a sealed vibmeasure HDF5 file named by its content's
SHA-256 in a folder beside the database (``raw_dir``), written before its row is committed.

Durability and concurrency are the engine's: rows added since the last ``commit()`` form one
transaction, so a process killed at any moment loses only those. SQLite runs in WAL mode (readers
never block the writer, nor it them) with ``synchronous=FULL`` and waits up to ``timeout`` seconds
for another writer's transaction; PostgreSQL takes many writers at once (a batch's Dask workers, a
plant's collectors), each measurement id from one sequence.
"""

from __future__ import annotations

import hashlib
import time as _time
from pathlib import Path

from ...core._validate import regular_input
from ...core.errors import ParameterError
from .._store_common import VERDICT_COLUMNS, STORE_SCHEMA, StoreLockedError, _asset_row, _check_name, _seconds
from . import schema as _schema_mod
from .queries import _SQLQueries
from .schema import SQL_STORE_VERSION, _dumps, _insert, _mid, _mnum, _short, _tables, _url


def _number(v):
    """A finite float, or None (JSON and SQL have no NaN to keep)."""
    try:
        v = float(v)
    except (TypeError, ValueError):
        return None
    return v if v == v and abs(v) != float("inf") else None


class SQLStore(_SQLQueries):
    """A condition-monitoring store on SQLite or PostgreSQL; ``vm.Store`` returns one for a database target.

    The same methods as the HDF5 store (``add_asset``, ``add_point``, ``add_measurement``, ``add_result``,
    ``commit``, ``assets``, ``points``, ``measurements``, ``results``, ``errors``, ``has``, ``record``).
    Rows added since the last commit are one transaction: a process killed at any moment loses only
    those, and readers see every committed row.

    Parameters
    ----------
    target : str or os.PathLike
        A SQLite file (.db, .sqlite, .sqlite3) or a database URL (``postgresql://user@host:port/db``,
        ``sqlite:///path``).
    writable : bool
        Open for writing (creating the schema where it is missing).
    timeout : float
        Seconds to wait for another writer's transaction (SQLite) or for the server (PostgreSQL).
    raw_dir : str or os.PathLike, optional
        Where raw records (``keep_raw=True``) are kept, one sealed HDF5 file per content hash; default
        ``<database>.raw`` beside a SQLite file. A PostgreSQL store needs it to keep raw records.

    Raises
    ------
    ParameterError
        For a missing database opened read-only, a file or database that is not a vibmeasure store, a
        newer schema, or a server that cannot be reached.
    StoreLockedError
        When another writer's transaction holds a SQLite store past ``timeout``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import vibmeasure as vm
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "plant.db"
    >>> with vm.Store(path, writable=True) as st:
    ...     _ = st.add_asset("pump-1", bearing="6205-2RS", iso_group=2)
    ...     _ = st.add_point("pump-1", "DE", channel="acc", unit="g")
    ...     rec = vm.synth.machine(rpm=1797, duration=1.0, seed=1)
    ...     mid = st.add_measurement("pump-1", "DE", time="2026-11-22T08:00", rpm=1797, record=rec, keep_raw=True)
    ...     st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none"})
    >>> st = vm.Store(path)
    >>> st.results("diagnose")["top"].tolist(), st.record(mid).fs
    (['none'], 12000.0)
    """

    def __init__(self, target, *, writable: bool = False, timeout: float = 0.0, raw_dir=None):
        import sqlalchemy as sa
        self.url = _url(target)
        self.is_sqlite = self.url.startswith("sqlite")
        self.path = Path(self.url[len("sqlite:///"):]) if self.is_sqlite else Path(self.url.rsplit("/", 1)[-1] or "db")
        self.target = str(target)
        self.writable = bool(writable)
        if isinstance(timeout, bool) or not isinstance(timeout, (int, float)) or not timeout == timeout:
            raise ParameterError(f"timeout={timeout!r} must be a number of seconds (>= 0)")
        self.timeout = max(float(timeout), 0.0)
        if raw_dir is None and self.is_sqlite:
            raw_dir = self.path.with_name(self.path.name + ".raw")
        self.raw_dir = None if raw_dir is None else Path(raw_dir)
        self._n_pending = 0
        # the writer's own knowledge, so that adding rows costs one INSERT each: the points and
        # measurements it has seen exist (rows are never deleted), and its results not yet sent
        # (sent in one executemany before any read or commit)
        self._seen_points: set = set()
        self._seen_ids: dict = {}      # measurement id -> (asset, point, time), copied into its results
        self._joined = False           # a version-1 store read as it is: results get their asset through the join
        self._results_out: list = []
        if self.is_sqlite and self.path.exists():
            regular_input(self.path, "store")
        if self.is_sqlite and not self.writable and not self.path.exists():
            raise ParameterError(f"store {self.target!r} does not exist (open it with writable=True to create it)")
        self._engine = self._make_engine(sa)
        self._conn = None
        try:
            self._prepare(sa)
        except BaseException:
            self._dispose()
            raise

    # --- opening -------------------------------------------------------------------------------
    def _make_engine(self, sa):
        from sqlalchemy.pool import NullPool
        if self.is_sqlite:
            engine = sa.create_engine(self.url, poolclass=NullPool,
                                      connect_args={"timeout": self.timeout, "check_same_thread": False})
            ms = int(self.timeout * 1000)

            @sa.event.listens_for(engine, "connect")
            def _pragmas(dbapi_conn, _record):
                cur = dbapi_conn.cursor()
                # WAL: readers never block the writer; FULL: a committed row survives a power loss too
                for pragma in ("journal_mode=WAL", "synchronous=FULL", "foreign_keys=ON", f"busy_timeout={ms}"):
                    cur.execute(f"PRAGMA {pragma}")
                cur.close()
            return engine
        try:
            return sa.create_engine(self.url, poolclass=NullPool,
                                    connect_args={"connect_timeout": max(1, int(self.timeout) or 10)})
        except ModuleNotFoundError as exc:
            raise ParameterError(f"store {self.target!r}: the database driver is missing ({exc.name}); "
                                 "install it with: pip install 'vibmeasure[postgres]'") from None

    def _prepare(self, sa):
        """The schema checked (and created when writable and missing)."""
        t = _tables()
        try:
            self._conn = self._engine.connect()
            names = set(sa.inspect(self._conn).get_table_names())
            if "vibmeasure" not in names:
                if names - set(t):   # tables that are not a store's (ours alone: one being created)
                    raise ParameterError(f"store {self.target!r} is a database of something else (tables "
                                         f"{sorted(names)[:5]}), not a vibmeasure store")
                if not self.writable:
                    raise ParameterError(f"store {self.target!r} holds no vibmeasure store (open it with "
                                         "writable=True to create one)")
            if self.writable:   # idempotent: a writer that created the tables may not have written the version
                self._create(sa)
            info = dict(self._conn.execute(sa.select(t["vibmeasure"].c.key, t["vibmeasure"].c.value)).all())
            self._end_read()
        except ParameterError:
            raise
        except sa.exc.OperationalError as exc:
            self._raise_operational(exc)
        except sa.exc.DatabaseError as exc:
            raise ParameterError(f"store {self.target!r} is not a readable database ({_short(exc)})") from None
        if info.get("schema") != STORE_SCHEMA:
            raise ParameterError(f"store {self.target!r} is not a vibmeasure store (schema {info.get('schema')!r})")
        version = int(info.get("schema_version", "0"))
        if version > SQL_STORE_VERSION:
            raise ParameterError(f"store {self.target!r} has schema_version {version}; this vibmeasure reads up to "
                                 f"{SQL_STORE_VERSION}")
        if version < 2 and self.writable:
            self._upgrade(sa)
        self._joined = version < 2 and not self.writable

    def _create(self, sa):
        """The schema and its version row. Two writers creating one store at once: a CREATE may fail on a
        table the other just made; the missing ones are created again until every table stands, then
        the version row is written (waiting for the other's transaction, nothing when it wrote it)."""
        t = _tables()
        deadline = _time.monotonic() + self.timeout + 10.0
        while True:   # each try creates the tables still missing; another writer may be creating them too
            try:
                _schema_mod._MD.create_all(self._conn, checkfirst=True)
                self._conn.commit()
                break
            except (sa.exc.OperationalError, sa.exc.ProgrammingError, sa.exc.IntegrityError):
                self._conn.rollback()
                if _time.monotonic() > deadline:
                    raise
                _time.sleep(0.05)
        ins = _insert(self._conn, t["vibmeasure"])
        self._conn.execute(ins.values([{"key": "schema", "value": STORE_SCHEMA},
                                       {"key": "schema_version", "value": str(SQL_STORE_VERSION)},
                                       {"key": "created", "value": repr(_time.time())}])
                           .on_conflict_do_nothing())
        self._conn.commit()

    def _upgrade(self, sa):
        """A version-1 store made version 2: the results' asset, point and time columns added and copied
        from their measurements (one transaction), PostgreSQL's table vacuumed (so that the index-only
        scans need not visit the rows the copy rewrote), then the indexes built and the version set (a
        million results: about half a minute, once). Two writers upgrading at once: the second finds the
        work done; a writer of an older vibmeasure still connected writes rows the trend does not see."""
        t = _tables()
        r, m, v = t["results"], t["measurements"], t["vibmeasure"]
        deadline = _time.monotonic() + self.timeout + 60.0
        while True:
            try:
                have = {c["name"] for c in sa.inspect(self._conn).get_columns("results")}
                quote = self._conn.dialect.identifier_preparer.quote
                for name in ("asset", "point", "time"):
                    if name not in have:
                        kind = r.c[name].type.compile(dialect=self._conn.dialect)
                        self._conn.execute(sa.text(f"ALTER TABLE results ADD COLUMN {quote(name)} {kind}"))
                of = {k: sa.select(m.c[k]).where(m.c.id == r.c.measurement).scalar_subquery()
                      for k in ("asset", "point", "time")}
                self._conn.execute(r.update().where(r.c.asset.is_(None)).values(**of))
                self._conn.commit()
                if self._conn.dialect.name == "postgresql":
                    with self._engine.connect().execution_options(isolation_level="AUTOCOMMIT") as c:
                        c.execute(sa.text("VACUUM ANALYZE results"))
                for index in r.indexes:
                    index.create(self._conn, checkfirst=True)
                self._conn.execute(v.update().where(v.c.key == "schema_version").values(value=str(SQL_STORE_VERSION)))
                self._conn.commit()
                return
            except (sa.exc.OperationalError, sa.exc.ProgrammingError, sa.exc.IntegrityError) as exc:
                self._conn.rollback()
                text = _short(exc).lower()
                # another writer's upgrade: its columns or indexes appear under ours, or it holds the lock
                racing = any(w in text for w in ("already exists", "duplicate", "locked", "busy", "deadlock"))
                if not racing or _time.monotonic() > deadline:
                    raise ParameterError(f"store {self.target!r} has schema_version 1 and could not be upgraded to "
                                         f"{SQL_STORE_VERSION} ({_short(exc)}): open it for writing once as a user "
                                         "who may alter its tables, or open it read-only") from None
                _time.sleep(0.05)

    def _raise_operational(self, exc):
        text = _short(exc)
        if "locked" in text or "busy" in text:
            raise StoreLockedError(f"store {self.target!r}: another writer holds it past timeout={self.timeout:g} s "
                                   f"({text})") from None
        raise ParameterError(f"store {self.target!r}: the database cannot be used ({text})") from None

    def _end_read(self):
        """Close a read-only store's snapshot, so that its next query sees every row committed since."""
        if not self.writable and self._conn is not None and self._conn.in_transaction():
            self._conn.rollback()

    def _run(self, stmt, params=None):
        """Execute one statement (with ``params``: bound values, or a list of them for executemany),
        after the results not yet sent; a lock held past the timeout, or a lost server, is named."""
        import sqlalchemy as sa
        try:
            if self._results_out:
                out, self._results_out = self._results_out, []
                self._conn.execute(_tables()["results"].insert(), out)
            return self._conn.execute(stmt, params)
        except sa.exc.OperationalError as exc:
            self._raise_operational(exc)
        except sa.exc.IntegrityError as exc:
            raise ParameterError(f"store {self.target!r}: the row breaks the store's rules ({_short(exc)})") from None

    # --- life ----------------------------------------------------------------------------------
    def commit(self) -> None:
        """Make the rows added since the last commit durable (one transaction).

        Returns
        -------
        None

        Raises
        ------
        ParameterError
            For a store opened read-only, or a database that refuses the transaction.
        StoreLockedError
            When another writer holds a SQLite store past ``timeout``.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "plant.db"
        >>> st = vm.Store(path, writable=True)
        >>> _ = st.add_asset("pump-1")
        >>> st.commit()
        >>> vm.Store(path).assets()["asset"].tolist()
        ['pump-1']
        >>> st.close()
        """
        import sqlalchemy as sa
        self._need_writable()
        if self._results_out:
            self._run(sa.text("SELECT 1"))   # sends them
        from .._common import write_errors_not_signals
        try:
            with write_errors_not_signals():   # a file-size limit: SQLite reports it, the process lives
                self._conn.commit()
        except sa.exc.OperationalError as exc:
            self._raise_operational(exc)
        self._n_pending = 0

    def close(self, *, commit: bool = True) -> None:
        """Commit (or, with ``commit=False``, roll back) the pending rows and release the connection."""
        if self._conn is None:
            return
        try:
            if self.writable and commit:
                self.commit()
            elif self._conn.in_transaction():
                self._results_out = []
                self._conn.rollback()
        finally:
            self._dispose()

    def _dispose(self):
        if self._conn is not None:
            try:
                self._conn.close()
            except Exception:   # a connection already broken is closed as far as we are concerned
                pass
            self._conn = None
        self._engine.dispose() if getattr(self, "_engine", None) is not None else None

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        self.close(commit=exc_type is None)

    def __del__(self):
        try:
            self.close(commit=False)
        except Exception:   # at interpreter exit the modules may be gone
            pass

    @property
    def pending(self) -> int:
        """Rows added since the last commit."""
        return self._n_pending

    def __repr__(self) -> str:
        import sqlalchemy as sa
        t = _tables()
        n = {k: self._run(sa.select(sa.func.count()).select_from(t[k])).scalar_one()
             for k in ("assets", "points", "measurements", "results")}
        self._end_read()
        where = self.path if self.is_sqlite else self.url.split("@")[-1]
        return (f"Store({str(where)!r}: {n['assets']} assets, {n['points']} points, {n['measurements']} "
                f"measurements, {n['results']} results{'; writable' if self.writable else ''})")

    # --- writing -------------------------------------------------------------------------------
    def _need_writable(self):
        if not self.writable or self._conn is None:
            raise ParameterError(f"store {self.target!r} is open for reading: open it with writable=True to add")

    def add_asset(self, asset: str, *, kind: str = "machine", bearing=None, gear=None, model=None,
                  iso_group: int | None = None, foundation: str | None = None, meta: dict | None = None) -> str:
        """An asset (a machine or a structure) with what its analysis needs; see ``Store.add_asset``.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> with vm.Store(pathlib.Path(tempfile.mkdtemp()) / "p.db", writable=True) as st:
        ...     st.add_asset("fan-3", bearing="6205-2RS")
        'fan-3'
        """
        self._need_writable()
        row = _asset_row(asset, kind, bearing, gear, model, iso_group, foundation, meta)
        try:
            db_row = dict(row, gear=_dumps(gear), meta=_dumps(row["meta"]))
        except (TypeError, ValueError):
            raise ParameterError(f"asset={asset!r}: its gear and meta must be JSON-able") from None
        # two writers adding one asset at once: the second insert does nothing, then both compare
        self._run(_insert(self._conn, _tables()["assets"]).values(**db_row).on_conflict_do_nothing())
        old = self._assets[asset]
        if old != row:
            raise ParameterError(f"asset={asset!r} exists in the store with a different description")
        self._n_pending += 1
        return asset

    def add_point(self, asset: str, point: str, *, channel: str | None = None, direction: str | None = None,
                  unit: str | None = None) -> str:
        """A measurement point of an asset; see ``Store.add_point``.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> with vm.Store(pathlib.Path(tempfile.mkdtemp()) / "p.db", writable=True) as st:
        ...     _ = st.add_asset("fan-3")
        ...     st.add_point("fan-3", "DE", unit="g")
        'DE'
        """
        self._need_writable()
        _check_name(point, "point")
        if asset not in self._assets:
            raise ParameterError(f"asset={asset!r} is not in the store: add_asset first")
        row = {"asset": asset, "point": point, "channel": channel, "direction": direction, "unit": unit}
        self._run(_insert(self._conn, _tables()["points"]).values(**row).on_conflict_do_nothing())
        if self._points[(asset, point)] != row:
            raise ParameterError(f"point {asset}/{point} exists in the store with a different description")
        self._n_pending += 1
        return point

    def add_measurement(self, asset: str, point: str, *, time, rpm: float | None = None, record=None,
                        keep_raw: bool = False, sha256: str | None = None, file: str | None = None,
                        meta: dict | None = None) -> str:
        """A measurement of a point at a time; its id ("m0000001", ...) comes from the database.

        See ``Store.add_measurement``. A raw record (``keep_raw=True``) is written to ``raw_dir`` as a
        sealed HDF5 file named by its content's SHA-256 before the row is added.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> with vm.Store(pathlib.Path(tempfile.mkdtemp()) / "p.db", writable=True) as st:
        ...     _ = st.add_asset("fan-3"); _ = st.add_point("fan-3", "DE")
        ...     st.add_measurement("fan-3", "DE", time="2026-11-28T08:00", rpm=1480)
        'm0000001'
        """
        import numpy as np
        self._need_writable()
        if (asset, point) not in self._seen_points:
            if (asset, point) not in self._points:
                raise ParameterError(f"point {asset}/{point} is not in the store: add_point first")
            self._seen_points.add((asset, point))
        t = _seconds(time)
        if rpm is not None and not (np.isfinite(rpm) and rpm > 0):
            raise ParameterError(f"rpm={rpm!r} must be > 0")
        if sha256 is None and record is not None:
            sha256 = hashlib.sha256(np.ascontiguousarray(record.data).tobytes()).hexdigest()
        try:
            meta_text = _dumps(meta or {})
        except (TypeError, ValueError):
            raise ParameterError("meta must be JSON-able") from None
        raw = self._write_raw(record) if keep_raw and record is not None else None
        res = self._run(_tables()["measurements"].insert(), dict(
            asset=asset, point=point, time=t, rpm=None if rpm is None else float(rpm), sha256=sha256, file=file,
            raw=raw, meta=meta_text))
        self._n_pending += 1
        mid = _mid(res.inserted_primary_key[0])
        self._seen_ids[mid] = (asset, point, t)
        return mid

    def _write_raw(self, record) -> str:
        """The record as a sealed HDF5 file in raw_dir named by its content's SHA-256 (the same content is
        written once); returns that name."""
        import numpy as np

        from ..hdf5 import write_hdf5
        if self.raw_dir is None:
            raise ParameterError(f"store {self.target!r} keeps raw records only with raw_dir= (a folder for "
                                 "their files): give Store(..., raw_dir=...) or keep_raw=False")
        h = hashlib.sha256(np.ascontiguousarray(record.data).tobytes())
        h.update(_dumps({"fs": float(record.fs), "t0": float(record.t0),
                         "channels": [[c.name, c.quantity, c.unit, c.location] for c in record.channels]}).encode())
        key = h.hexdigest()
        path = self.raw_dir / key[:2] / f"{key}.h5"
        if not path.exists():
            try:
                path.parent.mkdir(parents=True, exist_ok=True)
            except OSError as exc:
                raise ParameterError(f"raw_dir={str(self.raw_dir)!r}: cannot create it ({exc.strerror})") from None
            write_hdf5(path, record)
        return key

    def record_verdicts(self, verdicts) -> int:
        """Write the trend verdicts that changed into the alarm history (``alarms``): a row per asset,
        point, task and metric whose verdict differs from the last one recorded (the first evaluation
        is recorded too, so that the history starts). Part of the pending transaction.

        Parameters
        ----------
        verdicts : pandas.DataFrame
            ``vm.trend`` of this store (or of some of its assets).

        Returns
        -------
        int
            Rows written.

        Raises
        ------
        ParameterError
            For a store opened read-only.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import pandas as pd
        >>> import vibmeasure as vm
        >>> st = vm.Store(pathlib.Path(tempfile.mkdtemp()) / "p.db", writable=True)
        >>> v = pd.DataFrame({"asset": ["fan"], "point": ["DE"], "task": ["diagnose"], "metric": ["zone"],
        ...                   "verdict": ["alarm"], "last": [7.2], "alarm_limit": [4.5], "watch_limit": [2.8],
        ...                   "reason": ["ISO zone D"], "last_time": [pd.Timestamp("2026-11-28", tz="UTC")]})
        >>> st.record_verdicts(v), st.record_verdicts(v)
        (1, 0)
        """
        import sqlalchemy as sa
        self._need_writable()
        missing = [c for c in VERDICT_COLUMNS if c not in getattr(verdicts, "columns", ())]
        if missing:
            raise ParameterError(f"verdicts must be a vm.trend frame (columns {list(VERDICT_COLUMNS)} at least); "
                                 f"got {type(verdicts).__name__} without {missing}")
        bad = sorted({str(v) for v in verdicts["verdict"]} - {"ok", "watch", "alarm", "no baseline yet"})
        if bad:
            raise ParameterError(f"verdicts: verdict values must be ok, watch, alarm or 'no baseline yet', got {bad}")
        a = _tables()["alarms"]
        last = {}
        for row in self._run(sa.select(a.c.asset, a.c.point, a.c.task, a.c.metric, a.c.verdict).order_by(a.c.id)):
            last[tuple(row[:4])] = row[4]
        out, now = [], _time.time()
        for r in verdicts.to_dict(orient="records"):
            key = (str(r["asset"]), str(r["point"]), str(r.get("task") or ""), str(r["metric"]))
            if last.get(key) == r["verdict"]:
                continue
            limit = r.get("alarm_limit") if r["verdict"] == "alarm" else r.get("watch_limit")
            t = r.get("last_time")
            out.append({"asset": key[0], "point": key[1], "task": key[2], "metric": key[3], "verdict": str(r["verdict"]),
                        "value": _number(r.get("last")), "limit_value": _number(limit),
                        "reason": str(r.get("reason") or ""),
                        "time": None if t is None or t != t else float(getattr(t, "timestamp", lambda: t)()),
                        "created": now})
            last[key] = r["verdict"]
        if out:
            self._run(a.insert(), out)
            self._n_pending += len(out)
        return len(out)

    def add_result(self, measurement: str, task: str, result: dict, *, params: dict | None = None,
                   summary: dict | None = None) -> None:
        """A result of a task for a measurement; the vibmeasure version is recorded (``Store.add_result``).

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> with vm.Store(pathlib.Path(tempfile.mkdtemp()) / "p.db", writable=True) as st:
        ...     _ = st.add_asset("fan-3"); _ = st.add_point("fan-3", "DE")
        ...     mid = st.add_measurement("fan-3", "DE", time=0.0)
        ...     st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none"})
        ...     st.results("diagnose")["top"].tolist()
        ['none']
        """
        from ... import __version__
        from ...core.results import jsonable
        self._need_writable()
        where = self._seen_ids.get(measurement) if isinstance(measurement, str) else None
        if where is None:
            where = self._located(measurement)
            if where is None:
                raise ParameterError(f"measurement={measurement!r} is not in the store")
            self._seen_ids[measurement] = where
        task = _check_name(task, "task")
        try:
            cols = {k: _dumps(jsonable(v or {})) for k, v in (("params", params), ("summary", summary))}
            cols["result"] = _dumps(jsonable(result))
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"the {task!r} result is not JSON-able ({exc})") from None
        self._results_out.append(dict(measurement=_mnum(measurement), task=task, version=__version__,
                                      created=_time.time(), asset=where[0], point=where[1], time=where[2], **cols))
        self._n_pending += 1
