"""WAV audio files: integer PCM (scaled to full scale = 1.0) and float."""

from __future__ import annotations

import struct
import warnings

import numpy as np

from ..core.errors import ParameterError
from ..core.record import Record
from ..core._validate import select_names
from ._common import DEFAULT_MAX_SAMPLES, atomic_path, check_size, make_record

_FULL_SCALE = {np.dtype("int16"): 32768.0, np.dtype("int32"): 2147483648.0, np.dtype("uint8"): 128.0}


def read_wav(path, *, fs=None, channels=None, quantity=None, unit=None, max_samples=DEFAULT_MAX_SAMPLES) -> Record:
    from scipy.io import wavfile
    src = f"WAV file {str(path)!r}"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", wavfile.WavFileWarning)
            rate, data = wavfile.read(path, mmap=True)  # mapped, not loaded: sizes are checked first
    except (ValueError, EOFError, OSError, struct.error, wavfile.WavFileWarning) as exc:
        raise ParameterError(f"{src} is unreadable (truncated or not WAV): {exc}") from None
    check_size(data.size, source=src, max_samples=max_samples)
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
