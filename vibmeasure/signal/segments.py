"""The segment engine every averaged spectrum reduces to (psd, csd, coherence, spectrogram, FRFs).

``segment_sums`` reads as its steps: plan the segments and the window's DFT lines (``_plan``), read
the source block by block with the next block read ahead from disk (``_blocks``), transform each
block's segments in batches shared by two threads (``_batch_sums``), fold in the deferred detrend of
the window's lines, and check that the powers stayed finite (``_check_finite``).

For windows whose DFT has a few lines only (the cosine-sum family: Hann, Hamming, Blackman, flat-top,
boxcar) the constant detrend is applied to those lines of the transform (linearity: removing a
segment's mean m changes line k by m W[k]), not to every sample.
"""

from __future__ import annotations

import functools
import math
import threading
from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.fft as _fft

from ..core.errors import ParameterError
from ..core.record import Record

__all__ = ["segment_sums"]

BATCH = 16              # segments per channel transformed together: fits the cache, amortises call overhead
READ_SAMPLES = 1 << 21  # samples per channel read from a lazy source at a time
PREFETCH_BYTES = 1 << 26   # two blocks of a source on disk are held (one read ahead) when they fit in this
SCRATCH_BYTES = 1 << 22   # work buffers up to this size are kept by each thread between calls
# numpy >= 2 transforms into a reused buffer (out=) with less Python around the call than scipy.fft;
# with two threads sharing the batches, every Python step holds the GIL the other thread waits for
# (one A/B at 2^18 samples, interleaved with welch: 1.9-2.1 against 2.2-2.3 ms)
_NUMPY_FFT_OUT = np.lib.NumpyVersion(np.__version__) >= "2.0.0"

_IO_POOL = None
_POOL = None
_SCRATCH = threading.local()


class _ArraySource:
    """An in-memory record seen through the lazy-source interface (reads are views)."""

    def __init__(self, rec: Record):
        self.rec = rec
        self.fs, self.channels, self.n_samples, self.n_channels = rec.fs, rec.channels, rec.n_samples, rec.n_channels

    def read(self, start, stop):
        return self.rec.data[:, start:stop]


@functools.lru_cache(maxsize=32)
def _window_lines(key: bytes, nperseg: int, nfft: int):
    """The DFT lines of a window (padded to nfft) that are not zero: (indices, values)."""
    win = np.frombuffer(key, float)
    W = _fft.rfft(np.r_[win, np.zeros(nfft - nperseg)])
    lines = np.flatnonzero(np.abs(W) > 1e-12 * np.abs(W).max())
    return lines, W[lines]


@dataclass(frozen=True)
class _Plan:
    """What every batch of one call shares: segment geometry, window, detrend and reduction."""
    nperseg: int
    nfft: int
    step: int
    nseg: int
    nf: int
    n_ch: int
    sb: int              # segments per read
    win: np.ndarray
    detrend: object
    tt: np.ndarray | None
    pairs: tuple
    reducer: str
    keep: bool
    dtype: object
    lines: object        # the window's DFT lines (indices, or a slice when contiguous)
    W_mean: np.ndarray   # their values per unit segment sum
    sparse: bool         # the constant detrend is applied to those lines only
    deferred: bool       # ... and once per block, from the segment sums


def _plan(src, idx, nperseg, noverlap, nfft, win, detrend, pairs, keep, reducer, dtype) -> _Plan:
    step = nperseg - noverlap
    tt = None
    if detrend == "linear":
        tt = np.arange(nperseg) - (nperseg - 1) / 2
        tt = tt / np.sqrt(tt @ tt)
    win = win.astype(dtype)  # float32 segments stay float32 through the FFT (sums are kept in float64)
    lines, W_lines = _window_lines(np.ascontiguousarray(win, float).tobytes(), nperseg, nfft)
    sparse = detrend == "constant" and lines.size <= 8
    W_mean = (W_lines / nperseg).astype(np.complex64 if dtype == np.float32 else complex)  # per unit segment sum
    if sparse and lines.size and np.array_equal(lines, np.arange(lines[0], lines[-1] + 1)):
        lines = slice(int(lines[0]), int(lines[-1]) + 1)   # contiguous lines: a view, not a gather
    # Summed powers only: the threads keep each segment's raw values at those lines, and the lines are
    # detrended once at the end from the segment sums (a few operations per block instead of three per
    # batch: each numpy call that releases the GIL makes the two threads hand it over, and at 2^18
    # samples those hand-overs cost more than the arithmetic)
    deferred = sparse and reducer == "sum" and not keep and not pairs
    return _Plan(nperseg, nfft, step, (src.n_samples - nperseg) // step + 1, nfft // 2 + 1, len(idx),
                 max(1, (READ_SAMPLES - nperseg) // step + 1), win, detrend, tt, tuple(pairs), reducer, keep,
                 dtype, lines, W_mean, sparse, deferred)


def segment_sums(src, idx, *, nperseg, noverlap, nfft, win, detrend, pairs=(), keep_segments=False,
                 reducer="sum", progress: Callable[[float], None] | None = None, dtype=np.float64):
    """Sum (or max) over Welch segments of |X|^2 per channel and of X_i conj(X_j) per channel pair.

    Parameters
    ----------
    src : record source
        An in-memory source (``_ArraySource``) or a ``vm.LazyRecord``: ``n_samples``, ``n_channels``,
        ``channels`` and ``read(start, stop)``.
    idx : list of int
        The channels to transform.
    nperseg, noverlap, nfft : int
        Segment length, overlap and FFT length (checked by ``spectral.check_segment_params``).
    win : numpy.ndarray
        The window, nperseg values.
    detrend : {"constant", "linear", False, None}
        What each segment loses before it is windowed.
    pairs : sequence of (int, int)
        Positions in ``idx`` whose cross products are summed.
    keep_segments : bool
        Also return every segment's power (for median averaging).
    reducer : {"sum", "max"}
        Sum the powers (averaging) or keep their maximum (peak hold).
    progress : callable, optional
        Called with the share of segments done.
    dtype : numpy float type
        float32 computes in single precision (sums kept in float64).

    Returns
    -------
    tuple
        (autos (n_idx, nf), crosses (n_pairs, nf) complex, n_segments, per-segment powers or None).

    Raises
    ------
    ParameterError
        When a sample is NaN or inf (naming the channel and sample), or the powers overflow.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure.signal.segments import _ArraySource, segment_sums
    >>> rec = vm.Record.from_array(np.ones(1024), fs=1000.0)
    >>> autos, _, nseg, _ = segment_sums(_ArraySource(rec), [0], nperseg=256, noverlap=128, nfft=256,
    ...                                  win=np.hanning(256), detrend="constant")
    >>> nseg, float(autos.max()) < 1e-20
    (7, True)
    """
    p = _plan(src, idx, nperseg, noverlap, nfft, win, detrend, pairs, keep_segments, reducer, dtype)
    per_seg = np.empty((p.n_ch, p.nseg, p.nf)) if p.keep else None
    autos = np.zeros((p.n_ch, p.nf)) if p.reducer == "sum" else np.full((p.n_ch, p.nf), -np.inf)
    crosses = np.zeros((len(p.pairs), p.nf), complex)
    raw_lines = line_power = None
    if p.deferred:
        raw_lines = np.empty((p.n_ch, min(p.sb, p.nseg), np.arange(p.nf)[p.lines].size), complex)  # one block's
        line_power = np.zeros(raw_lines.shape[::2])    # detrended power at those lines, summed
    names = [c.name for c in src.channels]
    for s0, s1, block in _blocks(src, idx, p):
        segs = np.lib.stride_tricks.as_strided(
            block, shape=(p.n_ch, s1 - s0, p.nperseg),
            strides=(block.strides[0], block.strides[1] * p.step, block.strides[1]), writeable=False)
        for au, cr, lp in _block_sums(p, block, segs, s0, per_seg, raw_lines):
            if p.reducer == "sum":
                autos += au
            else:
                np.maximum(autos, au, out=autos)
            crosses += cr
            if lp is not None:
                line_power += lp
        _check_finite(autos, per_seg, s0, s1, block, idx, names, p)
        if progress is not None:
            progress(s1 / p.nseg)
    if p.deferred:
        autos[:, p.lines] = line_power
    return autos, crosses, p.nseg, per_seg


def _block_sums(p: _Plan, block, segs, s0, per_seg, raw_lines):
    """The sums over one block's segments: the batches shared between this thread and a worker (this
    thread works too, and takes more batches when the other core is slow to start); with the deferred
    detrend, the detrended power at the window's lines as a third part."""
    m = segs.shape[1]
    chunks = iter([(b, min(m, b + BATCH)) for b in range(0, m, BATCH)])
    pool = _pool()
    fut = pool.submit(_batch_sums, p, segs, chunks, s0, per_seg, raw_lines) if pool is not None and \
        m >= 2 * BATCH else None
    seg_sums = _segment_totals(block, segs, p.step, p.nperseg) if p.deferred else None   # while the other starts
    parts = [_batch_sums(p, segs, chunks, s0, per_seg, raw_lines)] + ([fut.result()] if fut is not None else [])
    lp = None
    if p.deferred:
        d = raw_lines[:, :m] - seg_sums[:, :, None] * p.W_mean
        lp = (d.real ** 2 + d.imag ** 2).sum(axis=1)
    return [(au, cr, lp if k == 0 else None) for k, (au, cr) in enumerate(parts)]


def _batch_sums(p: _Plan, segs, chunks, s0, per_seg, raw_lines):
    """Sums over the segment batches this thread takes from the shared chunk iterator (powers that
    overflow become inf, found after the block: no numpy warning on the way)."""
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        au = np.zeros((p.n_ch, 2 * p.nf)) if p.reducer == "sum" else np.full((p.n_ch, p.nf), -np.inf)
        cr = np.zeros((len(p.pairs), p.nf), complex)
        bufs = _buffers(p)
        for b0, b1 in chunks:   # list iterators hand out each chunk once, also across threads (GIL)
            Xs = []
            for c in range(p.n_ch):
                X, y = _transform(p, segs[c, b0:b1], bufs)
                if p.deferred:
                    raw_lines[c, b0:b1] = X[:, p.lines]
                elif p.sparse:
                    X[:, p.lines] -= np.multiply.outer(y.sum(axis=-1), p.W_mean)
                if p.pairs:   # the power is squared in place and the buffer is the next channel's: a copy
                    Xs.append(X.copy() if p.reducer == "sum" and not p.keep or bufs[2] is not None else X)
                _add_power(p, X, c, b0, b1, s0, au, per_seg)
            for k, (i, j) in enumerate(p.pairs):
                cr[k] += (Xs[i] * Xs[j].conj()).sum(axis=0)
        if p.reducer == "sum":
            au = au.reshape(p.n_ch, p.nf, 2).sum(axis=2) if not p.keep else au[:, :p.nf]
        return au, cr


def _buffers(p: _Plan):
    """This thread's windowed batch, zero-padded batch and transformed batch, reused between calls."""
    buf = _scratch("win", (BATCH, p.nperseg), p.dtype)
    pad = None
    if p.nfft > p.nperseg:
        pad = _scratch("pad", (BATCH, p.nfft), p.dtype)
        pad[:, p.nperseg:] = 0
    out = (_scratch("fft", (BATCH, p.nf), np.complex64 if p.dtype == np.float32 else complex)
           if _NUMPY_FFT_OUT else None)
    return buf, pad, out


def _transform(p: _Plan, y, bufs):
    """One channel's batch of segments detrended (unless the detrend goes to the window's lines),
    windowed and transformed: (X, the segments as detrended)."""
    buf, pad, out = bufs
    m = y.shape[0]
    if not p.sparse:
        if p.detrend == "constant":
            y = y - y.mean(axis=-1, keepdims=True)
        elif p.detrend == "linear":
            y = y - y.mean(axis=-1, keepdims=True)
            y = y - (y @ p.tt)[:, None] * p.tt
    yw = np.multiply(y, p.win, out=buf[:m])
    if pad is not None:
        pad[:m, :p.nperseg] = yw
        yw = pad[:m]
    X = np.fft.rfft(yw, axis=-1, out=out[:m]) if out is not None else _fft.rfft(yw, axis=-1)
    return X, y


def _add_power(p: _Plan, X, c, b0, b1, s0, au, per_seg) -> None:
    """Adds one channel's batch power to the sums (or the maximum), and keeps each segment's power
    when asked."""
    m = b1 - b0
    if p.reducer == "sum" and not p.keep:
        v = X.view(X.real.dtype).reshape(m, 2 * p.nf)   # re, im interleaved, squared in place
        np.square(v, out=v)
        au[c] += v.sum(axis=0, dtype=float)
        return
    P = X.real ** 2 + X.imag ** 2
    if p.keep:
        per_seg[c, s0 + b0:s0 + b1] = P
    if p.reducer == "sum":
        au[c, :p.nf] += P.sum(axis=0)
    else:
        np.maximum(au[c], P.max(axis=0), out=au[c])


def _blocks(src, idx, p: _Plan):
    """(first segment, last segment + 1, block) for every read of the source. A source on disk has
    the next block read by an I/O thread while this one is transformed (the read, the conversion to
    float and the first touch of the new block's pages release the GIL); at most two blocks are held,
    and only while a block is small enough that two fit the budget."""
    reads = [(s0, min(p.nseg, s0 + p.sb)) for s0 in range(0, p.nseg, p.sb)]
    all_rows = list(idx) == list(range(src.n_channels))
    spare = []   # two float64 blocks a source on disk is read into, in turn (no fresh 16 MB per read)

    def fetch(s0, s1):
        a0, a1 = s0 * p.step, (s1 - 1) * p.step + p.nperseg
        if spare and spare[0].shape[1] == a1 - a0:
            buf = spare.pop(0)
            block = src.read(a0, a1, out=buf)
            spare.append(buf)   # handed out again two reads later, after this block is transformed
        else:
            block = src.read(a0, a1)
        if not all_rows:
            block = block[idx]
        return block if block.dtype == p.dtype else block.astype(p.dtype)

    ahead = (not isinstance(src, _ArraySource) and len(reads) > 1
             and 2 * src.n_channels * READ_SAMPLES * 8 <= PREFETCH_BYTES)
    io = _io_pool() if ahead else None
    if io is not None:
        spare += [np.empty((src.n_channels, (p.sb - 1) * p.step + p.nperseg)) for _ in range(2)]
    nxt = io.submit(fetch, *reads[0]) if io is not None else None
    for r, (s0, s1) in enumerate(reads):
        if nxt is not None:
            block = nxt.result()
            nxt = io.submit(fetch, *reads[r + 1]) if r + 1 < len(reads) else None
        else:
            block = fetch(s0, s1)
        yield s0, s1, block


def _check_finite(autos, per_seg, s0, s1, block, idx, names, p: _Plan) -> None:
    """A NaN or inf sample anywhere in a segment reaches every line of that segment's power (no
    separate pass over the data); only then is the block searched for the first bad sample."""
    if np.isfinite(autos[:, 0]).all() and np.isfinite(autos[:, p.nf // 2]).all() and \
            (per_seg is None or np.isfinite(per_seg[:, s0:s1, 0]).all()):
        return
    bad = np.argwhere(~np.isfinite(block))
    if bad.size:
        bad = bad[0]
        raise ParameterError(f"channel {names[idx[bad[0]]]!r} has NaN/inf at sample {s0 * p.step + bad[1]}; the "
                             "rule is finite data: repair or cut the record first")
    from ..core._validate import check_range
    check_range(block)  # names the peak amplitude when it is outside the range allowed everywhere
    raise ParameterError("the spectrum's power overflows double precision: the samples are too large for "
                         "this segment length; rescale the record (choose another unit)")


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


def _io_pool():
    """One thread that reads the next block of a source on disk."""
    global _IO_POOL
    if _IO_POOL is None:
        from concurrent.futures import ThreadPoolExecutor
        _IO_POOL = ThreadPoolExecutor(max_workers=1, thread_name_prefix="vibmeasure-read")
    return _IO_POOL


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
