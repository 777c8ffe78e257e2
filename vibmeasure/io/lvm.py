"""LabVIEW measurement text files (.lvm), with the LabVIEW header or as bare columns."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from ..core.errors import ParameterError, UnitError, warn_quality
from ..core import units as _units
from ..core.record import Record
from ..core._validate import select_names
from .csvfile import _incomplete
from ._common import DEFAULT_MAX_SAMPLES, check_size, make_record, parse_number, require_fs

_END = "***End_of_Header***"


def read_lvm(path, *, fs=None, channels=None, quantity=None, unit=None, max_samples=DEFAULT_MAX_SAMPLES) -> Record:
    src = f"LVM file {str(path)!r}"
    try:
        text = Path(path).read_text(encoding="latin-1")
    except OSError as exc:
        raise ParameterError(f"{src} is unreadable: {exc}") from None
    lines = text.splitlines()
    header, sep, dec, body_start, names = _lvm_header(lines, src)
    rows = [ln for ln in lines[body_start:] if ln.strip()]
    values = _lvm_values(rows, text, header, sep, dec, src, max_samples)
    file_fs, t0, file_unit = None, 0.0, ""
    if header:
        values, names, file_fs, t0, file_unit = _lvm_columns(values, header, names, src)
    else:
        names = [f"ch{i}" for i in range(values.shape[1])]
    if fs is not None:
        fs = require_fs(fs, source=src)
        if file_fs is not None and abs(fs - file_fs) > 1e-6 * file_fs:
            raise ParameterError(f"fs={fs:g} contradicts {src}, whose Delta_X gives {file_fs:g} Hz")
    fs = file_fs if file_fs is not None else require_fs(fs, source=src)
    pick = select_names(names, channels, source=src)
    return make_record(values[:, pick].T, fs, [names[i] for i in pick], quantity=quantity, unit=unit,
                       units=[file_unit] * len(pick), t0=t0, meta={"source": str(path)}, source=src)


def _lvm_header(lines: list, src: str):
    """(header key -> values, separator, decimal mark, first data line, column names or None) of a
    LabVIEW Measurement file; a file without the LabVIEW header is tab-separated numbers."""
    sep, dec = "\t", "."
    header: dict[str, list[str]] = {}
    body_start = 0
    names: list[str] | None = None
    if not (lines and lines[0].startswith("LabVIEW Measurement")):
        return header, sep, dec, body_start, names
    ends = [i for i, ln in enumerate(lines) if ln.strip().startswith(_END)]
    if len(ends) < 2:
        raise ParameterError(f"{src}: LabVIEW header is incomplete (truncated file?)")
    for ln in lines[:ends[1]]:
        parts = ln.rstrip("\r").split("\t")
        if parts and parts[0] and not parts[0].startswith("***"):
            header[parts[0].strip()] = [p.strip() for p in parts[1:] if p.strip() != ""]
    sep = {"Tab": "\t", "Comma": ",", "Semicolon": ";", "Space": " "}.get(
        (header.get("Separator") or ["Tab"])[0], "\t")
    dec = (header.get("Decimal_Separator") or ["."])[0]
    if len(ends) > 2:
        raise ParameterError(f"{src} has {len(ends) - 1} data segments; only single-segment files are read")
    body_start = ends[1] + 1
    while body_start < len(lines) and not lines[body_start].strip():
        body_start += 1
    if body_start < len(lines) and lines[body_start].startswith("X_Value"):
        names = [p.strip() for p in lines[body_start].split(sep)]
        body_start += 1
    return header, sep, dec, body_start, names


def _fixed_width(rows: list) -> bool:
    """Whether every column of these rows has one number of decimals (LabVIEW's fixed format), so that a
    last line cut inside a number shows."""
    import re
    fields = [re.findall(r"[^,;\t ]+", r) for r in rows]
    if len(fields) < 2 or len({len(f) for f in fields}) != 1:
        return False
    return all(len({len(f[k].split(".")[1]) if f[k].count(".") == 1 else None for f in fields} - {None}) == 1 and
               all(f[k].count(".") == 1 for f in fields) for k in range(len(fields[0])))


def _lvm_values(rows: list, text: str, header: dict, sep: str, dec: str, src: str, max_samples):
    """The data rows as numbers, checked: size before reading, a complete last line, the header's
    sample count, no missing value."""
    import pandas as pd
    if not rows:
        raise ParameterError(f"{src} has no data rows")
    check_size(len(rows) * (rows[0].count(sep) + 1), source=src, max_samples=max_samples)
    if not text.endswith(("\n", "\r")):
        # a last line without its end of line is data when it is complete (a hand edit, another writer);
        # one that cannot be complete was cut
        why = _incomplete(rows[-1], rows[-50:-1])
        if why:
            raise ParameterError(f"{src}: the last line {rows[-1][:60]!r} {why} and has no end of line: the file "
                                 "was cut")
        if not _fixed_width(rows[-50:-1]):
            warn_quality(f"{src}: the last line {rows[-1][:60]!r} has no end of line and its columns have no fixed "
                         "number of decimals, so a cut inside its last number cannot be told: kept, check it",
                         stacklevel=5)
    stated = [parse_number(v, source=src, key="header Samples") for v in header.get("Samples", [])]
    if stated and any(v != len(rows) for v in stated):
        raise ParameterError(f"{src}: the header states {int(max(stated))} samples per channel but the file holds "
                             f"{len(rows)} rows (truncated file?)")
    try:
        df = pd.read_csv(io.StringIO("\n".join(rows)), sep=sep, header=None, decimal=dec, engine="c")
    except Exception as exc:
        raise ParameterError(f"{src}: data are not readable as numbers: {exc}") from None
    df = df.dropna(axis=1, how="all")
    if any(df[c].dtype.kind not in "fiu" for c in df.columns):
        raise ParameterError(f"{src}: data hold non-numeric values")
    values = df.to_numpy(dtype=np.float64)
    nan_rows = np.flatnonzero(np.isnan(values).any(axis=1))
    if nan_rows.size:
        raise ParameterError(f"{src}: data row {nan_rows[0] + 1} has missing values"
                             f"{' (truncated file?)' if nan_rows[0] == len(values) - 1 else ''}")
    return values


def _lvm_columns(values, header: dict, names, src: str):
    """(values without the X columns, channel names, fs from Delta_X, t0 from X0, unit) of a file with
    the LabVIEW header; a spectrum export is refused (vm.read_spectrum reads it)."""
    file_fs, t0 = None, 0.0
    xcols = (header.get("X_Columns") or ["One"])[0]
    if names:
        names = [n for n in names if n and n != "Comment"]
    ychan = [n for n in (names or []) if n != "X_Value"]
    if any(("FFT" in n or "Spectrum" in n or "Power" in n) for n in ychan):
        raise ParameterError(f"{src} holds a spectrum ({ychan[0]!r}: its X column is frequency), not a "
                             "time record; vm.read reads time records")
    if "Delta_X" in header:
        steps = {parse_number(v, source=src, key="header Delta_X") for v in header["Delta_X"]}
        if len(steps) > 1:
            raise ParameterError(f"{src}: the header states different Delta_X per channel {sorted(steps)}")
        dx = steps.pop()
        if dx <= 0:
            raise ParameterError(f"{src}: Delta_X={dx} must be > 0")
        file_fs = 1.0 / dx
        t0 = parse_number((header.get("X0") or ["0"])[0], source=src, key="header X0")
    ulab = (header.get("Y_Unit_Label") or [""])[0]
    try:
        file_unit = _units.normalize_unit(ulab)
    except UnitError:
        file_unit = ""
    if xcols == "Multi":
        keep = list(range(1, values.shape[1], 2))
    elif xcols == "One":
        keep = list(range(1, values.shape[1]))
    else:
        keep = list(range(values.shape[1]))
    values = values[:, keep]
    if not ychan or len(ychan) != values.shape[1]:
        ychan = [f"ch{i}" for i in range(values.shape[1])]
    return values, ychan, file_fs, t0, file_unit


DB_LIMIT = 300.0   # dB re 1 unit: 1e15 or 1e-15 of the unit, beyond every measurement chain


def read_lvm_spectrum(path):
    """A LabVIEW FFT export: frequency in the X column, magnitude (dB re 1 unit when the channel says
    so, else linear); returns an amplitude Spectrum."""
    import re as _re
    from ..core.results import Spectrum
    src = f"LVM file {str(path)!r}"
    text = Path(path).read_text(encoding="latin-1")
    lines = text.splitlines()
    ends = [i for i, ln in enumerate(lines) if ln.strip().startswith(_END)]
    if len(ends) < 2:
        raise ParameterError(f"{src}: no LabVIEW header with a channel block: not a spectrum export")
    head = {}
    for ln in lines[:ends[1]]:
        parts = ln.split("\t")
        if parts and parts[0].strip():
            head[parts[0].strip()] = [p.strip() for p in parts[1:] if p.strip()]
    body = ends[1] + 1
    while body < len(lines) and not lines[body].strip():
        body += 1
    names = lines[body].split("\t") if lines[body].startswith("X_Value") else []
    rows = [ln.split("\t") for ln in lines[body + (1 if names else 0):] if ln.strip()]
    try:
        arr = np.array([[float(v) for v in r[:2]] for r in rows])
    except (ValueError, IndexError):
        raise ParameterError(f"{src}: spectrum rows are not numbers (truncated file?)") from None
    if arr.ndim != 2 or arr.shape[0] < 2:
        raise ParameterError(f"{src}: {arr.shape[0] if arr.ndim else 0} spectrum line(s); a spectrum needs at least 2")
    freq, val = arr[:, 0], arr[:, 1]
    label = names[1].strip() if len(names) > 1 else "ch0"
    # LabVIEW states X_Dimension "Time" on FFT exports too, so the values decide: a channel not named as a
    # spectrum whose values swing both ways is a waveform (a magnitude is >= 0; dB are named so)
    spectral = any(k.lower() in label.lower() for k in ("FFT", "Spectrum", "Power", "PSD", "dB", "Magnitude"))
    if not spectral and val.min() < 0 < val.max():
        raise ParameterError(f"{src}: channel {label!r} swings above and below 0 and is not named as a spectrum: "
                             "a time record, which vm.read reads")
    if not (np.all(np.isfinite(arr)) and np.all(np.diff(freq) > 0) and freq[0] >= 0):
        raise ParameterError(f"{src}: the spectrum must hold finite values at frequencies from >= 0 Hz, increasing")
    unit_lab = (head.get("Y_Unit_Label") or [""])[0]
    is_db = "dB" in label or (val < 0).any()
    if is_db and np.max(np.abs(val)) > DB_LIMIT:
        raise ParameterError(f"{src}: a level of {val[np.argmax(np.abs(val))]:g} dB is beyond any sensor "
                             f"(+-{DB_LIMIT:g} dB re 1 unit): not a spectrum in dB")
    amp = 10 ** (val / 20) if is_db else val
    try:
        unit = _units.normalize_unit(unit_lab)
    except UnitError:
        unit = ""
    scaling = "rms" if _re.search(r"RMS", label, _re.I) else "peak"
    q = _units.quantity_of(unit) if unit else "unknown"
    df = float(np.median(np.diff(freq)))
    return Spectrum(freq, amp, "amplitude", unit, (label,), q,
                    {"scaling": scaling, "source": str(path), "from_db": is_db, "fs": 2 * freq[-1] + df})
