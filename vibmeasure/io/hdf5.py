"""HDF5: vibmeasure's own record schema (exact round trip), or any bare dataset given fs.

Schema "vibmeasure.record", version 1::

    /            attrs: vibmeasure_schema="vibmeasure.record", schema_version=1
    /data        float dataset (n_channels, n_samples); attrs fs (Hz), t0 (s)
                 attrs channel_names, channel_quantities, channel_units, channel_locations
    /            attrs meta (JSON), history (JSON list)
"""

from __future__ import annotations

import json

import os

import numpy as np

from ..core.errors import ParameterError
from ..core.record import Channel, Record
from ..core._validate import select_names
from ._common import DEFAULT_MAX_SAMPLES, atomic_path, check_size, make_record, parse_number, real_samples, require_fs

SCHEMA = "vibmeasure.record"
SCHEMA_VERSION = 2   # 2: the file is sealed (SHA-256 in the HDF5 user block); 1 is still read

USERBLOCK = 512
_MAGIC = b"VIBMEASURE-SEAL-SHA256 "
_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def _digest(path, start: int = USERBLOCK, fh=None, progress=None) -> str:
    """SHA-256 of the bytes from ``start`` on, of the file at path or of an open file;
    ``progress(fraction)`` is called as blocks are hashed."""
    import hashlib
    if fh is None:
        with open(path, "rb") as own:
            return _digest(path, start, own, progress)
    h = hashlib.sha256()
    total = max(os.fstat(fh.fileno()).st_size - start, 1)
    done = 0
    fh.seek(start)
    for block in iter(lambda: fh.read(1 << 22), b""):
        h.update(block)
        done += len(block)
        if progress is not None:
            progress(min(done / total, 1.0))
    return h.hexdigest()


def seal(path) -> None:
    """Write the SHA-256 of everything after the user block into the user block, twice (a single
    damaged byte leaves one copy readable). Call on a closed file made with userblock_size=512."""
    line = _MAGIC + _digest(path).encode() + b"\n"
    block = (line + b"\0" * (USERBLOCK // 2 - len(line))) * 2
    with open(path, "r+b") as fh:
        fh.write(block)


def check_seal(path, src: str, progress=None) -> bool:
    """Before HDF5 parses a file: a file vibmeasure sealed must match its checksum, so a damaged
    byte anywhere is a named error here instead of a crash, a hang or a silently changed number
    inside the HDF5 library. Returns True for a verified file, False for an unsealed one.
    ``progress(fraction)`` follows the hashing of a large file."""
    with open(path, "rb") as fh:  # one open file: a writer's rename meanwhile cannot mix two versions
        head = fh.read(USERBLOCK + len(_HDF5_SIGNATURE))
        return _check_head(path, fh, head, src, progress)


def _check_head(path, fh, head: bytes, src: str, progress=None) -> bool:
    copies = [head[:USERBLOCK // 2], head[USERBLOCK // 2: USERBLOCK]]
    ours = [c for c in copies if c.startswith(_MAGIC)]
    looks_ours = ours or any(b"VIBMEASURE" in c or b"SEAL-SHA256" in c for c in copies)
    if not looks_ours:
        return False
    if head[USERBLOCK:] != _HDF5_SIGNATURE:
        raise ParameterError(f"{src} is damaged: its HDF5 signature after the seal is missing (truncated or "
                             "overwritten)")
    stated = {c[len(_MAGIC): len(_MAGIC) + 64] for c in ours}
    actual = _digest(path, fh=fh, progress=progress).encode()
    if actual not in stated:
        raise ParameterError(f"{src} is damaged: its content does not match the SHA-256 vibmeasure wrote into it "
                             "(a changed or cut byte; or the file was edited after writing)")
    return True


def _open(path):
    import h5py
    check_seal(path, f"HDF5 file {str(path)!r}")
    try:
        return h5py.File(path, "r")
    except (OSError, ValueError) as exc:
        raise ParameterError(f"HDF5 file {str(path)!r} is unreadable (truncated or not HDF5): {exc}") from None


def _str_list(a) -> list[str]:
    return [x.decode() if isinstance(x, bytes) else str(x) for x in np.atleast_1d(a)]


def refuse_foreign(f, src: str) -> None:
    """Every object of the file lives in it: an external link, external raw storage or a virtual dataset
    (each reads or writes another file) anywhere in the tree is refused, before anything is read."""
    import h5py
    stack = [f]
    while stack:
        g = stack.pop()
        for name in g:
            lk = g.get(name, getlink=True)
            where = f"{g.name.rstrip('/')}/{name}"
            if isinstance(lk, h5py.ExternalLink):
                raise ParameterError(f"{src}: {where!r} is an external link to {lk.filename!r}; a store reads and "
                                     "writes only its own file: refused")
            if isinstance(lk, h5py.SoftLink):
                continue          # a path inside this file; its target is walked where it stands
            obj = g.get(name)
            if isinstance(obj, h5py.Group):
                stack.append(obj)
            elif isinstance(obj, h5py.Dataset) and (obj.external or obj.is_virtual):
                raise ParameterError(f"{src}: {where!r} keeps its samples in other files "
                                     f"({'virtual dataset' if obj.is_virtual else 'external raw storage'}); "
                                     "refused")


def _dataset(f, name: str, src: str, *, allow_external: bool, max_samples: int):
    """A dataset of the file, checked before anything is read: it must live in this file (no external
    link, external raw storage or virtual mapping unless allowed), be numeric and within max_samples."""
    import h5py
    lk = f.get(name, getlink=True)
    if lk is None:
        raise ParameterError(f"dataset={name!r} is not in {src}")
    if isinstance(lk, h5py.ExternalLink) and not allow_external:
        raise ParameterError(f"{src}: {name!r} is an external link to {lk.filename!r}:{lk.path!r}; links that "
                             "leave the file are refused (allow_external=True if you trust the file)")
    try:
        d = f[name]
    except KeyError as exc:
        raise ParameterError(f"{src}: {name!r} is a dangling link ({exc})") from None
    if not isinstance(d, h5py.Dataset):
        raise ParameterError(f"{src}: {name!r} is a group, not a dataset")
    if not allow_external:
        if d.file.filename != f.filename:
            raise ParameterError(f"{src}: {name!r} resolves into another file ({d.file.filename!r}); refused "
                                 "(allow_external=True if you trust the file)")
        if d.external:
            raise ParameterError(f"{src}: {name!r} keeps its samples in external raw files "
                                 f"{[e[0] for e in d.external]}: any local file could be read as samples; refused "
                                 "(allow_external=True if you trust the file)")
        if d.is_virtual:
            raise ParameterError(f"{src}: {name!r} is a virtual dataset mapping other files; refused "
                                 "(allow_external=True if you trust the file)")
    if d.dtype.kind not in "fiuc":
        raise ParameterError(f"{src}: {name!r} holds {d.dtype} values, not numbers")
    check_size(int(np.prod(d.shape, dtype=np.float64)), source=src, max_samples=max_samples, what=f"dataset {name!r}")
    return d


def schema_header(f, src: str, *, allow_external: bool, max_samples: int):
    """The checked parts of a record file in vibmeasure's schema, nothing read from the data yet:
    (dataset, channels, fs, t0, meta, history). The eager and the lazy reader share every check."""
    ver = f.attrs.get("schema_version", -1)
    try:
        ver = int(ver)
    except (TypeError, ValueError):
        raise ParameterError(f"{src}: schema_version {ver!r} is not a whole number") from None
    if ver > SCHEMA_VERSION:
        raise ParameterError(f"{src} has schema_version {ver}; this vibmeasure reads up to {SCHEMA_VERSION}")
    d = _dataset(f, "data", src, allow_external=allow_external, max_samples=max_samples)
    a = d.attrs
    try:
        chans = tuple(Channel(n, q, u, loc) for n, q, u, loc in zip(
            _str_list(a["channel_names"]), _str_list(a["channel_quantities"]),
            _str_list(a["channel_units"]), _str_list(a["channel_locations"])))
        rfs = parse_number(a["fs"], source=src, key="attribute fs")
        t0 = parse_number(a["t0"], source=src, key="attribute t0")
        meta = json.loads(f.attrs.get("meta", "{}"))
        history = tuple(json.loads(f.attrs.get("history", "[]")))
    except (KeyError, OSError, ValueError, TypeError) as exc:
        raise ParameterError(f"{src} claims schema {SCHEMA} but is damaged: {type(exc).__name__} {exc}") from None
    if not isinstance(meta, dict):
        raise ParameterError(f"{src}: its meta attribute is JSON but not a mapping")
    if rfs <= 0:
        raise ParameterError(f"{src}: attribute fs = {rfs:g} must be > 0")
    if d.ndim != 2 or d.shape[0] != len(chans) or len(chans) == 0:
        raise ParameterError(f"{src}: data has shape {d.shape} but {len(chans)} channel descriptions")
    if d.shape[1] < 2:
        raise ParameterError(f"{src}: data holds {d.shape[1]} samples per channel; a record needs at least 2")
    return d, chans, rfs, t0, meta, history


def read_hdf5(path, *, fs=None, channels=None, quantity=None, unit=None, dataset=None, allow_external=False,
              max_samples=DEFAULT_MAX_SAMPLES) -> Record:
    src = f"HDF5 file {str(path)!r}"
    with _open(path) as f:
        schema = f.attrs.get("vibmeasure_schema")
        schema = schema.decode() if isinstance(schema, bytes) else schema
        if schema == SCHEMA and dataset is None:
            d, chans, rfs, t0, meta, history = schema_header(f, src, allow_external=allow_external,
                                                            max_samples=max_samples)
            try:
                data = real_samples(d[()], source=src)
            except (OSError, ValueError, TypeError) as exc:
                raise ParameterError(f"{src} claims schema {SCHEMA} but its data are unreadable: {exc}") from None
            if fs is not None and float(fs) != rfs:
                raise ParameterError(f"fs={fs} contradicts {src}, which stores fs={rfs}")
            rec = Record(data, rfs, tuple(chans), t0=t0, meta=meta, history=history)
            if channels is not None:
                rec = rec.select([rec.names[i] for i in select_names(rec.names, channels, source=src)])
            if quantity is not None or unit is not None:
                rec = make_record(rec.data, rec.fs, rec.names, quantity=quantity, unit=unit,
                                  quantities=[c.quantity for c in rec.channels],
                                  units=[c.unit for c in rec.channels], t0=rec.t0, meta=rec.meta, source=src)
            return rec
        # a bare dataset: the caller names it and gives fs (or it carries an fs attribute)
        if dataset is None:
            names = []
            f.visititems(lambda n, o: names.append(n) if hasattr(o, "shape") and o.ndim in (1, 2) else None)
            if len(names) != 1:
                raise ParameterError(f"{src} is not a vibmeasure record file; name the dataset "
                                     f"(dataset=...) among {names}")
            dataset = names[0]
        d = _dataset(f, dataset, src, allow_external=allow_external, max_samples=max_samples)
        try:
            data = real_samples(d[()], source=f"{src} dataset {dataset!r}")
        except (OSError, TypeError, ValueError) as exc:
            raise ParameterError(f"{src}: dataset {dataset!r} is unreadable: {exc}") from None
        if data.ndim not in (1, 2) or data.size < 2:
            raise ParameterError(f"{src}: dataset {dataset!r} has shape {data.shape}; a record is 1-D or "
                                 "(channels, samples)")
        attrs = [k for k in ("fs", "sampling_rate", "fs_hz") if k in d.attrs]
        attr_fs = parse_number(d.attrs[attrs[0]], source=src, key=f"attribute {attrs[0]}") if attrs else None
        fs = attr_fs if fs is None and attr_fs is not None else require_fs(fs, source=f"{src} dataset {dataset!r}")
    if data.ndim == 1:
        data = data[np.newaxis]
    base = dataset.strip("/").replace("/", ".")
    names = [base] if data.shape[0] == 1 else [f"{base}[{i}]" for i in range(data.shape[0])]
    pick = select_names(names, channels, source=src)
    return make_record(data[pick], fs, [names[i] for i in pick], quantity=quantity, unit=unit,
                       meta={"source": str(path), "dataset": dataset}, source=src)


def write_hdf5(path, rec: Record) -> None:
    import h5py
    with atomic_path(path) as tmp:
        with h5py.File(tmp, "w", userblock_size=USERBLOCK) as f:
            f.attrs["vibmeasure_schema"] = SCHEMA
            f.attrs["schema_version"] = SCHEMA_VERSION
            f.attrs["meta"] = json.dumps(dict(rec.meta), default=str)
            f.attrs["history"] = json.dumps(list(rec.history))
            d = f.create_dataset("data", data=rec.data, chunks=True if rec.data.size > 2 ** 16 else None)
            d.attrs["fs"] = rec.fs
            d.attrs["t0"] = rec.t0
            d.attrs["channel_names"] = [c.name for c in rec.channels]
            d.attrs["channel_quantities"] = [c.quantity for c in rec.channels]
            d.attrs["channel_units"] = [c.unit for c in rec.channels]
            d.attrs["channel_locations"] = [c.location for c in rec.channels]
        seal(tmp)
