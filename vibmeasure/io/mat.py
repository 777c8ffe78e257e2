"""MATLAB .mat files: v4/v5 through scipy.io, v7.3 (HDF5) through h5py.

Variables and nested struct fields are addressed by dotted paths (``"bearing.gs"``,
``"Fe.Out.Acc"``); a matrix variable gives one channel per row (``"Fe.Out.Acc[0]"``); the elements
of a struct array (v5, and v7.3, where each field holds references to the elements' values) by
their Name field (``"N15.Y.vibration_1.Data"``) or 1-based index (``"S(2).Data"``). The sampling rate
comes from ``fs``, a sample-rate variable in the file, or a time vector.
"""

from __future__ import annotations

import re
from collections import Counter

import numpy as np

from ..core.errors import ParameterError
from ..core.record import Record
from ._common import DEFAULT_MAX_SAMPLES, check_size, fs_from_time, make_record, parse_number, require_fs

_TIME_LEAF = re.compile(r"^(time|t|time_domain|timevector|tvec|time_s)$", re.I)
_FS_LEAF = re.compile(r"^(fs|sr|samplerate|sample_rate|sampling_rate|samplingrate|.*_sample_rate|fsamp)$", re.I)
_RPM_LEAF = re.compile(r".*rpm$", re.I)
# a shaft speed in Hz: named so, or a bare "rate" beside the struct's sampling rate (MFPT's bearing.rate
# beside bearing.sr): there "rate" cannot be the sampling rate, which is stated
_SHAFT_HZ_LEAF = re.compile(r"^(shaft_?rate|shaft_?hz|shaft_?speed_?hz|shaft_?frequency)$", re.I)


def _declared_bytes_v5(path) -> int:
    """Bytes the variables of a MAT v5 file take once decompressed, from each element's tag: a compressed
    element's first 8 decompressed bytes are its matrix tag, whose size counts every nested struct field
    and cell. Read before anything is decompressed, so a small file that inflates to gigabytes is
    refused by its declared size."""
    import struct
    import zlib
    total = 0
    with open(path, "rb") as fh:
        head = fh.read(128)
        if len(head) < 128:
            return 0
        end = "<" if head[126:128] == b"IM" else ">"
        while True:
            tag = fh.read(8)
            if len(tag) < 8:
                return total
            kind, nbytes = struct.unpack(end + "II", tag)
            if kind == 15:          # miCOMPRESSED: its first 8 inflated bytes are the matrix tag
                first = fh.read(min(nbytes, 256))
                try:
                    inner = zlib.decompressobj().decompress(first, 8)
                except zlib.error:
                    return total      # damaged: loadmat names it
                if len(inner) == 8:
                    total += struct.unpack(end + "II", inner)[1]
                fh.seek(nbytes - len(first), 1)
            else:
                total += nbytes
                fh.seek(nbytes + (-nbytes) % 8, 1)


def _leaves_v5(path, max_samples: int | None = None) -> dict[str, np.ndarray]:
    import scipy.io as sio
    try:
        if max_samples is not None:  # the declared sizes, before any variable is decompressed
            for name, shape, _cls in sio.whosmat(path):
                if any(int(d) < 0 for d in shape):
                    raise ParameterError(f"MAT file {str(path)!r}: variable {name!r} declares the shape {shape}; "
                                         "a dimension below 0 is a damaged header")
                check_size(int(np.prod(shape, dtype=np.float64)), source=f"MAT file {str(path)!r}",
                           max_samples=max_samples, what=f"variable {name!r}")
            # nested struct fields and cells are not in whosmat: their inflated bytes, at 8 a sample
            check_size(_declared_bytes_v5(path) // 8, source=f"MAT file {str(path)!r}", max_samples=max_samples,
                       what="its content, decompressed,")
        raw = sio.loadmat(path, squeeze_me=False, struct_as_record=True)
        # scipy gives a MATLAB logical as uint8; whosmat knows it was true/false, not a number
        for name, _shape, cls in sio.whosmat(path):
            if cls == "logical" and name in raw:
                raw[name] = np.asarray(raw[name]).astype(bool)
    except NotImplementedError:
        raise _V73() from None
    except ParameterError:
        raise
    except Exception as exc:  # scipy raises ValueError, TypeError, OSError... for damaged files
        raise ParameterError(f"MAT file {str(path)!r} is unreadable (truncated or not MATLAB): {exc}") from None
    out: dict[str, np.ndarray] = {}

    def walk(prefix, v):
        if isinstance(v, np.ndarray) and v.dtype.names:
            if v.size == 1:
                for fld in v.dtype.names:
                    walk(f"{prefix}.{fld}", v[fld].flat[0])
            else:   # a struct array (the Paderborn rig's Y(1..7)): its elements by name, else by index
                for label, el in zip(_element_labels(v), v.flat):
                    for fld in v.dtype.names:
                        walk(f"{prefix}{label}.{fld}", el[fld])
        elif isinstance(v, np.ndarray) and v.dtype == object:
            if v.size == 1:
                walk(prefix, v.flat[0])
        elif isinstance(v, np.ndarray) and v.dtype.kind in "fiucb":
            out[prefix] = v
    for k, v in raw.items():
        if not k.startswith("__"):
            walk(k, v)
    return out


def _element_labels(v: np.ndarray) -> list[str]:
    """Path parts of a struct array's elements: ".name" from a text field Name (or name) when every
    element has a distinct one that is a plain identifier, else "(i)", 1-based as in MATLAB."""
    fld = next((f for f in ("Name", "name") if f in v.dtype.names), None)
    names = [_text(el[fld]) for el in v.flat] if fld else []
    return [_label(names, i, v.size) for i in range(v.size)]


def _text(x) -> str | None:
    """A MATLAB char value as loaded by scipy (possibly wrapped in 1x1 object arrays), else None."""
    while isinstance(x, np.ndarray) and x.dtype == object and x.size == 1:
        x = x.flat[0]
    if isinstance(x, np.ndarray) and x.dtype.kind == "U" and x.size == 1:
        x = str(x.flat[0])
    return x.strip() if isinstance(x, str) else None


class _V73(Exception):
    pass


def _leaves_v73(path, max_samples: int | None = None) -> dict[str, np.ndarray]:
    import h5py
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise ParameterError(f"MAT file {str(path)!r} is unreadable (truncated, or v7.3 damaged): {exc}") from None
    out: dict[str, np.ndarray] = {}

    def cls(obj):
        c = obj.attrs.get("MATLAB_class")
        return c.decode() if isinstance(c, bytes) else c

    def is_ref(obj):
        return isinstance(obj, h5py.Dataset) and h5py.check_ref_dtype(obj.dtype) is not None

    def leaf(obj, name):
        if cls(obj) in ("char", "logical", "cell", "struct") or obj.attrs.get("MATLAB_empty"):
            return                    # text, flags and empty variables are no signals
        if obj.dtype.kind not in "fiucb" and not obj.dtype.names:
            return
        if max_samples is not None:
            check_size(int(np.prod(obj.shape, dtype=np.float64)), source=f"MAT file {str(path)!r}",
                       max_samples=max_samples, what=f"variable {name!r}")
        a = obj[()]
        if a.dtype.names and set(a.dtype.names) >= {"real", "imag"}:
            a = a["real"] + 1j * a["imag"]
        out[name] = np.asarray(a).T  # MATLAB is column-major

    def walk(obj, name):
        if isinstance(obj, h5py.Dataset):
            if not is_ref(obj):   # references: a cell array (no signals), or a struct array's field (below)
                leaf(obj, name)
            return
        if obj.attrs.get("MATLAB_sparse") is not None:
            return                    # a sparse matrix: its data/ir/jc parts are no signals
        fields = [k for k in obj.keys() if not k.startswith("#")]
        refs = {k: obj[k] for k in fields if is_ref(obj[k]) and cls(obj[k]) != "cell"}
        if cls(obj) == "struct" and refs:
            # a struct array (the Paderborn rig's Y(1..7)): each field holds one reference per element,
            # stored transposed, so a C-order ravel is MATLAB's element order
            if max_samples is not None:
                for k, d in refs.items():
                    check_size(int(np.prod(d.shape, dtype=np.float64)), source=f"MAT file {str(path)!r}",
                               max_samples=max_samples, what=f"struct array field {name}.{k!s}")
            cells = {k: d[()].ravel() for k, d in refs.items()}
            n = min(v.size for v in cells.values())
            fld = next((k for k in ("Name", "name") if k in cells), None)
            names = [_text73(f[r]) for r in cells[fld][:n]] if fld else []
            for i in range(n):
                label = _label(names, i, n)
                for k, v in cells.items():
                    if v[i]:
                        walk(f[v[i]], f"{name}{label}.{k}")
            return
        for k in fields:
            walk(obj[k], f"{name}.{k}" if name else k)

    with f:
        try:
            walk(f, "")
        except ParameterError:
            raise
        except RecursionError:
            raise ParameterError(f"MAT file {str(path)!r} is unreadable (v7.3 damaged): a struct array refers back "
                                 "to itself") from None
        except (OSError, KeyError, ValueError, RuntimeError) as exc:   # a damaged object or reference
            raise ParameterError(f"MAT file {str(path)!r} is unreadable (v7.3 damaged): {exc}") from None
    return out


def _label(names: list, i: int, n: int) -> str:
    """A struct array element's path part: ".name" when every element has a distinct identifier name,
    else "(i)", 1-based as in MATLAB."""
    if len(names) == n and len(set(names)) == n and all(m and re.fullmatch(r"[A-Za-z_]\w*", m) for m in names):
        return f".{names[i]}"
    return f"({i + 1})"


def _text73(obj) -> str | None:
    """A v7.3 char dataset (UTF-16 code units) as text, else None."""
    import h5py
    if not isinstance(obj, h5py.Dataset) or obj.attrs.get("MATLAB_class") not in (b"char", "char"):
        return None
    codes = np.asarray(obj[()]).T.ravel()
    return "".join(map(chr, codes.astype(np.int64))).strip() if codes.size < 256 else None


def _signal_rows(a: np.ndarray) -> np.ndarray | None:
    """A leaf as (n_rows, n_samples) with time along the longer axis; None for scalars/3-D."""
    a = np.asarray(a)
    if a.ndim > 2 or a.size < 2:
        return None
    a = np.atleast_2d(a)
    return a if a.shape[1] >= a.shape[0] else a.T


def read_mat(path, *, fs=None, channels=None, quantity=None, unit=None, max_samples=DEFAULT_MAX_SAMPLES) -> Record:
    src = f"MAT file {str(path)!r}"
    try:
        leaves = _leaves_v5(path, max_samples)
    except _V73:
        leaves = _leaves_v73(path, max_samples)
    if not leaves:
        raise ParameterError(f"{src} holds no numeric variables")
    scalars = {k: v for k, v in leaves.items() if np.asarray(v).size == 1}
    signals = {k: r for k, v in leaves.items() if (r := _signal_rows(v)) is not None and r.dtype.kind != "c"}
    last = {k: k.split(".")[-1] for k in signals}
    times = {k: r for k, r in signals.items() if _TIME_LEAF.match(last[k]) and r.shape[0] == 1}

    # the channels: named ones, or every signal of the dominant length
    rows: list[np.ndarray] = []
    names: list[str] = []
    if channels is not None:
        want = [channels] if isinstance(channels, str) else list(channels)
        for w in want:
            m = re.match(r"^(.*)\[(\d+)\]$", str(w))
            base, row = (m.group(1), int(m.group(2))) if m else (str(w), None)
            if base not in signals:
                raise ParameterError(f"channels={want!r}: {base!r} is not a signal in {src}; "
                                     f"signals: {sorted(signals)}")
            r = signals[base]
            if row is not None:
                if row >= r.shape[0]:
                    raise ParameterError(f"channels={want!r}: {base!r} has {r.shape[0]} rows, not row {row}")
                rows.append(r[row]); names.append(f"{base}[{row}]")
            else:
                rows.extend(r)
                names.extend([base] if r.shape[0] == 1 else [f"{base}[{i}]" for i in range(r.shape[0])])
        lengths = {len(x) for x in rows}
        if len(lengths) != 1:
            raise ParameterError(f"channels={want!r} have different lengths {sorted(lengths)} in {src}")
    else:
        cand = {k: r for k, r in signals.items() if k not in times}
        if not cand:
            raise ParameterError(f"{src} holds no signal variables (only {sorted(leaves)})")
        if times:
            n_star = next(iter(times.values())).shape[1]
        else:
            count = Counter()
            for r in cand.values():
                count[r.shape[1]] += r.shape[0]
            n_star = max(count, key=lambda n: (count[n], n))
        for k, r in cand.items():
            if r.shape[1] == n_star:
                rows.extend(r)
                names.extend([k] if r.shape[0] == 1 else [f"{k}[{i}]" for i in range(r.shape[0])])
        if not rows:
            raise ParameterError(f"{src}: no signal matches the time vector's length {n_star}")
    n = len(rows[0])
    check_size(n * len(rows), source=src, max_samples=max_samples)   # struct fields: whosmat did not see them
    data = np.vstack([np.asarray(x, dtype=np.float64) for x in rows])

    # the sampling rate
    file_fs, t0 = None, 0.0
    stated = {k: parse_number(np.asarray(v).ravel()[0].item(), source=src, key=f"variable {k}")
              for k, v in scalars.items() if _FS_LEAF.match(k.split(".")[-1])}
    if len(set(stated.values())) > 1:
        raise ParameterError(f"{src} states two sampling rates {stated}: which one is right?")
    file_fs = next(iter(stated.values()), None)
    if file_fs is not None and file_fs <= 0:
        raise ParameterError(f"{src}: sampling rate {file_fs:g} must be > 0 Hz")
    if file_fs is None:
        prefix = names[0].split("[")[0].rsplit(".", 1)[0]
        tkeys = sorted((k for k, r in times.items() if r.shape[1] == n),
                       key=lambda k: 0 if k.rsplit(".", 1)[0] == prefix else 1)
        if tkeys:
            file_fs, t0 = fs_from_time(times[tkeys[0]][0], source=f"{src} time vector {tkeys[0]!r}")
    if fs is not None:
        fs = require_fs(fs, source=src)
        if file_fs is not None and abs(fs - file_fs) > 1e-6 * file_fs:
            raise ParameterError(f"fs={fs:g} contradicts {src}, whose timing gives {file_fs:g} Hz")
    fs = file_fs if file_fs is not None else require_fs(fs, source=src)
    meta = {"source": str(path)}
    meta.update(_stated_speed(scalars, stated, src))
    return make_record(data, fs, names, quantity=quantity, unit=unit, t0=t0, meta=meta, source=src)


def _stated_speed(scalars: dict, stated_fs: dict, src: str) -> dict:
    """The shaft speed the file states: a variable ending in "rpm", or a shaft rate in Hz (a leaf named
    so, or a bare "rate" in the struct that states the sampling rate) turned to rpm; with the variable it
    came from (``rpm_source``). A value that is no positive number is ignored, never guessed."""
    fs_structs = {k.rsplit(".", 1)[0] for k in stated_fs if "." in k}
    found = []
    for k, v in scalars.items():
        leaf = k.split(".")[-1]
        factor = 1.0 if _RPM_LEAF.match(leaf) else 60.0 if (
            _SHAFT_HZ_LEAF.match(leaf) or (leaf.lower() == "rate" and "." in k and k.rsplit(".", 1)[0] in fs_structs)
        ) else None
        if factor is None:
            continue
        try:
            value = float(np.asarray(v, dtype=float).ravel()[0]) * factor
        except (TypeError, ValueError, IndexError):
            continue
        if np.isfinite(value) and value > 0:
            found.append((factor == 1.0, k, value))
    if not found:
        return {}
    _, key, rpm = max(found, key=lambda f: f[0])   # an rpm stated as such first
    return {"rpm": rpm, "rpm_source": f"variable {key!r}"}


def read_frf_mat(path, variable: str | None = None):
    """An FRF stored in a MAT file (v5 or v7.3): a complex variable of one or (outputs, lines) rows and a
    frequency vector of as many lines (a variable whose name holds "freq"), each checked: complex, finite,
    frequencies increasing."""
    from ..core.results import FRF
    src = f"MAT file {str(path)!r}"
    try:
        leaves = _leaves_v5(path)
    except _V73:
        leaves = _leaves_v73(path)
    if variable is None:
        cands = [k for k, v in leaves.items() if np.iscomplexobj(v) and v.size > 8]
        if len(cands) != 1:
            raise ParameterError(f"variable= is required: complex variables in {src}: {cands}")
        variable = cands[0]
    if variable not in leaves:
        raise ParameterError(f"variable={variable!r} is not in {src}")
    h = np.squeeze(np.asarray(leaves[variable]))
    if not np.iscomplexobj(h):
        raise ParameterError(f"{src}: variable {variable!r} is real; an FRF is complex (a magnitude alone has no "
                             "phase to fit modes to): export the complex FRF")
    if h.ndim not in (1, 2) or h.size < 2:
        raise ParameterError(f"{src}: variable {variable!r} has shape {h.shape}; an FRF is one row of lines or "
                             "(outputs, lines)")
    freqs = {k: np.asarray(v, float).ravel() for k, v in leaves.items()
             if "freq" in k.lower() and np.asarray(v).dtype.kind in "fiu" and np.size(v) in h.shape}
    if not freqs:
        raise ParameterError(f"{src}: no frequency vector (a variable named *freq*) of {h.shape[-1]} lines"
                             + (f" or {h.shape[0]}" if h.ndim == 2 else ""))
    name, fvec = next(iter(freqs.items()))
    if h.ndim == 2 and h.shape[1] != fvec.size:
        h = h.T                  # stored as (lines, outputs)
    h = np.atleast_2d(h)
    if not (np.all(np.isfinite(fvec)) and np.all(np.diff(fvec) > 0)):
        raise ParameterError(f"{src}: frequency vector {name!r} must be finite and increasing")
    if not np.all(np.isfinite(h)):
        raise ParameterError(f"{src}: variable {variable!r} holds NaN or inf values")
    outputs = (variable,) if h.shape[0] == 1 else tuple(f"{variable}[{i}]" for i in range(h.shape[0]))
    return FRF(fvec, h[:, None, :], "unknown", estimator="file", outputs=outputs, inputs=("force",),
               params={"source": str(path)})
