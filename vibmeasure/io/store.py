"""The measurement store: one HDF5 file per condition-monitoring project (schema in docs/store.md).

Assets (machines, structures) with their metadata, measurement points, measurements (time, rpm,
content hash, the raw record optionally) and results (ring-down and modal estimates, spectra
summaries, diagnoses, comparisons), each result with the vibmeasure version and the parameters that
produced it. Rows are JSON documents in variable-length string datasets, so the schema can grow
without a migration; raw records are datasets of their own.

Crash safety is copy-on-commit: a commit copies the committed file, appends the pending rows to the
copy, seals it (SHA-256 in the user block), flushes it to disk and renames it over the store. A
writer killed at any moment leaves the previous committed file (plus a temporary file that the next
writer removes); readers only ever open a committed file. One writer at a time holds an advisory
lock (``fcntl.flock`` on ``<store>.lock``, released by the kernel if the holder dies); a second
writer gets :class:`StoreLockedError` naming the holder, or waits up to ``timeout`` seconds.
"""

from __future__ import annotations

import json
import os
import shutil
import socket
import time as _time
from pathlib import Path

import numpy as np

from ..core.errors import ParameterError, VibMeasureError

__all__ = ["Store", "StoreLockedError", "STORE_SCHEMA", "STORE_VERSION"]

STORE_SCHEMA = "vibmeasure.store"
STORE_VERSION = 1
TABLES = ("assets", "points", "measurements", "results")
TASK_ALIASES = {"diagnosis": "diagnose", "modal": "modes", "spectra": "spectrum", "comparison": "compare"}


def _hash_key(sha256: str) -> np.uint64:
    """The first 64 bits of a hex SHA-256: the in-memory index key (8 bytes per measurement)."""
    try:
        return np.uint64(int(sha256[:16], 16))
    except ValueError:
        return np.uint64(0)


class StoreLockedError(VibMeasureError):
    """Another process holds the store's writer lock."""


def _seconds(t) -> float:
    from ..core._validate import as_seconds
    return as_seconds(t)


def _check_name(value, what: str) -> str:
    if not isinstance(value, str) or not value.strip() or len(value) > 200 or any(c in value for c in "\n\r\0"):
        raise ParameterError(f"{what}={value!r} must be a non-empty name (one line, at most 200 characters)")
    return value


class Store:
    """A condition-monitoring store: assets, points, measurements and results in one HDF5 file.

    ``Store(path)`` reads; ``Store(path, writable=True)`` also writes (creating the file) under the
    writer lock. As a context manager the pending rows are committed on a clean exit and the lock is
    released. Commits are copy-on-write and sealed: a writer killed at any moment leaves every earlier
    commit readable (schema in docs/store.md).

    Parameters
    ----------
    path : str or os.PathLike
        The store file (.h5).
    writable : bool
        Open for writing (one writer at a time).
    timeout : float
        Seconds to wait for another writer's lock.

    Raises
    ------
    ParameterError
        For a damaged or foreign file, or a missing file opened read-only.
    StoreLockedError
        When another process holds the writer lock past ``timeout``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import vibmeasure as vm
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "plant.h5"
    >>> with vm.Store(path, writable=True) as st:
    ...     _ = st.add_asset("pump-1", bearing="6205-2RS", iso_group=2)
    ...     _ = st.add_point("pump-1", "DE", channel="acc", unit="g")
    ...     rec = vm.synth.machine(rpm=1797, duration=1.0, seed=1)
    ...     mid = st.add_measurement("pump-1", "DE", time="2026-11-22T08:00", rpm=1797, record=rec, keep_raw=True)
    ...     st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none"})
    >>> st = vm.Store(path)
    >>> st.results("diagnose")["top"].tolist()
    ['none']
    """

    def __init__(self, path, *, writable: bool = False, timeout: float = 0.0):
        self.path = Path(path)
        self.writable = bool(writable)
        self._lock_fd = None
        # in memory: assets and points (the fleet's size), the committed row counts, a compact index of
        # the measurements' content hashes and the rows not yet committed; every measurement and result
        # row stays on disk until a query reads it, so a long batch's client does not grow
        self._pending: dict[str, list] = {k: [] for k in TABLES}
        self._raw_pending: dict[str, object] = {}
        self._n = {k: 0 for k in TABLES}
        self._assets: dict[str, dict] = {}
        self._points: dict[tuple, dict] = {}
        self._pending_meas: dict[str, dict] = {}
        self._hash_keys = np.empty(0, np.uint64)   # first 64 bits of each stored SHA-256, sorted
        self._hash_rows = np.empty(0, np.int64)    # the measurement row of each key
        if self.writable:
            self._lock(timeout)
        try:
            if self.path.exists():
                self._load()
        except BaseException:
            self._unlock()
            raise
        if not self.path.exists() and not self.writable:
            raise ParameterError(f"store {str(self.path)!r} does not exist (open it with writable=True to create it)")

    # --- locking -------------------------------------------------------------------------------
    def _lock(self, timeout):
        import fcntl
        lock_path = self.path.with_name(self.path.name + ".lock")
        try:
            fd = os.open(lock_path, os.O_RDWR | os.O_CREAT, 0o666)
        except OSError as exc:
            raise ParameterError(f"store {str(self.path)!r}: cannot create its lock file ({exc.strerror})") from None
        deadline = _time.monotonic() + max(float(timeout), 0.0)
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if _time.monotonic() >= deadline:
                    try:
                        holder = os.pread(fd, 200, 0).decode(errors="replace").strip() or "another process"
                    finally:
                        os.close(fd)
                    raise StoreLockedError(f"store {str(self.path)!r} is being written by {holder}; one writer at a "
                                           "time (wait with timeout=, or read it with writable=False)") from None
                _time.sleep(0.05)
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"pid {os.getpid()} on {socket.gethostname()} since "
                      f"{_time.strftime('%Y-%m-%dT%H:%M:%S')}".encode(), 0)
        self._lock_fd = fd

    def _unlock(self):
        if self._lock_fd is not None:
            import fcntl
            try:
                os.ftruncate(self._lock_fd, 0)
                fcntl.flock(self._lock_fd, fcntl.LOCK_UN)
            finally:
                os.close(self._lock_fd)
                self._lock_fd = None

    def close(self, *, commit: bool = True):
        """Commit the pending rows (unless ``commit=False``) and release the writer lock.

        Parameters
        ----------
        commit : bool
            Commit first.

        Returns
        -------
        None

        Raises
        ------
        ParameterError
            When the commit fails (the store keeps its last commit).

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "plant.h5"
        >>> with vm.Store(path, writable=True) as st:
        ...     _ = st.add_asset("pump-1", bearing="6205-2RS", iso_group=2)
        ...     _ = st.add_point("pump-1", "DE", channel="acc", unit="g")
        ...     rec = vm.synth.machine(rpm=1797, duration=1.0, seed=1)
        ...     mid = st.add_measurement("pump-1", "DE", time="2026-11-22T08:00", rpm=1797, record=rec, keep_raw=True)
        ...     st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none"})
        >>> st = vm.Store(path)
        >>> st.close()
        """
        try:
            if commit and self.writable:
                self.commit()
        finally:
            self._unlock()

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        self.close(commit=exc_type is None)

    def __del__(self):
        try:
            self._unlock()
        except Exception:
            pass

    # --- reading ------------------------------------------------------------------------------
    def _open(self):
        import h5py
        try:
            return h5py.File(self.path, "r")
        except OSError as exc:
            raise ParameterError(f"store {str(self.path)!r} is damaged: {exc}") from None

    def _load(self) -> None:
        from .hdf5 import check_seal
        src = f"store {str(self.path)!r}"
        if not self.path.is_file():
            raise ParameterError(f"{src} is not a file")
        if not check_seal(self.path, src):
            raise ParameterError(f"{src} is not a vibmeasure store (no seal: not written by vm.Store)")
        try:
            with self._open() as f:
                schema = f.attrs.get("vibmeasure_schema")
                schema = schema.decode() if isinstance(schema, bytes) else schema
                if schema != STORE_SCHEMA:
                    raise ParameterError(f"{src} is not a vibmeasure store (schema {schema!r})")
                version = int(f.attrs.get("schema_version", -1))
                if version != STORE_VERSION:
                    raise ParameterError(f"{src} has store schema version {version}; this vibmeasure reads version "
                                         f"{STORE_VERSION} (upgrade vibmeasure, or convert the store)")
                self._n = {k: int(f[k].shape[0]) for k in TABLES}
                self._assets = {r["asset"]: r for r in self._rows_of(f, "assets")}
                self._points = {(r["asset"], r["point"]): r for r in self._rows_of(f, "points")}
                keys, rows = [], []
                for i, r in enumerate(self._rows_of(f, "measurements")):
                    if r.get("sha256"):
                        keys.append(_hash_key(r["sha256"]))
                        rows.append(i)
        except (OSError, KeyError, ValueError, TypeError) as exc:
            if isinstance(exc, ParameterError):
                raise
            raise ParameterError(f"{src} is damaged: {exc}") from None
        keys = np.array(keys, np.uint64)
        order = np.argsort(keys, kind="stable")
        self._hash_keys, self._hash_rows = keys[order], np.array(rows, np.int64)[order]

    def _rows_of(self, f, table, chunk: int = 4096):
        """The committed rows of a table as dicts, read in chunks (only the rows this Store has seen
        committed: a later commit by another writer only appends)."""
        d = f[table].asstr()
        n = min(self._n[table], d.shape[0])
        for i0 in range(0, n, chunk):
            for v in d[i0:min(i0 + chunk, n)]:
                yield json.loads(v)

    def _each(self, table):
        """Every row of a table, committed (streamed from the file) then pending."""
        if self._n[table]:
            try:
                with self._open() as f:
                    yield from self._rows_of(f, table)
            except (KeyError, ValueError, TypeError) as exc:
                raise ParameterError(f"store {str(self.path)!r} is damaged: {exc}") from None
        yield from self._pending[table]

    def _frame(self, table, **filters):
        import pandas as pd
        if table == "assets":
            rows = list(self._assets.values())
        elif table == "points":
            rows = list(self._points.values())
        else:
            rows = list(self._each(table))
        df = pd.DataFrame(rows)
        for k, v in filters.items():
            if v is not None and k in df:
                df = df[df[k] == v]
        return df.reset_index(drop=True)

    def assets(self):
        """Assets as a DataFrame (asset, kind, bearing, gear, model, iso_group, foundation, meta).

        Returns
        -------
        pandas.DataFrame

        Raises
        ------
        ParameterError
            Never for an open store.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "plant.h5"
        >>> with vm.Store(path, writable=True) as st:
        ...     _ = st.add_asset("pump-1", bearing="6205-2RS", iso_group=2)
        ...     _ = st.add_point("pump-1", "DE", channel="acc", unit="g")
        ...     rec = vm.synth.machine(rpm=1797, duration=1.0, seed=1)
        ...     mid = st.add_measurement("pump-1", "DE", time="2026-11-22T08:00", rpm=1797, record=rec, keep_raw=True)
        ...     st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none"})
        >>> st = vm.Store(path)
        >>> st.assets()["asset"].tolist()
        ['pump-1']
        """
        return self._frame("assets")

    def points(self, asset: str | None = None):
        """Measurement points as a DataFrame (asset, point, channel, direction, unit).

        Parameters
        ----------
        asset : str, optional
            Only this asset's.

        Returns
        -------
        pandas.DataFrame

        Raises
        ------
        ParameterError
            Never for an open store.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "plant.h5"
        >>> with vm.Store(path, writable=True) as st:
        ...     _ = st.add_asset("pump-1", bearing="6205-2RS", iso_group=2)
        ...     _ = st.add_point("pump-1", "DE", channel="acc", unit="g")
        ...     rec = vm.synth.machine(rpm=1797, duration=1.0, seed=1)
        ...     mid = st.add_measurement("pump-1", "DE", time="2026-11-22T08:00", rpm=1797, record=rec, keep_raw=True)
        ...     st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none"})
        >>> st = vm.Store(path)
        >>> st.points("pump-1")["channel"].tolist()
        ['acc']
        """
        return self._frame("points", asset=asset)

    def measurements(self, asset: str | None = None, point: str | None = None, since=None, until=None):
        """Measurements as a DataFrame, oldest first; ``time`` as UTC Timestamps.

        Parameters
        ----------
        asset, point : str, optional
            Only these.
        since, until : float, str or datetime, optional
            Only this time range.

        Returns
        -------
        pandas.DataFrame

        Raises
        ------
        ParameterError
            For a bad time.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "plant.h5"
        >>> with vm.Store(path, writable=True) as st:
        ...     _ = st.add_asset("pump-1", bearing="6205-2RS", iso_group=2)
        ...     _ = st.add_point("pump-1", "DE", channel="acc", unit="g")
        ...     rec = vm.synth.machine(rpm=1797, duration=1.0, seed=1)
        ...     mid = st.add_measurement("pump-1", "DE", time="2026-11-22T08:00", rpm=1797, record=rec, keep_raw=True)
        ...     st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none"})
        >>> st = vm.Store(path)
        >>> st.measurements(asset="pump-1")["rpm"].tolist()
        [1797.0]
        """
        return self._timed(self._frame("measurements", asset=asset, point=point), since, until)

    def results(self, task: str, asset: str | None = None, point: str | None = None, since=None, until=None):
        """Results of one task as a DataFrame, oldest first.

        Parameters
        ----------
        task : str
            The task.
        asset, point : str, optional
            Only these.
        since, until : float, str or datetime, optional
            Only this time range.

        Returns
        -------
        pandas.DataFrame
            measurement, asset, point, time, task, version, params, the summary values as columns and
            ``result`` (the full result, a dict).

        Raises
        ------
        ParameterError
            For a bad time.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "plant.h5"
        >>> with vm.Store(path, writable=True) as st:
        ...     _ = st.add_asset("pump-1", bearing="6205-2RS", iso_group=2)
        ...     _ = st.add_point("pump-1", "DE", channel="acc", unit="g")
        ...     rec = vm.synth.machine(rpm=1797, duration=1.0, seed=1)
        ...     mid = st.add_measurement("pump-1", "DE", time="2026-11-22T08:00", rpm=1797, record=rec, keep_raw=True)
        ...     st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none"})
        >>> st = vm.Store(path)
        >>> st.results("diagnose", asset="pump-1")["top"].tolist()
        ['none']
        """
        import pandas as pd
        task = TASK_ALIASES.get(task, task)
        meas = {r["id"]: (r["asset"], r["point"], r["time"]) for r in self._each("measurements")}
        flat = []
        for r in self._each("results"):
            if r["task"] != task:
                continue
            a, p, t = meas.get(r["measurement"], (None, None, None))
            if asset is not None and a != asset or point is not None and p != point:
                continue
            flat.append({"measurement": r["measurement"], "asset": a, "point": p, "time": t, "task": r["task"],
                         "version": r["version"], "params": r.get("params", {}), **r.get("summary", {}),
                         "result": r.get("result")})
        df = pd.DataFrame(flat)
        if df.empty:
            return pd.DataFrame(columns=["measurement", "asset", "point", "time", "task", "version", "params"])
        for k, v in (("asset", asset), ("point", point)):
            if v is not None:
                df = df[df[k] == v]
        return self._timed(df.reset_index(drop=True), since, until)

    def errors(self):
        """Inputs a batch could not analyse: measurement, file and the error message.

        Returns
        -------
        pandas.DataFrame

        Raises
        ------
        ParameterError
            Never for an open store.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "plant.h5"
        >>> with vm.Store(path, writable=True) as st:
        ...     _ = st.add_asset("pump-1", bearing="6205-2RS", iso_group=2)
        ...     _ = st.add_point("pump-1", "DE", channel="acc", unit="g")
        ...     rec = vm.synth.machine(rpm=1797, duration=1.0, seed=1)
        ...     mid = st.add_measurement("pump-1", "DE", time="2026-11-22T08:00", rpm=1797, record=rec, keep_raw=True)
        ...     st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none"})
        >>> st = vm.Store(path)
        >>> len(st.errors())
        0
        """
        return self.results("error")

    @staticmethod
    def _timed(df, since, until):
        import pandas as pd
        if df.empty or "time" not in df:
            return df
        if since is not None:
            df = df[df["time"] >= _seconds(since)]
        if until is not None:
            df = df[df["time"] <= _seconds(until)]
        df = df.sort_values("time", kind="stable").reset_index(drop=True)
        df["time"] = pd.to_datetime(df["time"], unit="s", utc=True)
        return df

    def has(self, sha256: str) -> str | None:
        """The measurement id already stored for a content hash, or None (the latest if several).

        Parameters
        ----------
        sha256 : str
            The content hash.

        Returns
        -------
        str or None

        Raises
        ------
        ParameterError
            Never for an open store.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "plant.h5"
        >>> with vm.Store(path, writable=True) as st:
        ...     _ = st.add_asset("pump-1", bearing="6205-2RS", iso_group=2)
        ...     _ = st.add_point("pump-1", "DE", channel="acc", unit="g")
        ...     rec = vm.synth.machine(rpm=1797, duration=1.0, seed=1)
        ...     mid = st.add_measurement("pump-1", "DE", time="2026-11-22T08:00", rpm=1797, record=rec, keep_raw=True)
        ...     st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none"})
        >>> st = vm.Store(path)
        >>> st.has("0" * 64) is None
        True
        """
        if not isinstance(sha256, str) or not sha256:
            return None   # no hash matches nothing (not a pending measurement stored without a hash)
        for mid in reversed(self._pending_meas):
            if self._pending_meas[mid].get("sha256") == sha256:
                return mid
        key = _hash_key(sha256)
        i = int(np.searchsorted(self._hash_keys, key, side="right"))
        if not i or self._hash_keys[i - 1] != key:
            return None
        with self._open() as f:  # the index holds 64 bits of the hash: confirm on the stored row
            d = f["measurements"].asstr()
            while i and self._hash_keys[i - 1] == key:
                i -= 1
                row = json.loads(d[int(self._hash_rows[i])])
                if row.get("sha256") == sha256:
                    return row["id"]
        return None

    def _known(self, measurement) -> bool:
        if measurement in self._pending_meas:
            return True
        if not isinstance(measurement, str) or len(measurement) < 8 or measurement[0] != "m" \
                or not measurement[1:].isdigit():
            return False
        return 1 <= int(measurement[1:]) <= self._n["measurements"]

    @property
    def n_measurements(self) -> int:
        """Measurements in the store, committed or pending."""
        return self._n["measurements"] + len(self._pending["measurements"])

    def record(self, measurement: str):
        """The raw record stored with a measurement (``keep_raw=True``).

        Parameters
        ----------
        measurement : str
            The measurement's id.

        Returns
        -------
        Record

        Raises
        ------
        ParameterError
            For an unknown measurement or one stored without its record.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "plant.h5"
        >>> with vm.Store(path, writable=True) as st:
        ...     _ = st.add_asset("pump-1", bearing="6205-2RS", iso_group=2)
        ...     _ = st.add_point("pump-1", "DE", channel="acc", unit="g")
        ...     rec = vm.synth.machine(rpm=1797, duration=1.0, seed=1)
        ...     mid = st.add_measurement("pump-1", "DE", time="2026-11-22T08:00", rpm=1797, record=rec, keep_raw=True)
        ...     st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none"})
        >>> st = vm.Store(path)
        >>> st.record("m0000001").fs
        12000.0
        """
        from ..core.record import Channel, Record
        if measurement in self._raw_pending:
            return self._raw_pending[measurement]
        if not self._known(measurement):
            raise ParameterError(f"measurement={measurement!r} is not in store {str(self.path)!r}")
        with self._open() as f:
            if f"raw/{measurement}" not in f:
                raise ParameterError(f"measurement {measurement!r} was stored without its raw record")
            d = f[f"raw/{measurement}"]
            chans = json.loads(d.attrs["channels"])
            return Record(d[()], float(d.attrs["fs"]), [Channel(**c) for c in chans], t0=float(d.attrs["t0"]))

    # --- writing ------------------------------------------------------------------------------
    def _need_writable(self):
        if not self.writable or self._lock_fd is None:
            raise ParameterError(f"store {str(self.path)!r} is open for reading: open it with writable=True to add")

    def add_asset(self, asset: str, *, kind: str = "machine", bearing=None, gear=None, model=None,
                  iso_group: int | None = None, foundation: str | None = None, meta: dict | None = None) -> str:
        """An asset (a machine or a structure) with what its analysis needs.

        Adding an asset that exists with the same description does nothing; a different one is an error.

        Parameters
        ----------
        asset : str
            The asset's name.
        kind : {"machine", "structure"}
            What it is.
        bearing : str or Bearing, optional
            A catalogue name or "N,d,D,angle".
        gear : int, optional
            Gear teeth.
        model : str, optional
            A TOML model's path.
        iso_group : {1, 2}, optional
            ISO 10816-3 group.
        foundation : {"rigid", "flexible"}, optional
            ISO 10816-3 support class.
        meta : dict, optional
            Anything else.

        Returns
        -------
        str
            The asset's name.

        Raises
        ------
        ParameterError
            For a bad name, a store opened read-only, or an asset described differently before.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "plant.h5"
        >>> with vm.Store(path, writable=True) as st:
        ...     _ = st.add_asset("pump-1", bearing="6205-2RS", iso_group=2)
        ...     _ = st.add_point("pump-1", "DE", channel="acc", unit="g")
        ...     rec = vm.synth.machine(rpm=1797, duration=1.0, seed=1)
        ...     mid = st.add_measurement("pump-1", "DE", time="2026-11-22T08:00", rpm=1797, record=rec, keep_raw=True)
        ...     st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none"})
        >>> st = vm.Store(path)
        >>> st.assets()["bearing"].tolist()
        ['6205-2RS']
        """
        self._need_writable()
        _check_name(asset, "asset")
        if iso_group is not None and iso_group not in (1, 2):
            raise ParameterError(f"iso_group={iso_group!r} must be 1 or 2 (ISO 10816-3)")
        row = {"asset": asset, "kind": str(kind), "bearing": None if bearing is None else str(bearing),
               "gear": gear, "model": None if model is None else str(model), "iso_group": iso_group,
               "foundation": foundation, "meta": meta or {}}
        json.dumps(row)  # must be JSON
        old = self._assets.get(asset)
        if old is not None:
            if old != row:
                raise ParameterError(f"asset={asset!r} exists in the store with a different description")
            return asset
        self._pending["assets"].append(row)
        self._assets[asset] = row
        return asset

    def add_point(self, asset: str, point: str, *, channel: str | None = None, direction: str | None = None,
                  unit: str | None = None) -> str:
        """A measurement point of an asset.

        Parameters
        ----------
        asset : str
            The asset (added before).
        point : str
            The point's name.
        channel : str, optional
            The channel it is recorded on.
        direction : str, optional
            Measuring direction.
        unit : str, optional
            Sensor unit.

        Returns
        -------
        str
            The point's name.

        Raises
        ------
        ParameterError
            For an unknown asset or a store opened read-only.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "plant.h5"
        >>> with vm.Store(path, writable=True) as st:
        ...     _ = st.add_asset("pump-1", bearing="6205-2RS", iso_group=2)
        ...     _ = st.add_point("pump-1", "DE", channel="acc", unit="g")
        ...     rec = vm.synth.machine(rpm=1797, duration=1.0, seed=1)
        ...     mid = st.add_measurement("pump-1", "DE", time="2026-11-22T08:00", rpm=1797, record=rec, keep_raw=True)
        ...     st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none"})
        >>> st = vm.Store(path)
        >>> st.points()["point"].tolist()
        ['DE']
        """
        self._need_writable()
        _check_name(point, "point")
        if asset not in self._assets:
            raise ParameterError(f"asset={asset!r} is not in the store: add_asset first")
        row = {"asset": asset, "point": point, "channel": channel, "direction": direction, "unit": unit}
        old = self._points.get((asset, point))
        if old is not None:
            if old != row:
                raise ParameterError(f"point {asset}/{point} exists in the store with a different description")
            return point
        self._pending["points"].append(row)
        self._points[(asset, point)] = row
        return point

    def add_measurement(self, asset: str, point: str, *, time, rpm: float | None = None, record=None,
                        keep_raw: bool = False, sha256: str | None = None, file: str | None = None,
                        meta: dict | None = None) -> str:
        """A measurement of a point at a time.

        Parameters
        ----------
        asset, point : str
            Where it was measured.
        time : float, str or datetime
            Unix seconds, ISO 8601 or a datetime.
        rpm : float, optional
            Shaft speed.
        record : Record, optional
            The record (its samples' hash identifies the content).
        keep_raw : bool
            Store the raw samples too.
        sha256 : str, optional
            Content hash (default: of the record's samples); lets a batch skip inputs it has analysed.
        file : str, optional
            The source file.
        meta : dict, optional
            Anything else.

        Returns
        -------
        str
            The measurement's id.

        Raises
        ------
        ParameterError
            For an unknown asset or point, a bad time, or a store opened read-only.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "plant.h5"
        >>> with vm.Store(path, writable=True) as st:
        ...     _ = st.add_asset("pump-1", bearing="6205-2RS", iso_group=2)
        ...     _ = st.add_point("pump-1", "DE", channel="acc", unit="g")
        ...     rec = vm.synth.machine(rpm=1797, duration=1.0, seed=1)
        ...     mid = st.add_measurement("pump-1", "DE", time="2026-11-22T08:00", rpm=1797, record=rec, keep_raw=True)
        ...     st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none"})
        >>> st = vm.Store(path)
        >>> st.measurements()["id"].tolist()
        ['m0000001']
        """
        self._need_writable()
        if (asset, point) not in self._points:
            raise ParameterError(f"point {asset}/{point} is not in the store: add_point first")
        t = _seconds(time)
        if rpm is not None and not (np.isfinite(rpm) and rpm > 0):
            raise ParameterError(f"rpm={rpm!r} must be > 0")
        if sha256 is None and record is not None:
            import hashlib
            sha256 = hashlib.sha256(np.ascontiguousarray(record.data).tobytes()).hexdigest()
        mid = f"m{self.n_measurements + 1:07d}"
        row = {"id": mid, "asset": asset, "point": point, "time": t, "rpm": None if rpm is None else float(rpm),
               "sha256": sha256, "file": file, "raw": bool(keep_raw and record is not None), "meta": meta or {}}
        self._pending["measurements"].append(row)
        self._pending_meas[mid] = row
        if keep_raw and record is not None:
            self._raw_pending[mid] = record
        return mid

    def add_result(self, measurement: str, task: str, result: dict, *, params: dict | None = None,
                   summary: dict | None = None) -> None:
        """A result of a task for a measurement; the vibmeasure version is recorded.

        Parameters
        ----------
        measurement : str
            The measurement's id.
        task : str
            The task ("diagnose", "ringdown", ...).
        result : dict
            The full result, JSON-able (e.g. ``est.to_dict()``).
        params : dict, optional
            The parameters that produced it.
        summary : dict, optional
            Flat numbers and short strings that become columns of ``results``.

        Returns
        -------
        None

        Raises
        ------
        ParameterError
            For an unknown measurement, a result that is not JSON-able, or a store opened read-only.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "plant.h5"
        >>> with vm.Store(path, writable=True) as st:
        ...     _ = st.add_asset("pump-1", bearing="6205-2RS", iso_group=2)
        ...     _ = st.add_point("pump-1", "DE", channel="acc", unit="g")
        ...     rec = vm.synth.machine(rpm=1797, duration=1.0, seed=1)
        ...     mid = st.add_measurement("pump-1", "DE", time="2026-11-22T08:00", rpm=1797, record=rec, keep_raw=True)
        ...     st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none"})
        >>> st = vm.Store(path)
        >>> st.results("diagnose")["measurement"].tolist()
        ['m0000001']
        """
        self._need_writable()
        from .. import __version__
        from ..core.results import jsonable
        if not self._known(measurement):
            raise ParameterError(f"measurement={measurement!r} is not in the store")
        row = jsonable({"measurement": measurement, "task": _check_name(task, "task"), "version": __version__,
                         "params": params or {}, "summary": summary or {}, "result": result})
        json.dumps(row, allow_nan=True)
        self._pending["results"].append(row)

    @property
    def pending(self) -> int:
        """Rows added since the last commit."""
        return sum(len(v) for v in self._pending.values())

    def commit(self) -> None:
        """Make the pending rows durable: copy, append, seal, fsync, rename.

        Returns
        -------
        None

        Raises
        ------
        ParameterError
            For a store opened read-only, or a write that fails (the last commit stays intact).

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "plant.h5"
        >>> with vm.Store(path, writable=True) as st:
        ...     _ = st.add_asset("pump-1", bearing="6205-2RS", iso_group=2)
        ...     _ = st.add_point("pump-1", "DE", channel="acc", unit="g")
        ...     rec = vm.synth.machine(rpm=1797, duration=1.0, seed=1)
        ...     mid = st.add_measurement("pump-1", "DE", time="2026-11-22T08:00", rpm=1797, record=rec, keep_raw=True)
        ...     st.add_result(mid, "diagnose", {"top": "none"}, summary={"top": "none"})
        >>> st = vm.Store(path)
        >>> with vm.Store(path, writable=True) as w:
        ...     _ = w.add_point("pump-1", "NDE")
        ...     w.commit()
        >>> sorted(vm.Store(path).points()["point"])
        ['DE', 'NDE']
        """
        self._need_writable()
        if not self.pending and self.path.exists():
            return
        import h5py
        from .. import __version__
        from ._common import atomic_path
        from .hdf5 import USERBLOCK, seal
        with atomic_path(self.path) as tmp:
            if self.path.exists():
                shutil.copyfile(self.path, tmp)
                f = h5py.File(tmp, "r+")
            else:
                f = h5py.File(tmp, "w", userblock_size=USERBLOCK)
                f.attrs["vibmeasure_schema"] = STORE_SCHEMA
                f.attrs["schema_version"] = STORE_VERSION
                f.attrs["created"] = _time.time()
                str_t = h5py.string_dtype()
                for k in TABLES:
                    f.create_dataset(k, shape=(0,), maxshape=(None,), dtype=str_t, chunks=(256,))
                f.create_group("raw")
            with f:
                f.attrs["written_by"] = f"vibmeasure {__version__}"
                for k in TABLES:
                    new = self._pending[k]
                    if not new:
                        continue
                    d = f[k]
                    n0 = d.shape[0]
                    d.resize((n0 + len(new),))
                    d[n0:] = [json.dumps(r, allow_nan=True) for r in new]
                for mid, rec in self._raw_pending.items():
                    d = f["raw"].create_dataset(mid, data=np.asarray(rec.data), compression="gzip", compression_opts=1)
                    d.attrs["fs"] = rec.fs
                    d.attrs["t0"] = rec.t0
                    d.attrs["channels"] = json.dumps([{"name": c.name, "quantity": c.quantity, "unit": c.unit,
                                                       "location": c.location} for c in rec.channels])
            seal(tmp)
        n0 = self._n["measurements"]
        new = [(_hash_key(r["sha256"]), n0 + i) for i, r in enumerate(self._pending["measurements"]) if r.get("sha256")]
        if new:  # committed rows leave memory; their hashes join the sorted index (a merge, O(n))
            k_new = np.array([k for k, _ in new], np.uint64)
            r_new = np.array([r for _, r in new], np.int64)
            o = np.argsort(k_new, kind="stable")
            at = np.searchsorted(self._hash_keys, k_new[o], side="right")  # after equal keys: latest last
            self._hash_keys = np.insert(self._hash_keys, at, k_new[o])
            self._hash_rows = np.insert(self._hash_rows, at, r_new[o])
        for k in TABLES:
            self._n[k] += len(self._pending[k])
            self._pending[k] = []
        self._pending_meas = {}
        self._raw_pending = {}

    def __repr__(self) -> str:
        n = {k: self._n[k] + len(self._pending[k]) for k in TABLES}
        return (f"Store({str(self.path)!r}: {n['assets']} assets, {n['points']} points, {n['measurements']} "
                f"measurements, {n['results']} results{'; writable' if self.writable else ''})")
