"""Writing to a store: assets, points, measurements and results, pending until the next commit."""

from __future__ import annotations

import json

import numpy as np

from ..core.errors import ParameterError
from ._store_common import _asset_row, _check_name, _seconds


class _Writes:
    """Methods of :class:`Store` (writing to a store: assets, points, measurements and results, pending until the next commit); Store inherits them."""

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
        row = _asset_row(asset, kind, bearing, gear, model, iso_group, foundation, meta)
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
