"""Envelope (amplitude demodulation) and the squared-envelope spectrum for bearing diagnostics."""

from __future__ import annotations

import numpy as np
from scipy import signal as _sig

from ..core._validate import as_record, check_band, response_channel
from ..core.errors import ParameterError
from ..core.record import Channel, Record
from ..core.results import Spectrum

__all__ = ["envelope", "envelope_spectrum"]


def _band(rec, band):
    if band is None:
        raise ParameterError("band=(lo, hi) is required: the demodulation band around the resonance the "
                             "impacts excite (e.g. (2000, 5000) Hz for rolling bearings)")
    lo, hi = check_band(band, rec.fs)
    if lo <= 0 or hi >= rec.fs / 2:
        raise ParameterError(f"band={band!r} must lie strictly inside 0..fs/2 = {rec.fs / 2:g} Hz")
    return lo, hi


def envelope(rec, *, band, channel=None, order: int = 4, fs: float | None = None) -> Record:
    """Envelope of one channel: zero-phase Butterworth band-pass, then |analytic signal|."""
    rec = as_record(rec, fs=fs)
    lo, hi = _band(rec, band)
    i = response_channel(rec, channel)
    x = rec.data[i]
    if not np.isfinite(x).all():
        raise ParameterError(f"channel {rec.channels[i].name!r} has NaN/inf samples; the rule is finite data")
    sos = _sig.butter(order, (lo, hi), btype="bandpass", fs=rec.fs, output="sos")
    env = np.abs(_sig.hilbert(_sig.sosfiltfilt(sos, x)))
    c = rec.channels[i]
    return Record(env, rec.fs, (Channel(f"{c.name}.env", c.quantity, c.unit, c.location),), t0=rec.t0,
                  meta=rec.meta, history=rec.history + (f"envelope(band=({lo:g}, {hi:g}))",))


def envelope_spectrum(rec, *, band, channel=None, window="hann", nperseg: int | None = None,
                      fs: float | None = None) -> Spectrum:
    """Amplitude spectrum of the squared envelope (mean removed) of the band-passed channel.

    The squared envelope keeps the fault's repetition lines sharp (Randall & Antoni); unit is the
    channel unit squared. Without ``nperseg`` the whole record is one segment.
    """
    from .spectral import amplitude_spectrum, power_unit
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
