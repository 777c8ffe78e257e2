"""Band levels from a PSD: the RMS in a band, and 1/1 or 1/3 octave bands (IEC 61260-1)."""

from __future__ import annotations

import numpy as np

from ..core.errors import ParameterError
from ..core.results import Spectrum
from .spectral import _check_band, psd

__all__ = ["band_rms", "octave_bands"]


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
    """RMS of each channel in a frequency band, from its PSD.

    Lines at the band edges count in part; ``band=(0, fs/2)`` gives the overall RMS less the mean.

    Parameters
    ----------
    obj : Spectrum, Record or array_like
        A PSD, or a record whose PSD is computed.
    band : tuple of float
        (lo, hi) in Hz.
    fs : float, optional
        Sampling rate for an array.
    nperseg : int, optional
        Segment length of the PSD computed from a record.

    Returns
    -------
    numpy.ndarray
        One RMS per channel, in the channels' unit.

    Raises
    ------
    ParameterError
        For a band outside (0, fs/2) or a spectrum that is no PSD.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> t = np.arange(2 ** 14) / 1000.0
    >>> rec = vm.Record.from_array(np.sqrt(2) * np.sin(2 * np.pi * 50.0 * t), fs=1000.0)
    >>> round(float(vm.band_rms(rec, (40, 60))[0]), 2)
    1.0
    """
    spec = _as_density(obj, fs=fs, nperseg=nperseg)
    lo, hi = _check_band(band, spec.params.get("fs", 2 * spec.freq[-1]))
    return np.sqrt(_band_power(spec, lo, hi))

def octave_bands(obj, *, fraction: int = 3, band=None, fs: float | None = None, nperseg: int | None = None):
    """RMS in 1/1 or 1/3 octave bands (base-10 IEC 61260-1 mid-band frequencies), from the PSD.

    Parameters
    ----------
    obj : Spectrum, Record or array_like
        A PSD, or a record whose PSD is computed.
    fraction : {1, 3}
        Octave (1) or third-octave (3) bands.
    band : tuple of float, optional
        (lo, hi) Hz the bands must lie in (default (df, fs/2)).
    fs : float, optional
        Sampling rate for an array.
    nperseg : int, optional
        Segment length of the PSD computed from a record.

    Returns
    -------
    pandas.DataFrame
        center_hz, lower_hz, upper_hz, lines (PSD lines inside the band: below 2 the band is narrower
        than the resolution) and one rms column per channel.

    Raises
    ------
    ParameterError
        For a fraction other than 1 or 3, or no band inside the range.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> rec = vm.Record.from_array(np.random.default_rng(1).normal(size=2 ** 14), fs=2000.0)
    >>> "center_hz" in vm.octave_bands(rec, fraction=3).columns
    True
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
