"""Amplitude-correct spectra, PSD, CSD, coherence, spectrogram, band and octave RMS.

All segment-averaged estimates reduce to one blocked engine (:func:`_segment_sums`): segments are
taken as strided views, windowed and transformed 16 at a time (cache-sized batches, shared between
the calling thread and one worker), and their power or cross products are summed. For windows
whose DFT has a few lines only (the cosine-sum family: Hann, Hamming, Blackman, flat-top, boxcar)
the constant detrend is applied to those lines of the transform (linearity), not to every sample. The same engine streams a
:class:`~vibmeasure.io.LazyRecord` from disk in bounded blocks, so a recording larger than memory
is handled like one in memory. Results equal ``scipy.signal.welch``/``csd`` to round-off.
"""

from __future__ import annotations

import functools
import math
import threading
from typing import Callable

import numpy as np
import scipy.fft as _fft
from scipy import signal as _sig

from ..core._validate import memory_guard, select_names
from ..core.errors import ParameterError
from ..core.record import Record
from ..core.results import Spectrogram, Spectrum

__all__ = ["amplitude_spectrum", "psd", "csd", "coherence", "spectrogram", "band_rms", "octave_bands",
           "power_unit", "get_window"]

BATCH = 16              # segments per channel transformed together: fits the cache, amortises call overhead
READ_SAMPLES = 1 << 21  # samples per channel read from a lazy source at a time
MEDIAN_LIMIT = 20_000_000  # per-segment values kept for median averaging
# numpy >= 2 transforms into a reused buffer (out=) with less Python around the call than scipy.fft;
# with two threads sharing the batches, every Python step holds the GIL the other thread waits for
# (one A/B at 2^18 samples, interleaved with welch: 1.9-2.1 against 2.2-2.3 ms)
_NUMPY_FFT_OUT = np.lib.NumpyVersion(np.__version__) >= "2.0.0"


# ------------------------------------------------------------------------------------------------
# sources and checks
class _ArraySource:
    """An in-memory record seen through the lazy-source interface (reads are views)."""

    def __init__(self, rec: Record):
        self.rec = rec
        self.fs, self.channels, self.n_samples, self.n_channels = rec.fs, rec.channels, rec.n_samples, rec.n_channels

    def read(self, start, stop):
        return self.rec.data[:, start:stop]


def _source(rec, fs=None, *, check: bool = True):
    """The record as a source of blocks; ``check=False`` leaves the amplitude-range check to the
    caller (psd checks its result instead, which saves a pass over the data)."""
    from ..core._validate import as_record
    from ..io.lazy import LazyRecord
    from ..core._validate import check_range
    if isinstance(rec, LazyRecord):
        return rec
    rec = as_record(rec, fs=fs)
    if check:
        check_range(rec.data)
    return _ArraySource(rec)


def _channel_indices(src, channels) -> list[int]:
    return select_names([c.name for c in src.channels], channels, source="this record")


def get_window(window, n: int) -> np.ndarray:
    """A periodic (DFT-even) window of length n by name, ("kaiser", beta) tuple or array."""
    if isinstance(window, np.ndarray):
        if window.shape != (n,):
            raise ParameterError(f"window array has shape {window.shape}; it must have nperseg={n} values")
        return window.astype(float)
    try:
        return _named_window(window, int(n)).copy()
    except (ValueError, TypeError) as exc:
        raise ParameterError(f"window={window!r} is not a known window ({exc}); e.g. 'hann', 'hamming', "
                             "'flattop', 'boxcar', ('kaiser', 8.0)") from None


@functools.lru_cache(maxsize=32)
def _named_window(window, n: int) -> np.ndarray:
    return _sig.get_window(window, n, fftbins=True)


@functools.lru_cache(maxsize=32)
def _window_lines(key: bytes, nperseg: int, nfft: int):
    """The DFT lines of a window (padded to nfft) that are not zero: (indices, values)."""
    win = np.frombuffer(key, float)
    W = _fft.rfft(np.r_[win, np.zeros(nfft - nperseg)])
    lines = np.flatnonzero(np.abs(W) > 1e-12 * np.abs(W).max())
    return lines, W[lines]


def _check_dtype(dtype):
    if dtype is None:
        return np.float64
    try:
        dt = np.dtype(dtype)
    except TypeError:
        dt = None
    if dt not in (np.dtype(np.float32), np.dtype(np.float64)):
        raise ParameterError(f"dtype={dtype!r} must be 'float32' or 'float64'")
    return dt.type


def _check_params(n, nperseg, noverlap, nfft, detrend, average, default_nperseg):
    if n < 2:
        raise ParameterError(f"the record has {n} sample(s); a spectrum needs at least 2")
    if nperseg is None:
        nperseg = min(n, default_nperseg)
    if isinstance(nperseg, bool) or not isinstance(nperseg, (int, np.integer)) or nperseg < 2:
        raise ParameterError(f"nperseg={nperseg!r} must be an integer >= 2")
    nperseg = int(nperseg)
    if nperseg > n:
        raise ParameterError(f"nperseg={nperseg} exceeds the record length {n} samples")
    if noverlap is None:
        noverlap = nperseg // 2
    if isinstance(noverlap, bool) or not isinstance(noverlap, (int, np.integer)) or not 0 <= noverlap < nperseg:
        raise ParameterError(f"noverlap={noverlap!r} must be an integer with 0 <= noverlap < nperseg={nperseg}")
    nfft = nperseg if nfft is None else nfft
    if isinstance(nfft, bool) or not isinstance(nfft, (int, np.integer)) or nfft < nperseg:
        raise ParameterError(f"nfft={nfft!r} must be an integer >= nperseg={nperseg}")
    if detrend not in ("constant", "linear", False, None):
        raise ParameterError(f"detrend={detrend!r} must be 'constant', 'linear' or False")
    if average not in ("mean", "median", "max"):
        raise ParameterError(f"average={average!r} must be 'mean', 'median' or 'max' (peak hold)")
    return nperseg, int(noverlap), int(nfft)


def _check_band(band, fs, name="band"):
    from ..core._validate import check_band
    return check_band(band, fs, name=name)


def power_unit(unit: str, *, density: bool) -> str:
    """Unit of a squared quantity per Hz (density) or per line: 'g' -> 'g^2/Hz', 'm/s^2' -> '(m/s^2)^2/Hz'."""
    if not unit:
        return "1/Hz" if density else ""
    u = f"({unit})^2" if any(c in unit for c in "/^*") else f"{unit}^2"
    return u + "/Hz" if density else u


# ------------------------------------------------------------------------------------------------
# the engine
def _segment_sums(src, idx, *, nperseg, noverlap, nfft, win, detrend, pairs=(), keep_segments=False,
                  reducer="sum", progress: Callable[[float], None] | None = None, dtype=np.float64):
    """Sum (or max) over segments of |X|^2 per channel and of X_i conj(X_j) per pair.

    Segments are strided views of blocks read from the source; each thread takes a share of a
    block's segments in batches of BATCH per channel and keeps its own sums.
    Returns (autos (n_idx, nf), crosses (n_pairs, nf) complex, n_segments, per_segment or None).
    """
    n = src.n_samples
    step = nperseg - noverlap
    nseg = (n - nperseg) // step + 1
    nf = nfft // 2 + 1
    n_ch = len(idx)
    per_seg = np.empty((n_ch, nseg, nf)) if keep_segments else None
    tt = None
    if detrend == "linear":
        tt = np.arange(nperseg) - (nperseg - 1) / 2
        tt = tt / np.sqrt(tt @ tt)
    sb = max(1, (READ_SAMPLES - nperseg) // step + 1)  # segments per read
    win = win.astype(dtype)  # float32 segments stay float32 through the FFT (sums are kept in float64)
    names = [c.name for c in src.channels]
    all_rows = list(idx) == list(range(src.n_channels))
    # A cosine-sum window (Hann, Hamming, Blackman, flat-top, boxcar) has a DFT with a few lines only:
    # removing a segment's mean m then changes only those lines, by m W[k] (linearity), so the
    # constant detrend costs a sum per segment instead of a pass over every sample.
    lines, W_lines = _window_lines(np.ascontiguousarray(win, float).tobytes(), nperseg, nfft)
    sparse = detrend == "constant" and lines.size <= 8
    W_mean = (W_lines / nperseg).astype(np.complex64 if dtype == np.float32 else complex)  # per unit segment sum
    if sparse and lines.size and np.array_equal(lines, np.arange(lines[0], lines[-1] + 1)):
        lines = slice(int(lines[0]), int(lines[-1]) + 1)   # contiguous lines: a view, not a gather
    # Summed powers only: the threads keep each segment's raw values at those lines, and the lines are
    # detrended once at the end from the segment sums (a few operations per block instead of three per
    # batch: each numpy call that releases the GIL makes the two threads hand it over, and at 2^18
    # samples those hand-overs cost more than the arithmetic)
    deferred = sparse and reducer == "sum" and not keep_segments and not pairs
    if deferred:
        raw_lines = np.empty((n_ch, min(sb, nseg), np.arange(nf)[lines].size), complex)  # one block's
        line_power = np.zeros(raw_lines.shape[::2])    # detrended power at those lines, summed

    def work(segs, chunks, s0):
        """Sums over the segment batches this thread takes from the shared chunk iterator (powers
        that overflow become inf, found after the block: no numpy warning on the way)."""
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            return _work(segs, chunks, s0)

    def _work(segs, chunks, s0):
        au = np.zeros((n_ch, 2 * nf)) if reducer == "sum" else np.full((n_ch, nf), -np.inf)
        cr = np.zeros((len(pairs), nf), complex)
        buf = _scratch("win", (BATCH, nperseg), dtype)    # one windowed batch, reused (no allocation per batch)
        pad = None
        if nfft > nperseg:
            pad = _scratch("pad", (BATCH, nfft), dtype)
            pad[:, nperseg:] = 0
        out = (_scratch("fft", (BATCH, nf), np.complex64 if dtype == np.float32 else complex)
               if _NUMPY_FFT_OUT else None)             # one transformed batch, reused
        for b0, b1 in chunks:   # list iterators hand out each chunk once, also across threads (GIL)
            Xs = []
            m = b1 - b0
            for c in range(n_ch):
                y = segs[c, b0:b1]
                if not sparse:
                    if detrend == "constant":
                        y = y - y.mean(axis=-1, keepdims=True)
                    elif detrend == "linear":
                        y = y - y.mean(axis=-1, keepdims=True)
                        y = y - (y @ tt)[:, None] * tt
                yw = np.multiply(y, win, out=buf[:m])
                if pad is not None:
                    pad[:m, :nperseg] = yw
                    yw = pad[:m]
                X = np.fft.rfft(yw, axis=-1, out=out[:m]) if out is not None else _fft.rfft(yw, axis=-1)
                if deferred:
                    raw_lines[c, b0:b1] = X[:, lines]
                elif sparse:
                    X[:, lines] -= np.multiply.outer(y.sum(axis=-1), W_mean)
                if pairs:   # the buffer is the next channel's too: a copy whenever it is in use
                    Xs.append(X.copy() if reducer == "sum" and not keep_segments or out is not None else X)
                if reducer == "sum" and not keep_segments:
                    v = X.view(X.real.dtype).reshape(m, 2 * nf)   # re, im interleaved, squared in place
                    np.square(v, out=v)
                    au[c] += v.sum(axis=0, dtype=float)
                else:
                    P = X.real ** 2 + X.imag ** 2
                    if keep_segments:
                        per_seg[c, s0 + b0:s0 + b1] = P
                    if reducer == "sum":
                        au[c, :nf] += P.sum(axis=0)
                    else:
                        np.maximum(au[c], P.max(axis=0), out=au[c])
            for k, (i, j) in enumerate(pairs):
                cr[k] += (Xs[i] * Xs[j].conj()).sum(axis=0)
        if reducer == "sum":
            au = au.reshape(n_ch, nf, 2).sum(axis=2) if not keep_segments else au[:, :nf]
        return au, cr

    autos = np.zeros((n_ch, nf)) if reducer == "sum" else np.full((n_ch, nf), -np.inf)
    crosses = np.zeros((len(pairs), nf), complex)
    pool = _pool()
    reads = [(s0, min(nseg, s0 + sb)) for s0 in range(0, nseg, sb)]

    spare = []   # two float64 blocks a source on disk is read into, in turn (no fresh 16 MB per read)

    def fetch(s0, s1):
        a0, a1 = s0 * step, (s1 - 1) * step + nperseg
        if spare and spare[0].shape[1] == a1 - a0:
            buf = spare.pop(0)
            block = src.read(a0, a1, out=buf)
            spare.append(buf)   # handed out again two reads later, after this block is transformed
        else:
            block = src.read(a0, a1)
        if not all_rows:
            block = block[idx]
        return block if block.dtype == dtype else block.astype(dtype)

    # a source on disk: the next block is read by an I/O thread while this one is transformed (the
    # read, the conversion to float and the first touch of the new block's pages release the GIL);
    # at most two blocks are held, and only while a block is small enough that two fit the budget
    ahead = (not isinstance(src, _ArraySource) and len(reads) > 1
             and 2 * src.n_channels * READ_SAMPLES * 8 <= PREFETCH_BYTES)
    io = _io_pool() if ahead else None
    if io is not None:
        spare += [np.empty((src.n_channels, (sb - 1) * step + nperseg)) for _ in range(2)]
    nxt = io.submit(fetch, *reads[0]) if io is not None else None
    for r, (s0, s1) in enumerate(reads):
        a0 = s0 * step
        if nxt is not None:
            block = nxt.result()
            nxt = io.submit(fetch, *reads[r + 1]) if r + 1 < len(reads) else None
        else:
            block = fetch(s0, s1)
        segs = np.lib.stride_tricks.as_strided(
            block, shape=(n_ch, s1 - s0, nperseg),
            strides=(block.strides[0], block.strides[1] * step, block.strides[1]), writeable=False)
        m = s1 - s0
        chunks = iter([(b, min(m, b + BATCH)) for b in range(0, m, BATCH)])
        fut = None
        if pool is not None and m >= 2 * BATCH:
            # this thread works too, and takes more batches when the other core is slow to start
            fut = pool.submit(work, segs, chunks, s0)
        if deferred:   # while the other thread starts
            seg_sums = _segment_totals(block, segs, step, nperseg)
        parts = [work(segs, chunks, s0)] + ([fut.result()] if fut is not None else [])
        if deferred:
            d = raw_lines[:, :m] - seg_sums[:, :, None] * W_mean
            line_power += (d.real ** 2 + d.imag ** 2).sum(axis=1)
        for au, cr in parts:
            if reducer == "sum":
                autos += au
            else:
                np.maximum(autos, au, out=autos)
            crosses += cr
        # a NaN or inf sample anywhere in a segment reaches every line of that segment's power (no
        # separate pass over the data); only then is the block searched for the first bad sample
        if not (np.isfinite(autos[:, 0]).all() and np.isfinite(autos[:, nf // 2]).all()) or \
                (per_seg is not None and not np.isfinite(per_seg[:, s0:s1, 0]).all()):
            bad = np.argwhere(~np.isfinite(block))
            if bad.size:
                bad = bad[0]
                raise ParameterError(f"channel {names[idx[bad[0]]]!r} has NaN/inf at sample {a0 + bad[1]}; the rule "
                                     "is finite data: repair or cut the record first")
            from ..core._validate import check_range
            check_range(block)  # names the peak amplitude when it is outside the range allowed everywhere
            raise ParameterError("the spectrum's power overflows double precision: the samples are too large for "
                                 "this segment length; rescale the record (choose another unit)")
        if progress is not None:
            progress(s1 / nseg)
    if deferred:
        autos[:, lines] = line_power
    return autos, crosses, nseg, per_seg


def _segment_totals(block, segs, step, nperseg):
    """Sum of every segment of a block, (n_ch, n_seg). Overlapping segments share samples: when the
    block's rows are contiguous and a segment is at most 8 parts of g = gcd(step, nperseg) samples,
    the sums are built from sums over those parts, each sample read once."""
    g = math.gcd(step, nperseg)
    q, r = step // g, nperseg // g
    n_ch, m = segs.shape[:2]
    if r > 8 or g < 32 or block.strides[1] != block.itemsize:
        return segs.sum(axis=-1, dtype=float)
    nb = (m - 1) * q + r
    parts = block[:, :nb * g].reshape(n_ch, nb, g).sum(axis=-1, dtype=float)
    tot = parts[:, 0:(m - 1) * q + 1:q].copy()
    for j in range(1, r):
        tot += parts[:, j:j + (m - 1) * q + 1:q]
    return tot


PREFETCH_BYTES = 1 << 26   # two blocks of a source on disk are held (one read ahead) when they fit in this


def _io_pool():
    """One thread that reads the next block of a source on disk."""
    global _IO_POOL
    if _IO_POOL is None:
        from concurrent.futures import ThreadPoolExecutor
        _IO_POOL = ThreadPoolExecutor(max_workers=1, thread_name_prefix="vibmeasure-read")
    return _IO_POOL


_IO_POOL = None
_POOL = None
_SCRATCH = threading.local()


SCRATCH_BYTES = 1 << 22   # work buffers up to this size are kept by each thread between calls


def _scratch(key, shape, dtype) -> np.ndarray:
    """A work buffer the calling thread keeps between calls (when it is at most SCRATCH_BYTES; a
    larger one is allocated per call). A fresh buffer of this size is mapped anew whenever other
    work has freed large arrays in between, and each of its 4 kB pages then faults on first touch:
    at 2^18 samples that cost half as much again as psd itself."""
    if np.dtype(dtype).itemsize * math.prod(shape) > SCRATCH_BYTES:
        return np.empty(shape, dtype)
    store = _SCRATCH.__dict__
    a = store.get(key)
    if a is None or a.shape != shape or a.dtype != dtype:
        a = store[key] = np.empty(shape, dtype)
    return a


def _pool():
    """Two worker threads (numpy and the FFT release the GIL) on machines with two or more cores."""
    global _POOL
    if _POOL is None:
        import os
        if (os.cpu_count() or 1) < 2:
            return None
        from concurrent.futures import ThreadPoolExecutor
        _POOL = ThreadPoolExecutor(max_workers=2, thread_name_prefix="vibmeasure-fft")
    return _POOL


def _one_sided(a, nfft):
    a = a.copy()
    hi = None if nfft % 2 else -1  # the Nyquist line of an even nfft is not doubled
    a[..., 1:hi] *= 2
    return a


def _median_bias(n):
    # median of chi^2_2 over its mean, as scipy applies it (ln 2 in the limit)
    ii_2 = 2 * np.arange(1.0, (n - 1) // 2 + 1)
    return 1 + np.sum(1.0 / (ii_2 + 1) - 1.0 / ii_2)


def _averaged_power(src, idx, *, nperseg, noverlap, nfft, win, detrend, average, progress, dtype=np.float64):
    keep = average == "median"
    if keep:
        step = nperseg - noverlap
        nseg = (src.n_samples - nperseg) // step + 1
        if len(idx) * nseg * (nfft // 2 + 1) > MEDIAN_LIMIT:
            raise ParameterError(f"average='median' keeps every segment ({nseg} x {nfft // 2 + 1} lines per channel): "
                                 "too many here; use average='mean' or a shorter record")
    autos, _, nseg, per = _segment_sums(src, idx, nperseg=nperseg, noverlap=noverlap, nfft=nfft, win=win,
                                        detrend=detrend, keep_segments=keep,
                                        reducer="max" if average == "max" else "sum", progress=progress,
                                        dtype=dtype)
    if average == "mean":
        return autos / nseg, nseg
    if average == "max":
        return autos, nseg
    return np.median(per, axis=1) / _median_bias(nseg), nseg


def _meta(src, idx):
    ch = [src.channels[i] for i in idx]
    units = {c.unit for c in ch}
    quants = {c.quantity for c in ch}
    return ch, (units.pop() if len(units) == 1 else ""), (quants.pop() if len(quants) == 1 else "unknown")


# ------------------------------------------------------------------------------------------------
@memory_guard
def psd(rec, *, nperseg: int | None = None, noverlap: int | None = None, window="hann", detrend="constant",
        average: str = "mean", scaling: str = "density", nfft: int | None = None, channels=None,
        fs: float | None = None, progress: Callable[[float], None] | None = None, dtype=None) -> Spectrum:
    """Welch power spectral density (or power spectrum) of every channel.

    ``scaling="density"`` gives unit^2/Hz (energy-corrected with sum(w^2): Parseval holds, the
    integral over frequency is the variance); ``"spectrum"`` gives unit^2 per line (amplitude-
    corrected with sum(w)^2: a sine of amplitude A reads A^2/2). ``average`` "mean", "median"
    (bias-corrected like scipy) or "max" (peak hold). Defaults: nperseg min(n, 4096), 50 % overlap,
    Hann, constant detrend. ``rec`` may be a Record, a LazyRecord (streamed from disk) or an array
    with ``fs``; ``progress(fraction)`` is called as blocks finish. ``dtype="float32"`` computes in
    single precision (half the memory and FFT work; about 1e-6 relative error): use it for float32
    recordings whose dynamic range is below about 120 dB. The default is float64.
    """
    src = _source(rec, fs, check=False)
    dtype = _check_dtype(dtype)
    nperseg, noverlap, nfft = _check_params(src.n_samples, nperseg, noverlap, nfft, detrend, average, 4096)
    if scaling not in ("density", "spectrum"):
        raise ParameterError(f"scaling={scaling!r} must be 'density' or 'spectrum'")
    idx = _channel_indices(src, channels)
    win = get_window(window, nperseg)
    P, nseg = _averaged_power(src, idx, nperseg=nperseg, noverlap=noverlap, nfft=nfft, win=win, detrend=detrend,
                              average=average, progress=progress, dtype=dtype)
    if isinstance(src, _ArraySource):
        # a channel whose powers are near the ends of double precision: only then are its samples
        # searched (amplitudes within 1e-150..1e150 are allowed, as everywhere; zeros give zeros)
        from ..core._validate import check_range
        for k in np.flatnonzero(~((P.max(axis=1) > 1e-250) & (P.max(axis=1) < 1e250))):
            check_range(src.rec.data[idx[k]], what=f"channel {src.channels[idx[k]].name!r}")
    scale = 1.0 / (src.fs * (win @ win)) if scaling == "density" else 1.0 / win.sum() ** 2
    P = _one_sided(P * scale, nfft)
    ch, unit, q = _meta(src, idx)
    enbw = src.fs * (win @ win) / win.sum() ** 2
    return Spectrum(np.fft.rfftfreq(nfft, 1 / src.fs), P, "psd" if scaling == "density" else "power",
                    power_unit(unit, density=scaling == "density"), tuple(c.name for c in ch), q,
                    {"window": window if isinstance(window, (str, tuple)) else "array", "nperseg": nperseg,
                     "noverlap": noverlap, "nfft": nfft, "detrend": detrend, "average": average, "fs": src.fs,
                     "n_averages": nseg, "enbw_hz": enbw, "scaling": scaling})


@memory_guard
def amplitude_spectrum(rec, *, window="hann", nfft: int | None = None, scaling: str = "peak",
                       nperseg: int | None = None, noverlap: int | None = None, average: str = "mean",
                       detrend="constant", channels=None, fs: float | None = None,
                       progress: Callable[[float], None] | None = None) -> Spectrum:
    """Single-sided, amplitude-correct spectrum: a sine of amplitude A reads A at its frequency.

    The window correction is computed from the actual window (2 / sum(w)), not from a table.
    ``scaling`` "peak", "rms" (peak / sqrt 2) or "peak-to-peak". With ``nperseg`` the segments are
    averaged in power ("mean", "median") or held ("max"); without it the whole record is one
    segment (a lazy record defaults to 65536-sample segments). ``nfft`` zero-pads.
    """
    from ..io.lazy import LazyRecord
    src = _source(rec, fs)
    if scaling not in ("peak", "rms", "peak-to-peak"):
        raise ParameterError(f"scaling={scaling!r} must be 'peak', 'rms' or 'peak-to-peak'")
    default = 65536 if isinstance(src, LazyRecord) else src.n_samples
    nperseg, noverlap, nfft = _check_params(src.n_samples, nperseg, noverlap, nfft, detrend, average, default)
    idx = _channel_indices(src, channels)
    win = get_window(window, nperseg)
    P, nseg = _averaged_power(src, idx, nperseg=nperseg, noverlap=noverlap, nfft=nfft, win=win, detrend=detrend,
                              average=average, progress=progress)
    A = np.sqrt(P) / win.sum()
    A[:, 1:None if nfft % 2 else -1] *= 2
    A *= {"peak": 1.0, "rms": 1 / np.sqrt(2), "peak-to-peak": 2.0}[scaling]
    if scaling == "rms":
        A[:, 0] *= np.sqrt(2)  # a constant's rms is itself
    ch, unit, q = _meta(src, idx)
    return Spectrum(np.fft.rfftfreq(nfft, 1 / src.fs), A, "amplitude", unit, tuple(c.name for c in ch), q,
                    {"window": window if isinstance(window, (str, tuple)) else "array", "nperseg": nperseg,
                     "noverlap": noverlap, "nfft": nfft, "detrend": detrend, "average": average, "fs": src.fs,
                     "n_averages": nseg, "scaling": scaling,
                     "enbw_hz": src.fs * (win @ win) / win.sum() ** 2})


def _pair_spectra(rec, x, y, nperseg, noverlap, window, detrend, nfft, fs, progress):
    src = _source(rec, fs)
    nperseg, noverlap, nfft = _check_params(src.n_samples, nperseg, noverlap, nfft, detrend, "mean", 4096)
    ix, iy = _channel_indices(src, [x, y])
    win = get_window(window, nperseg)
    autos, cross, nseg, _ = _segment_sums(src, [ix, iy], nperseg=nperseg, noverlap=noverlap, nfft=nfft, win=win,
                                          detrend=detrend, pairs=[(0, 1)], progress=progress)
    scale = 1.0 / (src.fs * (win @ win))
    return src, ix, iy, _one_sided(autos / nseg * scale, nfft), _one_sided(cross / nseg * scale, nfft), nseg, \
        dict(nperseg=nperseg, noverlap=noverlap, nfft=nfft)


def csd(rec, x, y, *, nperseg: int | None = None, noverlap: int | None = None, window="hann",
        detrend="constant", nfft: int | None = None, fs: float | None = None, progress=None) -> Spectrum:
    """Cross spectral density S_xy = E[conj(X) Y] (scipy's convention) between channels x and y."""
    src, ix, iy, autos, cross, nseg, p = _pair_spectra(rec, x, y, nperseg, noverlap, window, detrend, nfft, fs,
                                                        progress)
    cx, cy = src.channels[ix], src.channels[iy]
    unit = f"{cx.unit}*{cy.unit}/Hz" if cx.unit or cy.unit else "1/Hz"
    return Spectrum(np.fft.rfftfreq(p["nfft"], 1 / src.fs), cross.conj(), "csd", unit, (f"{cx.name}*{cy.name}",),
                    "unknown", dict(p, window=window, detrend=detrend, fs=src.fs, n_averages=nseg))


def coherence(rec, x, y, *, nperseg: int | None = None, noverlap: int | None = None, window="hann",
              detrend="constant", nfft: int | None = None, fs: float | None = None, progress=None) -> Spectrum:
    """Magnitude-squared coherence |S_xy|^2 / (S_xx S_yy) between channels x and y (needs >= 2 averages)."""
    src, ix, iy, autos, cross, nseg, p = _pair_spectra(rec, x, y, nperseg, noverlap, window, detrend, nfft, fs,
                                                        progress)
    if nseg < 2:
        raise ParameterError(f"coherence needs at least 2 averages; nperseg={p['nperseg']} gives {nseg}: "
                             "use a shorter nperseg")
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.abs(cross[0]) ** 2 / (autos[0] * autos[1])
    c = np.where(np.isfinite(c), c, 0.0)
    return Spectrum(np.fft.rfftfreq(p["nfft"], 1 / src.fs), c, "coherence", "",
                    (f"{src.channels[ix].name}~{src.channels[iy].name}",), "unknown",
                    dict(p, window=window, detrend=detrend, fs=src.fs, n_averages=nseg))


@memory_guard
def spectrogram(rec, *, channel=None, nperseg: int | None = None, noverlap: int | None = None, window="hann",
                detrend="constant", nfft: int | None = None, fs: float | None = None) -> Spectrogram:
    """Power spectral density of each segment over time (a waterfall): values (1, n_freq, n_times)."""
    src = _source(rec, fs)
    nperseg, noverlap, nfft = _check_params(src.n_samples, nperseg, noverlap, nfft, detrend, "mean", 1024)
    idx = _channel_indices(src, 0 if channel is None else channel)
    win = get_window(window, nperseg)
    step = nperseg - noverlap
    nseg = (src.n_samples - nperseg) // step + 1
    if nseg * (nfft // 2 + 1) > MEDIAN_LIMIT:
        raise ParameterError(f"spectrogram of {nseg} segments x {nfft // 2 + 1} lines is too large: "
                             "raise nperseg or lower the overlap")
    _, _, _, per = _segment_sums(src, idx, nperseg=nperseg, noverlap=noverlap, nfft=nfft, win=win,
                                 detrend=detrend, keep_segments=True)
    S = _one_sided(per / (src.fs * (win @ win)), nfft)  # (1, nseg, nf)
    times = (np.arange(nseg) * step + nperseg / 2) / src.fs
    ch, unit, _ = _meta(src, idx)
    return Spectrogram(np.fft.rfftfreq(nfft, 1 / src.fs), times, np.transpose(S, (0, 2, 1)),
                       power_unit(unit, density=True), (ch[0].name,),
                       {"window": window, "nperseg": nperseg, "noverlap": noverlap, "nfft": nfft, "fs": src.fs})


# ------------------------------------------------------------------------------------------------
def _as_density(obj, fs=None, **kw) -> Spectrum:
    if isinstance(obj, Spectrum):
        if obj.kind != "psd":
            raise ParameterError(f"band RMS needs a power spectral density (kind 'psd'), got kind {obj.kind!r}")
        return obj
    return psd(obj, fs=fs, **kw)


def _band_power(spec: Spectrum, lo: float, hi: float) -> np.ndarray:
    """Integral of a density over [lo, hi], each line covering +-df/2 and counted in part."""
    f, df = spec.freq, spec.df
    left = np.clip(f - df / 2, 0, None)
    right = f + df / 2
    frac = np.clip((np.minimum(right, hi) - np.maximum(left, lo)) / df, 0, 1)
    return spec.values.real @ frac * df


def band_rms(obj, band, *, fs: float | None = None, nperseg: int | None = None) -> np.ndarray:
    """RMS of each channel in a frequency band (lo, hi) Hz, from its PSD (a Spectrum or a record).

    Lines at the band edges count in part. ``band=(0, fs/2)`` gives the overall RMS less the mean.
    """
    spec = _as_density(obj, fs=fs, nperseg=nperseg)
    lo, hi = _check_band(band, spec.params.get("fs", 2 * spec.freq[-1]))
    return np.sqrt(_band_power(spec, lo, hi))


def octave_bands(obj, *, fraction: int = 3, band=None, fs: float | None = None, nperseg: int | None = None):
    """RMS in 1/1 or 1/3 octave bands (base-10 IEC 61260-1 mid-band frequencies), from the PSD.

    Returns a pandas table: center_hz, lower_hz, upper_hz, lines (PSD lines inside the band: below 2
    the band is narrower than the resolution) and one rms column per channel. Bands must lie
    inside (df, fs/2) or ``band``.
    """
    import pandas as pd
    if fraction not in (1, 3):
        raise ParameterError(f"fraction={fraction!r} must be 1 (octave) or 3 (third octave)")
    spec = _as_density(obj, fs=fs, nperseg=nperseg)
    f_hi_lim = spec.freq[-1]
    lo_lim, hi_lim = (spec.df, f_hi_lim) if band is None else _check_band(band, 2 * f_hi_lim)
    G = 10 ** 0.3
    rows = []
    for x in range(-60, 60):
        fm = 1000 * G ** (x / fraction)
        fl, fu = fm * G ** (-1 / (2 * fraction)), fm * G ** (1 / (2 * fraction))
        if fl < lo_lim or fu > hi_lim:
            continue
        pw = _band_power(spec, fl, fu)
        rows.append({"center_hz": fm, "lower_hz": fl, "upper_hz": fu,
                     "lines": int(np.sum((spec.freq >= fl) & (spec.freq < fu))),
                     **{f"rms_{c}": float(np.sqrt(p)) for c, p in zip(spec.channels, pw)}})
    if not rows:
        raise ParameterError(f"no {'octave' if fraction == 1 else 'third-octave'} band fits between "
                             f"{lo_lim:g} and {hi_lim:g} Hz")
    return pd.DataFrame(rows)
