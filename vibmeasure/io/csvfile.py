"""CSV text: a time column or a sampling-rate header; comma, semicolon or tab; decimal comma."""

from __future__ import annotations

import io
import re
from pathlib import Path

import numpy as np

from ..core.errors import ParameterError
from ..core.record import Record
from ..core._validate import select_names
from ._common import (DEFAULT_MAX_SAMPLES, MAX_CHANNELS, atomic_path, check_size, fs_from_time, make_record,
                      parse_number, require_fs, TIME_STEP_RTOL)

_FS_KEYS = ("fs", "fs_hz", "sampling_rate", "sample_rate", "samplerate", "sampling_frequency")
_NAME_UNIT = re.compile(r"^\s*(.*?)\s*[\[(]\s*([^\])]*)\s*[\])]\s*$")


def _split_name_unit(label: str) -> tuple[str, str | None]:
    m = _NAME_UNIT.match(label)
    return (m.group(1), m.group(2)) if m else (label.strip(), None)


WHITESPACE = r"\s+"   # runs of spaces (or tabs mixed with spaces): the loggers' and OMA datasets' .asc/.txt
DELIMITERS = {",": ",", ";": ";", "\t": "\t", "tab": "\t", " ": WHITESPACE, "space": WHITESPACE,
              "whitespace": WHITESPACE}


def _sniff(lines: list[str], delimiter=None) -> tuple[str, str]:
    """Delimiter and decimal mark from the first data lines (or the caller's ``delimiter``): a tab, a
    semicolon or a comma where the lines hold one, else runs of whitespace between fields."""
    sample = "\n".join(lines[:20])
    if delimiter is not None:
        sep = DELIMITERS[delimiter]
    elif "\t" in sample:
        sep = "\t"
    elif ";" in sample:
        sep = ";"
    elif "," in sample and not re.search(r"\d,\d+[ \t]+[-+]?\d", sample):   # not a decimal comma between spaces
        sep = ","
    elif any(re.search(r"\S[ \t]+\S", ln.strip()) for ln in lines[:20]):
        sep = WHITESPACE
    else:
        sep = ","
    decimal = "."
    if sep != ",":
        if re.search(r"\d,\d", sample) and not re.search(r"\d\.\d", sample):
            decimal = ","
    return sep, decimal


def _fields(line: str, sep: str) -> list:
    return line.split() if sep == WHITESPACE else line.split(sep)


def _cut_last_line(text: str, src: str) -> str:
    """A last line without an end of line (hand edits, some exporters) is data when it is complete: as
    many fields as the row before it, and no number shorter than its column's fixed width (every earlier
    row giving that column the same number of decimals). A line that cannot be complete (fewer fields, a
    number cut short) is dropped with a QualityWarning naming it."""
    if not text or text.endswith(("\n", "\r")):
        return text
    head, _, last = text.rpartition("\n")
    if not last.strip() or last.lstrip().startswith("#"):
        return text
    rows = [ln for ln in head.splitlines()[-50:] if ln.strip() and not ln.lstrip().startswith("#")]
    why = _incomplete(last, rows)
    if why is None:
        return text + "\n"
    import warnings
    from ..core.errors import QualityWarning
    warnings.warn(f"{src}: the last line {last[:60]!r} has no end of line and {why} (a cut file?); it was left out",
                  QualityWarning, stacklevel=4)
    return head + "\n"


_FIELD = re.compile(r"[^,;\t ]+")


def _number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _incomplete(last: str, rows: list) -> str | None:
    """Why ``last`` cannot be a complete row after ``rows`` (the lines before it), or None."""
    if not rows:
        return None
    fields = _FIELD.findall(last)
    before = [_FIELD.findall(r) for r in rows]
    if len(fields) != len(before[-1]):
        return f"has {len(fields)} field(s) where the row before has {len(before[-1])}"
    same = [b for b in before if len(b) == len(fields) and all(_number(x) for x in b)]
    for k, f in enumerate(fields):
        widths = {len(b[k].split(".")[1]) if b[k].count(".") == 1 else None for b in same}
        if len(widths) == 1 and None not in widths and len(same) >= 2:
            w = widths.pop()
            got = len(f.split(".")[1]) if f.count(".") == 1 else 0
            if got < w and "e" not in f.lower():
                return f"its field {k + 1} ({f!r}) has {got} decimal(s) where every row before has {w}"
    return None


def _check_digest(text: str, src: str) -> None:
    """A CSV vibmeasure wrote states the SHA-256 of its data rows: a changed digit is a named error."""
    m = re.search(r"^#\s*sha256\s*=\s*([0-9a-f]{64})\s*$", text[:1 << 16], re.M)
    if not m:
        return
    import hashlib
    pos = 0
    while pos < len(text) and text.startswith("#", pos):
        nl = text.find("\n", pos)
        pos = len(text) if nl < 0 else nl + 1
    if hashlib.sha256(text[pos:].encode("utf-8")).hexdigest() != m.group(1):
        raise ParameterError(f"{src} is damaged: its rows do not match the SHA-256 stated in its header (a changed, "
                             "cut or edited file)")


def read_csv(path, *, fs=None, channels=None, quantity=None, unit=None, max_samples=DEFAULT_MAX_SAMPLES,
             delimiter=None) -> Record:
    src = f"CSV file {str(path)!r}"
    try:
        text = Path(path).read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise ParameterError(f"{src} is not UTF-8 text: unreadable as CSV") from None
    _check_digest(text, src)
    header_kv, chan_meta, body = _header_and_body(_cut_last_line(text, src).splitlines(), src)
    values, labels, has_header = _table(body, src, max_samples, delimiter)
    _check_rows(values, has_header, header_kv, src)
    split = [_split_name_unit(lab) for lab in labels]
    names, units = [nm for nm, _ in split], [un for _, un in split]
    tcol, t_unit = _time_column(names)
    unnamed_time = tcol is None and not has_header and _is_time_base(values)
    if unnamed_time:   # a headerless first column that increases in uniform steps is the time base
        tcol = 0
    if tcol is not None and t_unit and not units[tcol]:
        units[tcol] = t_unit      # time_ms, t_us: the unit in the name
    fs, t0 = _timing(values, units, tcol, header_kv, fs, src)
    data_cols = [i for i in range(len(names)) if i != tcol]
    if not data_cols:
        raise ParameterError(f"{src} has a time column but no data column")
    locations = _exact_channels(header_kv, names, data_cols, chan_meta, src)
    avail = [names[i] for i in data_cols]
    pick = [data_cols[j] for j in select_names(avail, channels, source=src)]
    quantities = [chan_meta.get(names[i], ("unknown", ""))[0] for i in pick]
    file_units = [chan_meta.get(names[i], (None, units[i] or ""))[1] for i in pick]
    meta = {k: v for k, v in header_kv.items() if k not in _FS_KEYS and k not in ("t0_s", "n_samples", "channels_json")}
    meta["source"] = str(path)
    if unnamed_time:
        meta["time_column"] = "column 1 (no header; read as time in s: it increases in uniform steps)"
    rec = make_record(values[:, pick].T, fs, [names[i] for i in pick], quantity=quantity, unit=unit,
                      quantities=quantities, units=file_units, t0=t0, meta=meta, source=src)
    if any(locations.values()):
        from ..core.record import Channel
        rec = rec.replace(channels=tuple(Channel(c.name, c.quantity, c.unit, locations.get(c.name, ""))
                                         for c in rec.channels))
    return rec


def _is_time_base(values) -> bool:
    """A first column (of two or more) that rises in uniform steps (``fs_from_time``'s tolerance) is a
    time base: no vibration signal increases monotonically at a constant rate for a whole record."""
    if values.ndim != 2 or values.shape[1] < 2 or values.shape[0] < 16:
        return False
    d = np.diff(values[:, 0])
    step = float(np.median(d))
    return bool(step > 0 and np.all(d > 0) and np.max(np.abs(d - step)) <= TIME_STEP_RTOL * step)


_TIME_NAME = re.compile(r"^(time|t|zeit|seconds|timestamp)(?:[_ ]?(s|sec|ms|us))?$", re.I)


def _time_column(names: list) -> tuple:
    """(index, unit from the name) of the time column, e.g. "time", "t", "time_s", "time_ms"; else (None, None)."""
    for i, n in enumerate(names):
        m = _TIME_NAME.match(n.strip())
        if m:
            return i, {"sec": "s"}.get((m.group(2) or "").lower(), (m.group(2) or "").lower())
    return None, None


def _header_and_body(lines: list, src: str) -> tuple[dict, dict, list]:
    """The '# key = value' header (``# channel = name; quantity; unit`` lines apart) and the data rows."""
    header_kv: dict[str, str] = {}
    chan_meta: dict[str, tuple[str, str]] = {}
    body = []
    for ln in lines:
        s = ln.strip()
        if s.startswith("#"):
            m = re.match(r"#\s*([\w .]+?)\s*[=:]\s*(.*)$", s)
            if m:
                key, val = m.group(1).strip().lower(), m.group(2).strip()
                if key == "channel":
                    parts = [p.strip() for p in val.split(";")]
                    if len(parts) >= 3:
                        chan_meta[parts[0]] = (parts[1], parts[2])
                elif key != "sha256":
                    header_kv[key] = val
            continue
        if s:
            body.append(ln)
    if not body:
        raise ParameterError(f"{src} has no data rows")
    return header_kv, chan_meta, body


def _table(body: list, src: str, max_samples, delimiter=None) -> tuple:
    """(values (n_rows, n_columns), column labels, whether the first row is a header): separator and
    decimal mark sniffed, sizes checked before pandas reads anything."""
    import pandas as pd
    sep, decimal = _sniff(body[1:] if len(body) > 1 else body, delimiter)
    first = _fields(body[0], sep)
    if len(first) > MAX_CHANNELS:
        raise ParameterError(f"{src}: its first row has {len(first):,} fields, above the limit of {MAX_CHANNELS:,} "
                             "channels")
    check_size(len(first) * len(body), source=src, max_samples=max_samples)
    has_header = any(not _is_number(f, decimal) for f in first if f.strip())
    if sep == "," and decimal == "." and has_header and len(body) > 1:
        # a decimal comma with a comma separator cannot be told apart: reject clearly
        n_head = len(first)
        n_row = len(body[1].split(","))
        if n_row != n_head:
            raise ParameterError(f"{src}: header has {n_head} fields but row 2 has {n_row}; a decimal comma "
                                 "with a comma separator is ambiguous: use ';' or tab as separator")
    try:
        df = pd.read_csv(io.StringIO("\n".join(body)), sep=sep, decimal=decimal,
                         header=0 if has_header else None, skipinitialspace=sep != WHITESPACE, engine="c")
    except Exception as exc:  # pandas raises many types for malformed text
        raise ParameterError(f"{src} is not readable as CSV: {exc}") from None
    df = df.dropna(axis=1, how="all")  # trailing separators
    if not has_header:
        df.columns = [f"ch{i}" for i in range(df.shape[1])]
    for c in df.columns:
        if df[c].dtype.kind not in "fiu":
            raise ParameterError(f"{src}: column {str(c)!r} holds non-numeric values (decimal mark "
                                 f"{decimal!r}, separator {sep!r})")
    return df.to_numpy(dtype=np.float64), [str(c) for c in df.columns], has_header


def _check_rows(values, has_header: bool, header_kv: dict, src: str) -> None:
    """Every row complete, and as many as the header states."""
    if values.shape[0] == 0:
        raise ParameterError(f"{src} has a header but no data rows")
    nan_rows = np.flatnonzero(np.isnan(values).any(axis=1))
    if nan_rows.size:
        r = int(nan_rows[0]) + 1 + int(has_header)
        raise ParameterError(f"{src}: data row {r} has missing values"
                             f"{' (truncated file?)' if nan_rows[0] == values.shape[0] - 1 else ''}")
    if "n_samples" in header_kv:
        stated = parse_number(header_kv["n_samples"], source=src, key="header n_samples")
        if stated != values.shape[0]:
            raise ParameterError(f"{src}: the header states {stated:g} samples but the file holds {values.shape[0]} "
                                 "rows (a cut or edited file)")


def _timing(values, units: list, tcol, header_kv: dict, fs, src: str) -> tuple[float, float]:
    """(fs, t0) from the header, the time column and the caller's fs; any two that disagree are an error."""
    t0 = 0.0
    stated = {k: parse_number(header_kv[k], source=src, key=f"header {k}") for k in _FS_KEYS if k in header_kv}
    if len(set(stated.values())) > 1:
        raise ParameterError(f"{src}: the header states two sampling rates {stated}: which one is right?")
    file_fs = next(iter(stated.values()), None)
    if file_fs is not None and file_fs <= 0:
        raise ParameterError(f"{src}: header fs = {file_fs:g} must be > 0 Hz")
    if tcol is not None:
        tscale = {"ms": 1e-3, "us": 1e-6, "s": 1.0, None: 1.0, "": 1.0}.get(units[tcol], None)
        if tscale is None:
            raise ParameterError(f"{src}: time column unit {units[tcol]!r} is not s, ms or us")
        col_fs, t0 = fs_from_time(values[:, tcol] * tscale, source=src)
        if file_fs is not None and abs(col_fs - file_fs) > 1e-6 * file_fs:
            raise ParameterError(f"{src}: header fs={file_fs:g} Hz contradicts the time column ({col_fs:g} Hz)")
        file_fs = file_fs or col_fs  # the header's exact value wins when both agree
    if fs is not None:
        fs = require_fs(fs, source=src)
        if file_fs is not None and abs(fs - file_fs) > 1e-6 * file_fs:
            raise ParameterError(f"fs={fs:g} contradicts {src}, whose timing gives {file_fs:g} Hz")
    fs = file_fs if file_fs is not None else require_fs(fs, source=src)
    if "t0_s" in header_kv:
        t0 = parse_number(header_kv["t0_s"], source=src, key="header t0_s")
    return fs, t0


def _exact_channels(header_kv: dict, names: list, data_cols: list, chan_meta: dict, src: str) -> dict:
    """Names (any character), quantities, units and locations from the header's ``channels_json``,
    which vibmeasure writes; updates ``names`` and ``chan_meta`` and returns the locations."""
    locations: dict = {}
    if "channels_json" not in header_kv:
        return locations
    import json
    try:
        described = json.loads(header_kv["channels_json"])
        exact = [(str(c["name"]), str(c["quantity"]), str(c["unit"]), str(c.get("location", "")))
                 for c in described]
    except (ValueError, TypeError, KeyError) as exc:
        raise ParameterError(f"{src}: header channels_json is damaged ({exc})") from None
    if len(exact) != len(data_cols):
        raise ParameterError(f"{src}: header describes {len(exact)} channels but the file has {len(data_cols)} "
                             "data columns")
    for i, (nm, q, u, loc) in zip(data_cols, exact):
        names[i] = nm
        chan_meta[nm] = (q, u)
        locations[nm] = loc
    return locations


def _is_number(s: str, decimal: str) -> bool:
    s = s.strip().strip('"').strip("'")  # a quoted number is still a number, not a column label
    if decimal == ",":
        s = s.replace(",", ".")
    try:
        float(s)
        return True
    except ValueError:
        return False


def write_csv(path, rec: Record, *, time_column: bool = True) -> None:
    """Write a record as CSV: metadata in '#' header lines, a time column, full float precision."""
    import json
    head = ["# vibmeasure record, schema 2", f"# fs_hz = {rec.fs!r}", f"# t0_s = {rec.t0!r}",
            f"# n_samples = {rec.n_samples}",
            "# channels_json = " + json.dumps([{"name": c.name, "quantity": c.quantity, "unit": c.unit,
                                                 "location": c.location} for c in rec.channels])]

    def label(c):  # the column row is for people and other tools; exact names are in channels_json
        name = re.sub(r'[,;"\t\r\n\[\]()#]', "_", c.name) or "_"
        return f"{name} [{c.unit}]" if c.unit else name
    cols = (["time [s]"] if time_column else []) + [label(c) for c in rec.channels]
    arr = np.vstack([rec.time, rec.data]).T if time_column else rec.data.T
    buf = io.StringIO()
    buf.write(",".join(cols) + "\n")
    np.savetxt(buf, arr, delimiter=",", fmt="%.17g")
    body = buf.getvalue()
    import hashlib
    head.append(f"# sha256 = {hashlib.sha256(body.encode('utf-8')).hexdigest()}")  # of everything below
    with atomic_path(path) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="\n") as fh:
            fh.write("\n".join(head) + "\n" + body)
