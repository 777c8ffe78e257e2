"""Reading a store: its tables as DataFrames, a stored record, a content hash's measurement."""

from __future__ import annotations

import json

import numpy as np

from ..core.errors import ParameterError
from ..core._validate import check_flag
from ._store_common import ALARM_COLUMNS, COLUMNS, TASK_ALIASES, _hash_key, _seconds, check_row


class _Queries:
    """Methods of :class:`Store` (reading a store: its tables as dataframes, a stored record, a content hash's measurement); Store inherits them."""

    def _rows_of(self, f, table, chunk: int = 4096):
        """The committed rows of a table as dicts, read in chunks (only the rows this Store has seen
        committed: a later commit by another writer only appends)."""
        d = f[table].asstr()
        n = min(self._n[table], d.shape[0])
        src = f"store {str(self.path)!r}"
        for i0 in range(0, n, chunk):
            for v in d[i0:min(i0 + chunk, n)]:
                yield check_row(table, json.loads(v), src)

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
        df = pd.DataFrame(rows) if rows else pd.DataFrame(columns=list(COLUMNS[table]))
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

    def results(self, task: str, asset: str | None = None, point: str | None = None, since=None, until=None,
                *, with_result: bool = True):
        """Results of one task as a DataFrame, oldest first.

        Parameters
        ----------
        task : str
            The task.
        asset, point : str, optional
            Only these.
        since, until : float, str or datetime, optional
            Only this time range.
        with_result : bool
            False leaves out the ``result`` column: a trend needs the summary values only, and over a
            year of a busy store the full documents are most of the query's time.

        Returns
        -------
        pandas.DataFrame
            measurement, asset, point, time, task, version, params, the summary values as columns and
            ``result`` (the full result, a dict); one row per measurement, its latest result of the task
            (a re-analysis replaces the earlier one).

        Raises
        ------
        ParameterError
            For a bad time, or a ``with_result`` that is not True or False.

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
        check_flag(with_result, "with_result")
        task = TASK_ALIASES.get(task, task)
        meas = {r["id"]: (r["asset"], r["point"], r["time"]) for r in self._each("measurements")}
        flat, at, last_ok = [], [], {}
        for i, r in enumerate(self._each("results")):
            if r["task"] != task:
                last_ok[r["measurement"]] = i
                continue
            a, p, t = meas.get(r["measurement"], (None, None, None))
            if asset is not None and a != asset or point is not None and p != point:
                continue
            flat.append({"measurement": r["measurement"], "asset": a, "point": p, "time": t, "task": r["task"],
                         "version": r["version"], "params": r.get("params", {}), **r.get("summary", {}),
                         **({"result": r.get("result")} if with_result else {})})
            at.append(i)
        if task == "error":   # an error a later analysis of the same measurement succeeded past is gone
            flat = [row for row, i in zip(flat, at) if i > last_ok.get(row["measurement"], -1)]
        df = pd.DataFrame(flat)
        if df.empty:
            return pd.DataFrame(columns=["measurement", "asset", "point", "time", "task", "version", "params"])
        # a measurement analysed again: its latest result of the task replaces the earlier ones
        df = df.drop_duplicates("measurement", keep="last")
        for k, v in (("asset", asset), ("point", point)):
            if v is not None:
                df = df[df[k] == v]
        return self._timed(df.reset_index(drop=True), since, until)

    def _results_by_task(self, tasks, asset=None, point=None, since=None, until=None, *, with_result=True) -> dict:
        """{task: its ``results`` frame} for several tasks (the database store answers from one query)."""
        keys = dict.fromkeys(TASK_ALIASES.get(k, k) for k in tasks)
        return {k: self.results(k, asset, point, since, until, with_result=with_result) for k in keys}

    def alarms(self, asset: str | None = None, point: str | None = None):
        """The alarm history, which only a database store keeps (``vm.Store("plant.db")``): an HDF5 store
        returns it empty, with the database's columns; ``vm.trend`` gives its current verdicts.

        Parameters
        ----------
        asset, point : str, optional
            Only this asset or point (a database store filters by them).

        Returns
        -------
        pandas.DataFrame
            asset, point, task, metric, verdict, value, limit, reason, time, created (no rows).

        Raises
        ------
        ParameterError
            Never for an open store.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> import vibmeasure as vm
        >>> len(vm.Store(pathlib.Path(tempfile.mkdtemp()) / "plant.h5", writable=True).alarms())
        0
        """
        import pandas as pd
        return pd.DataFrame(columns=list(ALARM_COLUMNS))

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

    def _measurements_with(self, tasks, ids=None) -> dict:
        """task -> the ids of the measurements (of ``ids``, or all) with a result of it (one pass over the
        rows, no frame)."""
        out = {t: set() for t in tasks}
        keep = None if ids is None else set(ids)
        for r in self._each("results"):
            if r["task"] in out and (keep is None or r["measurement"] in keep):
                out[r["task"]].add(r["measurement"])
        return out

    def _with_contents(self, shas) -> list:
        """(measurement id, sha256, asset, point) of the stored measurements of these content hashes,
        oldest first."""
        want = set(shas)
        if not want:
            return []
        m = self.measurements()
        return [row for row in zip(m["id"], m["sha256"], m["asset"], m["point"]) if row[1] in want]

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
