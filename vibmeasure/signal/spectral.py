"""Amplitude-correct spectra, PSD, CSD, coherence, spectrogram, band and octave RMS.

All segment-averaged estimates reduce to one blocked engine (:func:`segment_sums`): segments are
taken as strided views, windowed and transformed 16 at a time (cache-sized batches, shared between
the calling thread and one worker), and their power or cross products are summed. For windows
whose DFT has a few lines only (the cosine-sum family: Hann, Hamming, Blackman, flat-top, boxcar)
the constant detrend is applied to those lines of the transform (linearity), not to every sample. The same engine streams a
:class:`~vibmeasure.io.LazyRecord` from disk in bounded blocks, so a recording larger than memory
is handled like one in memory. Results equal ``scipy.signal.welch``/``csd`` to round-off.
"""

from __future__ import annotations

import functools
from typing import Callable

import numpy as np
from scipy import fft as _fft
from scipy import signal as _sig

from ..core._validate import memory_guard, select_names
from ..core.errors import ParameterError
from ..core.results import Spectrogram, Spectrum
from .segments import _ArraySource, segment_sums

__all__ = ["amplitude_spectrum", "psd", "csd", "coherence", "spectrogram", "power_unit", "get_window", "segment_sums", "check_segment_params", "symmetric_window"]

MEDIAN_LIMIT = 20_000_000  # per-segment values kept for median averaging


# ------------------------------------------------------------------------------------------------
# sources and checks
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


def fast_len_below(n: int, *, real: bool = True) -> int:
    """The largest length <= n whose FFT is fast: prime factors 2, 3 and 5 (``real``: the rfft's
    radices), or 2 to 11. A length with a large prime factor costs 5-20 x as much per FFT (CWRU's
    120,801 samples = 3 x 67 x 601: 22 ms per rfft against 4 ms at 120,736 = 2^5 x 7^3 x 11).

    Parameters
    ----------
    n : int
        A length >= 1.
    real : bool
        Only 2, 3 and 5 as factors (at most 2.8 % shorter from 10^5 samples on), else 2 to 11
        (at most 0.8 % shorter from 10^5 on, 1.6 % from 10^4).

    Returns
    -------
    int

    Raises
    ------
    ParameterError
        For n not a whole number >= 1.

    Examples
    --------
    >>> from vibmeasure.signal.spectral import fast_len_below
    >>> fast_len_below(120801), fast_len_below(120801, real=False)
    (120000, 120736)
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ParameterError(f"n={n!r} must be a whole number >= 1")
    m = int(n)
    while m > 1 and _fft.next_fast_len(m, real=real) != m:
        m -= 1
    return m


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


def symmetric_window(window: str, n: int) -> np.ndarray:
    """A symmetric window of length n ("hann": np.hanning's; else scipy's with fftbins=False), read-only.

    One diagnosis windows the same record length a dozen times and each envelope band's length twice:
    the last 32 windows up to 2^17 samples and the last four up to 2^20 are kept (64 MiB at most),
    longer ones are computed each time.

    Examples
    --------
    >>> from vibmeasure.signal.spectral import symmetric_window
    >>> w = symmetric_window("hann", 5)
    >>> w.tolist(), w.flags.writeable
    ([0.0, 0.5, 1.0, 0.5, 0.0], False)
    """
    n = int(n)
    if n <= 2 ** 17:
        return _symmetric_short(window, n)
    return _symmetric(window, n) if n <= 2 ** 20 else _symmetric.__wrapped__(window, n)


def _window(window: str, n: int) -> np.ndarray:
    w = np.hanning(n) if window == "hann" else _sig.get_window(window, n, fftbins=False)
    w.flags.writeable = False
    return w


# a record's envelope spectra window a dozen band lengths or more, each up to 2^17 samples: their last 32
# are kept (32 MiB at most); whole records, up to 2^20 samples, their last four (32 MiB)
_symmetric_short = functools.lru_cache(maxsize=32)(_window)
_symmetric = functools.lru_cache(maxsize=4)(_window)


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


def check_segment_params(n, nperseg, noverlap, nfft, detrend, average, default_nperseg):
    """Checked Welch segment parameters: (nperseg, noverlap, nfft) for a record of n samples, or a
    ParameterError naming the argument and its rule; the one check psd, csd and estimate_frf share."""
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
    autos, _, nseg, per = segment_sums(src, idx, nperseg=nperseg, noverlap=noverlap, nfft=nfft, win=win,
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

    ``scaling="density"`` gives unit^2/Hz (energy-corrected with sum(w^2): Parseval holds, the integral
    over frequency is the variance); ``"spectrum"`` gives unit^2 per line (a sine of amplitude A reads
    A^2/2). Equal to ``scipy.signal.welch`` to round-off, faster (docs/methods/spectra.md).

    Parameters
    ----------
    rec : Record, LazyRecord or array_like
        The record (a lazy record is streamed from disk; an array needs ``fs``).
    nperseg : int, optional
        Segment length (default min(n, 4096)).
    noverlap : int, optional
        Overlap (default nperseg // 2).
    window : str, tuple or array_like
        Window (default Hann).
    detrend : {"constant", "linear", False}
        What each segment loses first.
    average : {"mean", "median", "max"}
        Mean, median (bias-corrected like scipy) or peak hold.
    scaling : {"density", "spectrum"}
        Density or power per line.
    nfft : int, optional
        FFT length (zero-padding).
    channels : str, int or list, optional
        Channels to analyse (default all).
    fs : float, optional
        Sampling rate for an array.
    progress : callable, optional
        ``progress(fraction)`` as blocks finish.
    dtype : {"float64", "float32"}, optional
        float32 halves memory and FFT work (about 1e-6 relative error).

    Returns
    -------
    Spectrum
        Of kind "psd" (unit^2/Hz) or "power".

    Raises
    ------
    ParameterError
        For bad parameters, NaN or inf samples, or too short a record.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> rec = vm.Record.from_array(np.random.default_rng(1).normal(size=2 ** 14), fs=1000.0, unit="g")
    >>> p = vm.psd(rec, nperseg=1024)
    >>> round(float(np.sum(p.values[0]) * p.df), 1)   # the variance
    1.0
    """
    src = _source(rec, fs, check=False)
    dtype = _check_dtype(dtype)
    nperseg, noverlap, nfft = check_segment_params(src.n_samples, nperseg, noverlap, nfft, detrend, average, 4096)
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

    The window correction is computed from the actual window (2 / sum(w)), not from a table. With
    ``nperseg`` the segments are averaged in power ("mean", "median") or held ("max"); without it the
    whole record is one segment (a lazy record defaults to 65536-sample segments).

    Parameters
    ----------
    rec : Record, LazyRecord or array_like
        The record (an array needs ``fs``).
    window : str, tuple or array_like
        Window name ("hann", "flattop", ...), ("kaiser", beta) or the window's values.
    nfft : int, optional
        FFT length (zero-padding).
    scaling : {"peak", "rms", "peak-to-peak"}
        What a line reads for a sine.
    nperseg, noverlap : int, optional
        Segment length and overlap for averaging.
    average : {"mean", "median", "max"}
        How segments are combined.
    detrend : {"constant", "linear", False}
        What each segment loses first.
    channels : str, int or list, optional
        Channels to analyse (default all).
    fs : float, optional
        Sampling rate for an array.
    progress : callable, optional
        ``progress(fraction)`` as blocks finish.

    Returns
    -------
    Spectrum
        Of kind "amplitude", in the channels' unit.

    Raises
    ------
    ParameterError
        For bad parameters or data (NaN, inf, too short).

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> t = np.arange(4096) / 1024.0
    >>> rec = vm.Record.from_array(2.0 * np.sin(2 * np.pi * 100.0 * t), fs=1024.0, unit="g")
    >>> spec = vm.amplitude_spectrum(rec)
    >>> round(float(spec.values[0].max()), 3)
    2.0
    """
    from ..io.lazy import LazyRecord
    src = _source(rec, fs)
    if scaling not in ("peak", "rms", "peak-to-peak"):
        raise ParameterError(f"scaling={scaling!r} must be 'peak', 'rms' or 'peak-to-peak'")
    default = 65536 if isinstance(src, LazyRecord) else src.n_samples
    nperseg, noverlap, nfft = check_segment_params(src.n_samples, nperseg, noverlap, nfft, detrend, average, default)
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
    nperseg, noverlap, nfft = check_segment_params(src.n_samples, nperseg, noverlap, nfft, detrend, "mean", 4096)
    ix, iy = _channel_indices(src, [x, y])
    win = get_window(window, nperseg)
    autos, cross, nseg, _ = segment_sums(src, [ix, iy], nperseg=nperseg, noverlap=noverlap, nfft=nfft, win=win,
                                          detrend=detrend, pairs=[(0, 1)], progress=progress)
    scale = 1.0 / (src.fs * (win @ win))
    return src, ix, iy, _one_sided(autos / nseg * scale, nfft), _one_sided(cross / nseg * scale, nfft), nseg, \
        dict(nperseg=nperseg, noverlap=noverlap, nfft=nfft)


def csd(rec, x, y, *, nperseg: int | None = None, noverlap: int | None = None, window="hann",
        detrend="constant", nfft: int | None = None, fs: float | None = None, progress=None) -> Spectrum:
    """Cross spectral density S_xy = E[conj(X) Y] (scipy's convention) between two channels.

    Parameters
    ----------
    rec : Record, LazyRecord or array_like
        The record.
    x, y : str or int
        The two channels.
    nperseg, noverlap : int, optional
        Segment length and overlap (defaults as ``psd``).
    window : str, tuple or array_like
        Window (default Hann).
    detrend : {"constant", "linear", False}
        What each segment loses first.
    nfft : int, optional
        FFT length.
    fs : float, optional
        Sampling rate for an array.
    progress : callable, optional
        ``progress(fraction)`` as blocks finish.

    Returns
    -------
    Spectrum
        Complex, of kind "csd".

    Raises
    ------
    ParameterError
        For unknown channels or bad parameters.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> x = np.random.default_rng(1).normal(size=8192)
    >>> rec = vm.Record(np.vstack([x, 2 * x]), fs=1000.0, channels=[vm.Channel("f", "force", "N"), vm.Channel("a")])
    >>> s = vm.csd(rec, "f", "a", nperseg=512)
    >>> bool(np.allclose(s.values[0].imag, 0.0))
    True
    """
    src, ix, iy, autos, cross, nseg, p = _pair_spectra(rec, x, y, nperseg, noverlap, window, detrend, nfft, fs,
                                                        progress)
    cx, cy = src.channels[ix], src.channels[iy]
    unit = f"{cx.unit}*{cy.unit}/Hz" if cx.unit or cy.unit else "1/Hz"
    return Spectrum(np.fft.rfftfreq(p["nfft"], 1 / src.fs), cross.conj(), "csd", unit, (f"{cx.name}*{cy.name}",),
                    "unknown", dict(p, window=window, detrend=detrend, fs=src.fs, n_averages=nseg))


def coherence(rec, x, y, *, nperseg: int | None = None, noverlap: int | None = None, window="hann",
              detrend="constant", nfft: int | None = None, fs: float | None = None, progress=None) -> Spectrum:
    """Magnitude-squared coherence |S_xy|^2 / (S_xx S_yy) between two channels (needs >= 2 averages).

    Parameters
    ----------
    rec : Record, LazyRecord or array_like
        The record.
    x, y : str or int
        The two channels.
    nperseg, noverlap : int, optional
        Segment length and overlap (defaults as ``psd``).
    window : str, tuple or array_like
        Window (default Hann).
    detrend : {"constant", "linear", False}
        What each segment loses first.
    nfft : int, optional
        FFT length.
    fs : float, optional
        Sampling rate for an array.
    progress : callable, optional
        ``progress(fraction)`` as blocks finish.

    Returns
    -------
    Spectrum
        Of kind "coherence", between 0 and 1.

    Raises
    ------
    ParameterError
        For unknown channels, bad parameters or a single average.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> x = np.random.default_rng(1).normal(size=8192)
    >>> rec = vm.Record(np.vstack([x, 2 * x]), fs=1000.0, channels=[vm.Channel("f", "force", "N"), vm.Channel("a")])
    >>> round(float(vm.coherence(rec, "f", "a", nperseg=512).values[0].min()), 6)
    1.0
    """
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
    """Power spectral density of each segment over time (a waterfall).

    Parameters
    ----------
    rec : Record, LazyRecord or array_like
        The record.
    channel : str or int, optional
        The channel (default the first).
    nperseg, noverlap : int, optional
        Segment length and overlap.
    window : str, tuple or array_like
        Window (default Hann).
    detrend : {"constant", "linear", False}
        What each segment loses first.
    nfft : int, optional
        FFT length.
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    Spectrogram
        ``values`` of shape (1, n_freq, n_times).

    Raises
    ------
    ParameterError
        For bad parameters or data.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> rec = vm.Record.from_array(np.random.default_rng(1).normal(size=4096), fs=1000.0)
    >>> vm.spectrogram(rec, nperseg=256).values.shape[0]
    1
    """
    src = _source(rec, fs)
    nperseg, noverlap, nfft = check_segment_params(src.n_samples, nperseg, noverlap, nfft, detrend, "mean", 1024)
    idx = _channel_indices(src, 0 if channel is None else channel)
    win = get_window(window, nperseg)
    step = nperseg - noverlap
    nseg = (src.n_samples - nperseg) // step + 1
    if nseg * (nfft // 2 + 1) > MEDIAN_LIMIT:
        raise ParameterError(f"spectrogram of {nseg} segments x {nfft // 2 + 1} lines is too large: "
                             "raise nperseg or lower the overlap")
    _, _, _, per = segment_sums(src, idx, nperseg=nperseg, noverlap=noverlap, nfft=nfft, win=win,
                                 detrend=detrend, keep_segments=True)
    S = _one_sided(per / (src.fs * (win @ win)), nfft)  # (1, nseg, nf)
    times = (np.arange(nseg) * step + nperseg / 2) / src.fs
    ch, unit, _ = _meta(src, idx)
    return Spectrogram(np.fft.rfftfreq(nfft, 1 / src.fs), times, np.transpose(S, (0, 2, 1)),
                       power_unit(unit, density=True), (ch[0].name,),
                       {"window": window, "nperseg": nperseg, "noverlap": noverlap, "nfft": nfft, "fs": src.fs})


# ------------------------------------------------------------------------------------------------
