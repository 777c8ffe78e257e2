"""What the store's modules share: its schema names, the names' rule, time and hash helpers."""

from __future__ import annotations

import numpy as np

from ..core.errors import ParameterError, VibMeasureError

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
