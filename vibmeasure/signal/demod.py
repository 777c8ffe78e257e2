"""Envelope (amplitude demodulation) and the squared-envelope spectrum for bearing diagnostics."""

from __future__ import annotations

import numpy as np
from scipy import signal as _sig

from ..core._validate import as_record, check_band, memory_guard, response_channel
from ..core.errors import ParameterError
from ..core.record import Channel, Record
from ..core.results import Spectrum

__all__ = ["envelope", "envelope_spectrum", "order_track", "time_synchronous_average", "shaft_angle", "angle_grid", "at_times"]


def _band(rec, band):
    if band is None:
        raise ParameterError("band=(lo, hi) is required: the demodulation band around the resonance the "
                             "impacts excite (e.g. (2000, 5000) Hz for rolling bearings)")
    lo, hi = check_band(band, rec.fs)
    if lo <= 0 or hi >= rec.fs / 2:
        raise ParameterError(f"band={band!r} must lie strictly inside 0..fs/2 = {rec.fs / 2:g} Hz")
    return lo, hi


@memory_guard
def envelope(rec, *, band, channel=None, order: int = 4, fs: float | None = None) -> Record:
    """Envelope of one channel: zero-phase Butterworth band-pass, then |analytic signal|.

    Parameters
    ----------
    rec : Record or array_like
        The record.
    band : tuple of float
        (lo, hi) Hz of the band-pass.
    channel : str or int, optional
        The channel (default the first that is not a force).
    order : int
        Butterworth order.
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    Record
        One channel, the envelope, in the channel's unit.

    Raises
    ------
    ParameterError
        For a band outside (0, fs/2) or bad data.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> t = np.arange(8192) / 8192.0
    >>> x = (1 + 0.5 * np.cos(2 * np.pi * 10 * t)) * np.sin(2 * np.pi * 1000 * t)
    >>> env = vm.envelope(vm.Record.from_array(x, fs=8192.0), band=(800, 1200))
    >>> round(float(np.median(env.data[0])), 1)
    1.0
    """
    rec = as_record(rec, fs=fs)
    lo, hi = _band(rec, band)
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or not 1 <= order <= 12:
        raise ParameterError(f"order={order!r} must be an integer from 1 to 12")
    i = response_channel(rec, channel)
    x = rec.data[i]
    if not np.isfinite(x).all():
        raise ParameterError(f"channel {rec.channels[i].name!r} has NaN/inf samples; the rule is finite data")
    sos = _sig.butter(order, (lo, hi), btype="bandpass", fs=rec.fs, output="sos")
    env = np.abs(_sig.hilbert(_sig.sosfiltfilt(sos, x)))
    c = rec.channels[i]
    return Record(env, rec.fs, (Channel(f"{c.name}.env", c.quantity, c.unit, c.location),), t0=rec.t0,
                  meta=rec.meta, history=rec.history + (f"envelope(band=({lo:g}, {hi:g}))",))


@memory_guard
def envelope_spectrum(rec, *, band, channel=None, window="hann", nperseg: int | None = None,
                      fs: float | None = None, progress=None) -> Spectrum:
    """Amplitude spectrum of the squared envelope (mean removed) of the band-passed channel.

    The squared envelope keeps a fault's repetition lines sharp (Randall & Antoni 2011); its unit is
    the channel's unit squared. A lazy record is streamed in segments, each demodulated in its band,
    so memory stays bounded.

    Parameters
    ----------
    rec : Record, LazyRecord or array_like
        The record.
    band : tuple of float
        (lo, hi) Hz of the demodulation band (below fs/2).
    channel : str or int, optional
        The channel (default the first that is not a force).
    window : str, tuple or array_like
        Window of the spectrum.
    nperseg : int, optional
        Segment length (default: the whole record; a lazy record 2^18 with half overlap).
    fs : float, optional
        Sampling rate for an array.
    progress : callable, optional
        ``progress(fraction)`` as a lazy record's blocks finish.

    Returns
    -------
    Spectrum
        Of kind "envelope".

    Raises
    ------
    ParameterError
        For a band outside (0, fs/2) or bad data.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> rec = vm.synth.machine(fault="bearing_outer_race", rpm=1797, duration=2.0, seed=1)
    >>> env = vm.envelope_spectrum(rec, band=(2500, 4500))
    >>> env.kind
    'envelope'
    """
    from ..io.lazy import LazyRecord
    from .spectral import amplitude_spectrum, power_unit
    if isinstance(rec, LazyRecord):
        return _envelope_spectrum_streamed(rec, band=band, channel=channel, nperseg=nperseg, progress=progress)
    rec = as_record(rec, fs=fs)
    env = envelope(rec, band=band, channel=channel)
    sq = env.data[0] ** 2
    sq = sq - sq.mean()
    c = env.channels[0]
    r2 = Record(sq, rec.fs, (Channel(c.name + "^2", "unknown", ""),))
    spec = amplitude_spectrum(r2, window=window, nperseg=nperseg)
    params = dict(spec.params, band_hz=tuple(_band(rec, band)), squared=True)
    return Spectrum(spec.freq, spec.values, "envelope", power_unit(c.unit, density=False),
                    (c.name,), c.quantity, params)


def _envelope_spectrum_streamed(rec, *, band, channel, nperseg, progress):
    """Averaged squared-envelope spectrum of one channel of a lazy record, segment by segment."""
    from scipy import fft as sfft
    from .spectral import power_unit
    lo, hi = _band(rec, band)
    i = response_channel(rec, channel) if hasattr(rec, "data") else (rec.index(channel) if channel is not None else 0)
    n = rec.n_samples
    if nperseg is not None and (isinstance(nperseg, bool) or not isinstance(nperseg, (int, np.integer))):
        raise ParameterError(f"nperseg={nperseg!r} must be an integer number of samples")
    seg = min(n, 2 ** 18 if nperseg is None else int(nperseg))
    if seg < 256:
        raise ParameterError(f"nperseg={nperseg!r} must be at least 256 samples (and at most the record)")
    step = seg // 2
    starts = list(range(0, n - seg + 1, step)) or [0]
    k = np.fft.rfftfreq(seg, 1 / rec.fs)
    keep = (k >= lo) & (k <= hi)
    w = np.hanning(seg)
    acc = np.zeros(seg // 2 + 1)
    for j, s0 in enumerate(starts):
        x = np.asarray(rec.read(s0, s0 + seg)[i], float)
        if not np.isfinite(x).all():
            raise ParameterError(f"channel {rec.names[i]!r} has NaN/inf samples near sample {s0}")
        X = sfft.rfft(x - x.mean(), workers=-1)
        Xb = np.zeros(seg, complex)
        Xb[np.flatnonzero(keep)] = 2 * X[keep]
        e = np.abs(sfft.ifft(Xb, workers=-1)) ** 2   # |analytic signal of the band|^2
        acc += np.abs(sfft.rfft((e - e.mean()) * w, workers=-1)) * (2.0 / w.sum())
        if progress is not None:
            progress((j + 1) / len(starts))
    c = rec.channels[i]
    return Spectrum(k, acc[None] / len(starts), "envelope", power_unit(c.unit, density=False), (f"{c.name}.env",),
                    c.quantity,
                    {"window": "hann", "nperseg": seg, "noverlap": seg - step, "averages": len(starts),
                     "band_hz": (lo, hi), "squared": True, "streamed": True})


def _rising_edges(p, lvl, hyst):
    """Samples i with p[i] < lvl <= p[i + 1] where the signal rises through lvl after it was below
    lvl - hyst, to reach lvl + hyst before it falls again: the noise on a slow edge makes one pulse,
    not several (a Schmitt trigger)."""
    state = np.full(p.size, -1)
    state[p <= lvl - hyst] = 0
    state[p >= lvl + hyst] = 1
    known = np.flatnonzero(state >= 0)
    if known.size < 2:
        return np.zeros(0, int)
    s = state[known]
    turn = np.flatnonzero((s[1:] == 1) & (s[:-1] == 0))        # last low sample -> first high sample
    hi_i = known[turn + 1]
    # the last plain crossing of lvl before each first high sample (there is one: the low sample
    # before it lies under lvl)
    cross = np.flatnonzero((p[:-1] < lvl) & (p[1:] >= lvl))
    return cross[np.searchsorted(cross, hi_i, side="left") - 1]


def shaft_angle(rec, *, tach=None, rpm_profile=None, pulses_per_rev: int = 1, tach_level: float | None = None):
    """Shaft angle (revolutions) at every sample, from tachometer pulses or an rpm profile."""
    t = np.arange(rec.n_samples) / rec.fs
    if (tach is None) == (rpm_profile is None):
        raise ParameterError("give exactly one of tach (pulse channel name or array) and rpm_profile")
    if tach is not None:
        p = rec.channel(tach) if isinstance(tach, (str, int, np.integer)) else np.asarray(tach, float)
        if p.shape != t.shape:
            raise ParameterError(f"tach has {p.size} samples; the record has {t.size}")
        if p.size < 4:
            raise ParameterError(f"tach has {p.size} samples; pulses need at least 4")
        bad = np.flatnonzero(~np.isfinite(p))
        if bad.size:
            raise ParameterError(f"tach has {bad.size} NaN/inf samples (first at index {bad[0]}); the rule is finite "
                                 "data: repair or cut the record first")
        lvl = (p.max() + p.min()) / 2 if tach_level is None else tach_level
        up = _rising_edges(p, lvl, 0.1 * (p.max() - p.min()))
        if up.size < 3:
            raise ParameterError(f"tach: {up.size} pulse(s) found at level {lvl:g}; at least 3 are needed")
        # sub-sample crossing times, then the angle is linear between pulses (cubic would overshoot)
        tc = (up + (lvl - p[up]) / (p[up + 1] - p[up])) / rec.fs
        rev = np.arange(tc.size) / pulses_per_rev
        return np.interp(t, tc, rev, left=np.nan, right=np.nan)
    prof = np.asarray(rpm_profile, float)
    if prof.shape != t.shape or np.any(~np.isfinite(prof)) or np.any(prof <= 0):
        raise ParameterError(f"rpm_profile must hold one positive rpm per sample ({t.size})")
    from scipy.integrate import cumulative_trapezoid
    return cumulative_trapezoid(prof / 60.0, t, initial=0.0)


def angle_grid(ang, fs, samples_per_rev):
    """Equal steps of shaft angle (revolutions) over the samples where the angle is known, and the
    times at which the shaft reaches them."""
    ok = np.flatnonzero(np.isfinite(ang))
    a0, a1 = ang[ok[0]], ang[ok[-1]]
    grid = np.arange(np.ceil(a0 * samples_per_rev), np.floor(a1 * samples_per_rev)) / samples_per_rev
    return grid, np.interp(grid, ang[ok], ok / fs)


def at_times(x, fs, t_grid):
    """Samples x (at rate fs) interpolated at the given times (cubic spline)."""
    from scipy.interpolate import CubicSpline
    return CubicSpline(np.arange(x.size) / fs, x)(t_grid)


def order_track(rec, *, channel=None, tach=None, rpm_profile=None, samples_per_rev: int = 64,
                pulses_per_rev: int = 1, fs: float | None = None) -> Record:
    """Angular resampling: the channel at equal shaft-angle steps.

    The result's ``fs`` is in samples per revolution, so its spectrum is an order spectrum (1.0 = 1X)
    however the speed varied.

    Parameters
    ----------
    rec : Record
        The record.
    channel : str or int, optional
        The vibration channel.
    tach : str, int or array_like, optional
        The tachometer channel (or its samples).
    rpm_profile : array_like, optional
        One rpm per sample, instead of a tachometer.
    samples_per_rev : int
        Samples per revolution of the result.
    pulses_per_rev : int
        Tachometer pulses per revolution.
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    Record
        The channel in the angle domain.

    Raises
    ------
    ParameterError
        Without tach or rpm_profile, or with too few revolutions.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> run = vm.synth.machine(fault="unbalance", rpm=(1500, 2100), duration=4.0, tach=1, seed=1)
    >>> vm.order_track(run, channel="acc", tach="tach", samples_per_rev=64).fs
    64.0
    """
    rec = as_record(rec, fs=fs)
    i = response_channel(rec, channel)
    if isinstance(samples_per_rev, bool) or not isinstance(samples_per_rev, (int, np.integer)) or samples_per_rev < 4:
        raise ParameterError(f"samples_per_rev={samples_per_rev!r} must be an integer >= 4")
    ang = shaft_angle(rec, tach=tach, rpm_profile=rpm_profile, pulses_per_rev=pulses_per_rev)
    grid, t_grid = angle_grid(ang, rec.fs, samples_per_rev)
    if grid.size < 4 * samples_per_rev:
        raise ParameterError("fewer than 4 revolutions are covered by the speed information")
    x = at_times(rec.data[i], rec.fs, t_grid)
    c = rec.channels[i]
    return Record(x, float(samples_per_rev), (Channel(f"{c.name}.orders", c.quantity, c.unit, c.location),),
                  meta=dict(rec.meta, domain="angle", samples_per_rev=samples_per_rev, first_rev=float(grid[0])),
                  history=rec.history + (f"order_track({samples_per_rev} samples/rev)",))


def time_synchronous_average(rec, *, channel=None, tach=None, rpm_profile=None, samples_per_rev: int = 256,
                             pulses_per_rev: int = 1, fs: float | None = None) -> Record:
    """Average of the angle-resampled signal over whole revolutions.

    What turns with the shaft stays; the rest (noise, other shafts, bearing impacts that slip) averages
    out by about 1/sqrt(revolutions).

    Parameters
    ----------
    rec : Record
        The record.
    channel : str or int, optional
        The vibration channel.
    tach : str, int or array_like, optional
        The tachometer channel (or its samples).
    rpm_profile : array_like, optional
        One rpm per sample, instead of a tachometer.
    samples_per_rev : int
        Samples per revolution.
    pulses_per_rev : int
        Tachometer pulses per revolution.
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    Record
        One revolution (``samples_per_rev`` samples, fs in samples per revolution).

    Raises
    ------
    ParameterError
        Without tach or rpm_profile, or with too few revolutions.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> run = vm.synth.machine(fault="unbalance", rpm=1797, duration=4.0, tach=1, seed=1)
    >>> vm.time_synchronous_average(run, channel="acc", tach="tach").n_samples
    256
    """
    ang_rec = order_track(rec, channel=channel, tach=tach, rpm_profile=rpm_profile, samples_per_rev=samples_per_rev,
                          pulses_per_rev=pulses_per_rev, fs=fs)
    start = int((-ang_rec.meta["first_rev"] * samples_per_rev) % samples_per_rev)
    x = ang_rec.data[0, start:]
    n_rev = x.size // samples_per_rev
    avg = x[: n_rev * samples_per_rev].reshape(n_rev, samples_per_rev).mean(axis=0)
    return ang_rec.replace(data=avg, meta=dict(ang_rec.meta, revolutions_averaged=n_rev),
                           note=f"time_synchronous_average({n_rev} revolutions)")
