"""WAV audio files: integer PCM (scaled to full scale = 1.0) and float."""

from __future__ import annotations

import os
import struct
import warnings

import numpy as np

from ..core.errors import ParameterError
from ..core.record import Record
from ..core._validate import select_names
from ._common import DEFAULT_MAX_SAMPLES, atomic_path, check_size, make_record

_FULL_SCALE = {np.dtype("int16"): 32768.0, np.dtype("int32"): 2147483648.0, np.dtype("uint8"): 128.0}


_BITS = (8, 16, 24, 32, 64)   # the PCM and float sample sizes a WAV file can hold


def _check_format(path, src: str) -> None:
    """The format chunk's sample size must be one a WAV file holds: 0 or 12 bits are crafted, not recorded."""
    with open(path, "rb") as fh:
        head = fh.read(1 << 16)
    for cid, off, size in _chunks(head):
        if cid == b"fmt " and size >= 16 and off + 16 <= len(head):
            channels = struct.unpack("<H", head[off + 2:off + 4])[0]
            bits = struct.unpack("<H", head[off + 14:off + 16])[0]
            if bits not in _BITS or channels == 0:
                raise ParameterError(f"{src}: its format chunk declares {bits} bits per sample and {channels} "
                                     f"channel(s); a WAV record has {_BITS} bits and at least one channel")
            return


def read_wav(path, *, fs=None, channels=None, quantity=None, unit=None, max_samples=DEFAULT_MAX_SAMPLES) -> Record:
    from scipy.io import wavfile
    src = f"WAV file {str(path)!r}"
    _check_format(path, src)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", wavfile.WavFileWarning)
            try:
                rate, data = wavfile.read(path, mmap=True)  # mapped, not loaded: sizes are checked first
            except ValueError as exc:
                if "mmap" not in str(exc):
                    raise
                # 24-bit PCM (what measurement recorders write) cannot be mapped: its size is bounded by
                # the file's (3 bytes a sample) before it is read into int32 samples, left-justified
                check_size(os.path.getsize(path) // 3, source=src, max_samples=max_samples)
                rate, data = wavfile.read(path, mmap=False)
    except (ValueError, EOFError, OSError, struct.error, wavfile.WavFileWarning) as exc:
        raise ParameterError(f"{src} is unreadable (truncated or not WAV): {exc}") from None
    check_size(data.size, source=src, max_samples=max_samples)
    _check_digest(path, src)
    if data.dtype.kind not in "iuf":
        raise ParameterError(f"{src}: sample type {data.dtype} is not PCM integer or float")
    if fs is not None and float(fs) != float(rate):
        raise ParameterError(f"fs={fs} contradicts {src}, recorded at {rate} Hz")
    data = np.array(data)  # out of the file mapping
    scale = _FULL_SCALE.get(data.dtype)
    x = data.astype(np.float64)
    if data.dtype == np.uint8:
        x -= 128.0
    if scale:
        x /= scale
    x = x.T if x.ndim == 2 else x[np.newaxis]
    names = [f"ch{i}" for i in range(x.shape[0])]
    pick = select_names(names, channels, source=src)
    meta = {"source": str(path), "wav_dtype": str(data.dtype), "full_scale": 1.0 if scale else None}
    return make_record(x[pick], float(rate), [names[i] for i in pick], quantity=quantity, unit=unit,
                       meta=meta, source=src)


def write_wav(path, rec: Record) -> None:
    """Write float samples as a 64-bit float WAV (the sampling rate is rounded to an integer Hz)."""
    from scipy.io import wavfile
    if rec.fs != round(rec.fs):
        raise ParameterError(f"WAV stores an integer sampling rate; fs={rec.fs} is not an integer: resample")
    with atomic_path(path) as tmp:
        wavfile.write(tmp, int(rec.fs), np.ascontiguousarray(rec.data.T))
        _append_digest(tmp)


_TAG = b"vibmeasure sha256="


def _chunks(raw: bytes):
    """(id, offset of the payload, size) of the chunks of a RIFF/WAVE file."""
    pos = 12
    while pos + 8 <= len(raw):
        cid, size = raw[pos:pos + 4], struct.unpack("<I", raw[pos + 4:pos + 8])[0]
        yield cid, pos + 8, size
        pos += 8 + size + (size & 1)


def _signed(raw: bytes) -> bytes | None:
    """What the digest covers: the format chunk (how samples are decoded) and the data chunk."""
    parts = {cid: raw[o:o + n] for cid, o, n in _chunks(raw) if cid in (b"fmt ", b"data")}
    return parts[b"fmt "] + parts[b"data"] if len(parts) == 2 else None


def _append_digest(path) -> None:
    """A LIST/INFO chunk with the SHA-256 of the data chunk (players and scipy skip LIST chunks)."""
    import hashlib
    raw = open(path, "rb").read()
    body = _signed(raw)
    if body is None:
        return
    text = _TAG + hashlib.sha256(body).hexdigest().encode() + b"\0"
    icmt = b"ICMT" + struct.pack("<I", len(text)) + text + (b"\0" if len(text) & 1 else b"")
    chunk = b"LIST" + struct.pack("<I", 4 + len(icmt)) + b"INFO" + icmt
    with open(path, "r+b") as fh:
        fh.seek(0, 2)
        fh.write(chunk)
        size = fh.tell()
        fh.seek(4)
        fh.write(struct.pack("<I", size - 8))


def _check_digest(path, src: str) -> None:
    """A WAV vibmeasure wrote carries the SHA-256 of its samples: a changed sample is a named error."""
    import hashlib
    raw = open(path, "rb").read()
    stated = None
    for cid, o, n in _chunks(raw):
        if cid == b"LIST" and raw[o:o + 4] == b"INFO":
            i = raw.find(_TAG, o, o + n)
            if i >= 0:
                stated = raw[i + len(_TAG): i + len(_TAG) + 64]
    body = _signed(raw)
    if stated is not None and (body is None or hashlib.sha256(body).hexdigest().encode() != stated):
        raise ParameterError(f"{src} is damaged: its samples do not match the SHA-256 vibmeasure wrote into it")
