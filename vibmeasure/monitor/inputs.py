"""The inputs of a batch: files, folders and globs, and the rows of a manifest CSV, each checked by
its own rules (a bad row is that row's error, never the batch's)."""

from __future__ import annotations

import csv
import glob
import os
from pathlib import Path

from ..core._validate import regular_input
from ..core.errors import ParameterError

__all__ = ["read_manifest", "MANIFEST_COLUMNS"]

MANIFEST_COLUMNS = ("file", "asset", "point", "channel", "rpm", "bearing", "model", "time", "tach", "pulses_per_rev",
                    "unit", "fs", "gear")
MAX_MANIFEST_BYTES = 256 << 20   # a manifest lists files: 256 MiB is millions of rows, more is not one
READABLE = (".csv", ".txt", ".h5", ".hdf5", ".wav", ".mat", ".lvm", ".uff", ".unv")


def read_manifest(path) -> list[dict]:
    """Rows of a manifest CSV, each with its ``file`` glob expanded (relative to the manifest).

    Parameters
    ----------
    path : str or os.PathLike
        The manifest: columns file, asset, point, channel, rpm, bearing, model, time, tach,
        pulses_per_rev, unit, fs, gear (the teeth of a gear on the measured shaft, ``32``, or with
        its mating gear's, ``32/71``; any other column is an error).

    Returns
    -------
    list of dict
        One item per file; a row that breaks a rule (rpm or fs not a positive number, an unparsable time,
        a name too long or with a line break, a glob that matches nothing) is an item with "error"
        (its row and rule), which a batch reports and does not analyse.

    Raises
    ------
    ParameterError
        For a missing manifest, a file that is not UTF-8 CSV, or an unknown or missing column.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import vibmeasure as vm
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> items = vm.synth.fleet(folder, n_measurements=2)
    >>> len(vm.read_manifest(folder / "machines.csv")) > 0
    True
    """
    p = regular_input(path, "manifest", max_bytes=MAX_MANIFEST_BYTES)
    src = f"manifest {str(path)!r}"
    try:
        with open(p, newline="", encoding="utf-8-sig") as fh:
            reader = csv.DictReader(fh)
            cols = [c.strip() for c in (reader.fieldnames or [])]
            unknown = [c for c in cols if c not in MANIFEST_COLUMNS]
            if unknown:
                raise ParameterError(f"{src}: unknown column(s) {unknown}; the columns are {list(MANIFEST_COLUMNS)}")
            if "file" not in cols:
                raise ParameterError(f"{src} needs a 'file' column")
            raws = list(enumerate(reader, start=2))
    except UnicodeDecodeError as exc:
        raise ParameterError(f"{src} is not UTF-8 text (byte {exc.start}): save it as UTF-8 CSV") from None
    except csv.Error as exc:
        raise ParameterError(f"{src} is not a readable CSV: {exc}") from None
    rows = []
    for i, raw in raws:
        try:
            rows += _manifest_row(raw, p)
        except ParameterError as exc:   # one bad row is that row's error; the others are analysed
            label = str((raw.get("file") or "").strip()[:200]) or f"{p.name} row {i}"
            rows.append({"file": label, "error": f"{src} row {i} (the header is row 1): {exc}"})
    return rows


MAX_NAME = 200   # an asset or point name longer than this is a pasted text, not a name


def _manifest_row(raw: dict, p: Path) -> list[dict]:
    """One manifest row checked by its own rules, as one item per file it names."""
    import math
    row = {k.strip(): (v.strip() if isinstance(v, str) else v) for k, v in raw.items() if k}
    if None in raw:
        raise ParameterError(f"more fields than columns ({len(raw[None])} extra)")
    if not row.get("file"):
        raise ParameterError("empty 'file'")
    for key in ("asset", "point", "channel"):
        v = row.get(key) or ""
        if len(v) > MAX_NAME or any(ord(c) < 32 for c in v):
            raise ParameterError(f"{key}={v[:40]!r}{'...' if len(v) > 40 else ''} must be a name of at most "
                                 f"{MAX_NAME} characters without line breaks or control characters")
    for key in ("rpm", "fs"):
        if row.get(key):
            try:
                row[key] = float(row[key])
            except ValueError:
                raise ParameterError(f"{key}={row[key]!r} is not a number") from None
            if not (math.isfinite(row[key]) and row[key] > 0):
                raise ParameterError(f"{key}={row[key]!r} must be a finite number > 0")
    if row.get("pulses_per_rev"):
        try:
            row["pulses_per_rev"] = int(row["pulses_per_rev"])
        except ValueError:
            raise ParameterError(f"pulses_per_rev={row['pulses_per_rev']!r} is not a whole number") from None
        if row["pulses_per_rev"] < 1:
            raise ParameterError(f"pulses_per_rev={row['pulses_per_rev']} must be >= 1")
    if row.get("gear"):
        row["gear"] = _gear_spec(row["gear"])
    if row.get("time"):
        import pandas as pd
        try:
            t = pd.Timestamp(row["time"])
        except (ValueError, TypeError, OverflowError):
            t = None
        if t is None or t is pd.NaT:
            raise ParameterError(f"time={row['time'][:40]!r} is not a date and time (ISO 8601, e.g. "
                                 "2026-11-28T08:00)")
    if row.get("model") and not os.path.isabs(row["model"]):
        row["model"] = str(p.parent / row["model"])
    pattern = row["file"] if os.path.isabs(row["file"]) else str(p.parent / row["file"])
    hits = sorted(glob.glob(pattern)) if any(c in pattern for c in "*?[") else [pattern]
    if not hits:
        raise ParameterError(f"no file matches {row['file']!r}")
    return [{k: (v if v != "" else None) for k, v in dict(row, file=h).items()} for h in hits]


def _expand(inputs) -> list[dict]:
    if isinstance(inputs, (str, os.PathLike)):
        inputs = [inputs]
    items = []
    for x in inputs:
        s = str(x)
        if any(c in s for c in "*?["):
            hits = sorted(glob.glob(s, recursive=True))
            if not hits:
                raise ParameterError(f"input {s!r} matches no file")
        elif os.path.isdir(s):
            hits = sorted(str(q) for q in Path(s).rglob("*") if _data_name(q) and q.is_file())
        elif os.path.isfile(s):
            items.append({"file": s})   # a file named by the user is read whatever its name
            continue
        else:
            raise ParameterError(f"input {s!r} is not a file, folder or glob")
        items += [{"file": h} for h in hits if _data_name(Path(h))]
    return items


def _data_name(p: Path) -> bool:
    """Whether a file found in a folder or by a glob is a record to read: a readable suffix, or none
    at all, or a numeric one (rigs that name files by their time stamp, "2004.02.12.10.32.39");
    never a hidden file (a store's lock, a writer's temporary file)."""
    suffix = p.suffix.lower()
    return not p.name.startswith(".") and (suffix in READABLE or suffix == "" or suffix[1:].isdigit())


def _is_manifest(path) -> bool:
    """Whether a CSV file is a manifest (its header: a ``file`` column and manifest columns only), not
    a record: a folder of records often holds its manifest too."""
    if Path(path).suffix.lower() != ".csv":
        return False
    try:
        with open(path, newline="", encoding="utf-8-sig") as fh:
            head = next(csv.reader(fh), [])
    except (OSError, UnicodeDecodeError, csv.Error):
        return False
    cols = [c.strip() for c in head]
    return "file" in cols and all(c in MANIFEST_COLUMNS for c in cols)


def _unique(inputs: list, rows: list, manifest=None) -> tuple[list, list]:
    """(items, notes): each file once; a file a manifest row names takes that row's metadata (the
    plain input is dropped), a manifest is no record; a row listed twice is analysed once. Notes:
    (file, message) per drop."""
    named = {os.path.realpath(r["file"]) for r in rows}
    if manifest is not None:
        named.add(os.path.realpath(manifest))
    items, notes, seen = [], [], set()
    for it in inputs:
        if os.path.realpath(it["file"]) not in named and _is_manifest(it["file"]):
            notes.append((it["file"], "a manifest, not a record: give it as manifest= (--manifest)"))
            named.add(os.path.realpath(it["file"]))
    for it in [i for i in inputs if os.path.realpath(i["file"]) not in named] + rows:
        key = (os.path.realpath(it["file"]), tuple(sorted((k, str(v)) for k, v in it.items() if k != "file")))
        if key in seen:
            notes.append((it["file"], "listed twice: analysed once"))
            continue
        seen.add(key)
        items.append(it)
    return items, notes


def _gear_spec(text: str):
    """A manifest's gear: its teeth (``32``: an int) or its teeth and its mating gear's (``32/71``: kept as
    that text); each at least 5."""
    parts = str(text).strip().split("/")
    try:
        teeth = [int(p) for p in parts]
    except ValueError:
        teeth = []
    if len(teeth) not in (1, 2) or min(teeth) < 5:
        raise ParameterError(f"gear={text!r} must be the gear's teeth (>= 5), or its teeth and its mating gear's "
                             "as '32/71'")
    return teeth[0] if len(teeth) == 1 else f"{teeth[0]}/{teeth[1]}"
