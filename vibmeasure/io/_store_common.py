"""What the store's modules share: its schema names, the names' rule, time and hash helpers."""

from __future__ import annotations

import numpy as np

from ..core.errors import ParameterError, VibMeasureError

STORE_SCHEMA = "vibmeasure.store"
STORE_VERSION = 1
TABLES = ("assets", "points", "measurements", "results")
# what each stored row must hold: a row of another shape is a damaged (or crafted) store, refused by name
ROW_SHAPE = {
    "assets": {"asset": str},
    "points": {"asset": str, "point": str},
    "measurements": {"id": str, "asset": str, "point": str, "meta": dict},
    "results": {"measurement": str, "task": str, "summary": dict, "params": dict},
}

# the columns a table's frame has, also where it holds no row (a store whose first writer was killed
# before its first measurement committed: ``measurements()["id"]`` must be an empty column, not a KeyError)
COLUMNS = {
    "assets": ("asset", "kind", "bearing", "gear", "model", "iso_group", "foundation", "meta"),
    "points": ("asset", "point", "channel", "direction", "unit"),
    "measurements": ("id", "asset", "point", "time", "rpm", "sha256", "file", "raw", "meta"),
}


def check_row(table: str, row, src: str) -> dict:
    """``row`` if it has its table's keys with their types, else a ParameterError naming the first misfit."""
    if not isinstance(row, dict):
        raise ParameterError(f"{src} is damaged: a row of {table} is {type(row).__name__}, not a mapping")
    for key, kind in ROW_SHAPE[table].items():
        if not isinstance(row.get(key), kind):
            raise ParameterError(f"{src} is damaged: a row of {table} has {key}={str(row.get(key))[:40]!r}, "
                                 f"not a {kind.__name__}")
    return row


# the alarm history's columns (a database store's ``alarms`` table; an HDF5 store's is empty)
ALARM_COLUMNS = ("asset", "point", "task", "metric", "verdict", "value", "limit", "reason", "time", "created")
VERDICT_COLUMNS = ("asset", "point", "metric", "verdict")   # what ``record_verdicts`` needs of a trend frame
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


def _asset_row(asset, kind, bearing, gear, model, iso_group, foundation, meta) -> dict:
    """An asset's row as every store keeps it, its name and ISO group checked."""
    _check_name(asset, "asset")
    if iso_group is not None and iso_group not in (1, 2):
        raise ParameterError(f"iso_group={iso_group!r} must be 1 or 2 (ISO 10816-3)")
    return {"asset": asset, "kind": str(kind), "bearing": None if bearing is None else str(bearing),
            "gear": gear, "model": None if model is None else str(model), "iso_group": iso_group,
            "foundation": foundation, "meta": meta or {}}

