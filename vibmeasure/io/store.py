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

from ..core._validate import regular_input
from ..core.errors import ParameterError
from ._store_common import STORE_SCHEMA, STORE_VERSION, TABLES, StoreLockedError, _hash_key
from .store_query import _Queries
from .store_write import _Writes

__all__ = ["Store", "StoreLockedError", "STORE_SCHEMA", "STORE_VERSION", "is_store"]


def is_store(obj) -> bool:
    """Whether ``obj`` is an open store (HDF5 or database) rather than a path or URL to open."""
    from .sql.store import SQLStore
    return isinstance(obj, (Store, SQLStore))

class Store(_Queries, _Writes):
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
    raw_dir : str or os.PathLike, optional
        For a database target only (.db, .sqlite, .sqlite3 or a URL such as
        ``postgresql://user@host/db``, which opens an :class:`~vibmeasure.io.sql.SQLStore` with the
        same methods): where its raw records are kept.

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

    def __new__(cls, path=None, *, writable: bool = False, timeout: float = 0.0, raw_dir=None):
        # a database target (.db/.sqlite/.sqlite3 or a URL) is the same store on SQLite or PostgreSQL
        from .sql.schema import is_sql_target
        from .sql.store import SQLStore
        if cls is Store and path is not None and is_sql_target(path):
            return SQLStore(path, writable=writable, timeout=timeout, raw_dir=raw_dir)
        return super().__new__(cls)

    def __init__(self, path, *, writable: bool = False, timeout: float = 0.0, raw_dir=None):
        if raw_dir is not None:
            raise ParameterError("raw_dir= is for a database store (.db or a URL): an HDF5 store keeps its raw "
                                 "records inside its file")
        # a symlink is followed first: the lock and every commit act on the real file, so two writers
        # reaching it by different names still exclude each other and the link stays a link
        self.path = Path(os.path.realpath(path))
        if self.path.exists():
            regular_input(self.path, "store")
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
        from .hdf5 import check_seal, refuse_foreign
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
                refuse_foreign(f, src)
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
        from ._common import atomic_path, write_errors_not_signals
        from .hdf5 import USERBLOCK, seal
        self._room_for_commit()
        try:
            with write_errors_not_signals():
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
                        self._append(f, __version__)
                    seal(tmp)
        except (OSError, RuntimeError) as exc:   # a write failed: the temporary copy is gone, the store intact
            raise ParameterError(f"store {str(self.path)!r}: the commit could not be written ({exc}); the store "
                                 "keeps its last commit and these rows are still pending: free space and commit "
                                 "again") from None
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

    def _room_for_commit(self) -> None:
        """A commit writes a copy of the store plus the pending rows and raw records: refused before a byte
        is written when the disk or the process's file-size limit cannot take it (HDF5 left mid-write by a
        full disk can crash the process)."""
        import resource
        old = self.path.stat().st_size if self.path.exists() else 0
        rows = sum(len(json.dumps(r, allow_nan=True)) for k in TABLES for r in self._pending[k])
        raw = sum(np.asarray(rec.data).nbytes for rec in self._raw_pending.values())
        need = old + rows + raw + (1 << 20)          # 1 MiB for HDF5's own structures
        free = shutil.disk_usage(self.path.parent).free
        limit = resource.getrlimit(resource.RLIMIT_FSIZE)[0]
        room = min(free, limit if limit != resource.RLIM_INFINITY else free)
        if need > room:
            what = "free space on its disk" if room == free else "the process's file-size limit (ulimit -f)"
            raise ParameterError(f"store {str(self.path)!r}: a commit needs up to {need:,} bytes (a copy of the store "
                                 f"and {rows + raw:,} new) and {what} is {room:,}; nothing was written, the "
                                 "rows are still pending: free space and commit again")

    def _append(self, f, version: str) -> None:
        """The pending rows and raw records into an open copy of the store."""
        f.attrs["written_by"] = f"vibmeasure {version}"
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

    def __repr__(self) -> str:
        n = {k: self._n[k] + len(self._pending[k]) for k in TABLES}
        return (f"Store({str(self.path)!r}: {n['assets']} assets, {n['points']} points, {n['measurements']} "
                f"measurements, {n['results']} results{'; writable' if self.writable else ''})")
