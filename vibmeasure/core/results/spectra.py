"""Spectrum, Spectrogram, Peaks and Kurtogram."""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from ..errors import ParameterError


@dataclass(frozen=True)
class Spectrum:
    """A frequency-domain result: ``values`` (n_channels, n_freq) at ``freq`` (Hz).

    Parameters
    ----------
    freq : array_like
        Frequencies in Hz.
    values : array_like
        (n_channels, n_freq).
    kind : str
        "amplitude", "psd" (unit^2/Hz), "power" (unit^2 per line), "envelope", "csd" (complex) or
        "coherence".
    unit : str
        The values' unit.
    channels : tuple of str
        Channel names.
    quantity : str
        The channels' quantity.
    params : mapping
        What it was made with (window, nperseg, noverlap, nfft, detrend, average, n_averages, enbw_hz).

    Raises
    ------
    ParameterError
        For shapes that do not match.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> s = vm.Spectrum(np.arange(4.0), np.ones((1, 4)), "amplitude", unit="g", channels=("a",))
    >>> s.df
    1.0
    """

    freq: np.ndarray
    values: np.ndarray
    kind: str
    unit: str = ""
    channels: tuple[str, ...] = ()
    quantity: str = "unknown"
    params: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        f = np.asarray(self.freq, dtype=float)
        v = np.asarray(self.values)
        if v.ndim == 1:
            v = v[np.newaxis]
        if f.ndim != 1 or v.ndim != 2 or v.shape[1] != f.size:
            raise ParameterError(f"values must have shape (n_channels, {f.size}) for {f.size} frequencies, "
                                 f"got {v.shape}")
        chans = tuple(self.channels) if self.channels else tuple(f"ch{i}" for i in range(v.shape[0]))
        if len(chans) != v.shape[0]:
            raise ParameterError(f"channels has {len(chans)} names for {v.shape[0]} rows of values")
        f.setflags(write=False)
        v = v.copy()
        v.setflags(write=False)
        object.__setattr__(self, "freq", f)
        object.__setattr__(self, "values", v)
        object.__setattr__(self, "channels", chans)
        object.__setattr__(self, "params", MappingProxyType(dict(self.params)))

    @property
    def df(self) -> float:
        """Line spacing in Hz."""
        return float(self.freq[1] - self.freq[0]) if self.freq.size > 1 else float("nan")

    @property
    def n_channels(self) -> int:
        return self.values.shape[0]

    def channel(self, channel: str | int = 0) -> np.ndarray:
        """The values of one channel.

        Parameters
        ----------
        channel : str or int
            Name or position.

        Returns
        -------
        numpy.ndarray

        Raises
        ------
        ParameterError
            For an unknown channel.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> vm.Spectrum(np.arange(3.0), np.ones((1, 3)), "amplitude", channels=("a",)).channel("a").tolist()
        [1.0, 1.0, 1.0]
        """
        from .._validate import name_index
        return self.values[name_index(self.channels, channel)]

    def to_frame(self):
        """A pandas table: a freq_hz column and one column per channel.

        Returns
        -------
        pandas.DataFrame

        Raises
        ------
        ParameterError
            Never for a valid object.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> list(vm.Spectrum(np.arange(3.0), np.ones((1, 3)), "amplitude", channels=("a",)).to_frame().columns)
        ['freq_hz', 'a']
        """
        import pandas as pd
        df = pd.DataFrame(self.values.T, columns=list(self.channels))
        df.insert(0, "freq_hz", self.freq)
        return df

    def __repr__(self) -> str:
        return (f"Spectrum({self.kind}, {self.n_channels} ch x {self.freq.size} lines, df={self.df:.4g} Hz, "
                f"unit={self.unit!r})")


@dataclass(frozen=True)
class Spectrogram:
    """Power spectral density over time.

    Parameters
    ----------
    freq : array_like
        Frequencies in Hz.
    times : array_like
        Segment centres in s.
    values : array_like
        (n_channels, n_freq, n_times).
    unit : str
        The values' unit.
    channels : tuple of str
        Channel names.
    params : mapping
        What it was made with.

    Raises
    ------
    ParameterError
        For shapes that do not match.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> sg = vm.spectrogram(vm.Record.from_array(np.random.default_rng(1).normal(size=4096), fs=1000.0), nperseg=256)
    >>> sg.values.ndim
    3
    """

    freq: np.ndarray
    times: np.ndarray
    values: np.ndarray
    unit: str = ""
    channels: tuple[str, ...] = ()
    params: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        v = np.asarray(self.values)
        if v.ndim != 3 or v.shape[1:] != (np.size(self.freq), np.size(self.times)):
            raise ParameterError(f"values must be (n_channels, n_freq, n_times), got {v.shape}")
        object.__setattr__(self, "params", MappingProxyType(dict(self.params)))


@dataclass(frozen=True)
class Peaks:
    """Spectral peaks: interpolated frequency, scalloping-corrected amplitude and prominence.

    Parameters
    ----------
    freq : array_like
        Frequencies in Hz, strongest peak first.
    amplitude : array_like
        Amplitudes in the spectrum's unit.
    prominence : array_like
        Prominences in the spectrum's unit.
    channel : str
        The channel.
    unit : str
        The unit.
    kind : str
        The spectrum's kind.
    families : mapping
        Family name -> list of dicts (order, expected_hz, found_hz, amplitude) when searched.

    Raises
    ------
    ParameterError
        For arrays of different lengths.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> p = vm.Peaks(freq=np.array([50.0]), amplitude=np.array([1.0]), prominence=np.array([0.9]))
    >>> len(p)
    1
    """

    freq: np.ndarray
    amplitude: np.ndarray
    prominence: np.ndarray
    channel: str = ""
    unit: str = ""
    kind: str = ""
    families: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        f = np.atleast_1d(np.asarray(self.freq, float))
        for name in ("amplitude", "prominence"):
            a = np.atleast_1d(np.asarray(getattr(self, name), float))
            if a.shape != f.shape:
                raise ParameterError(f"{name} must have one value per peak ({f.size}), got {a.shape}")
            object.__setattr__(self, name, a)
        object.__setattr__(self, "freq", f)
        object.__setattr__(self, "families", MappingProxyType(dict(self.families)))

    def __len__(self) -> int:
        return self.freq.size

    def to_frame(self):
        """A pandas table with freq, amplitude, prominence and unit, strongest first.

        Returns
        -------
        pandas.DataFrame

        Raises
        ------
        ParameterError
            Never for a valid object.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> p = vm.Peaks(freq=np.array([50.0]), amplitude=np.array([1.0]), prominence=np.array([0.9]))
        >>> p.to_frame()["freq_hz"].tolist()
        [50.0]
        """
        import pandas as pd
        return pd.DataFrame({"freq_hz": self.freq, "amplitude": self.amplitude, "prominence": self.prominence,
                             "unit": [self.unit] * self.freq.size})

    def __repr__(self) -> str:
        rows = ", ".join(f"{f:.6g} Hz: {a:.4g}" for f, a in zip(self.freq[:6], self.amplitude[:6]))
        return f"Peaks({len(self)} in {self.channel!r}: {rows}{' ...' if len(self) > 6 else ''})"


@dataclass(frozen=True)
class Kurtogram:
    """A fast kurtogram and infogram: per level of the 1/3-binary tree, per band, kurtosis and negentropy.

    Parameters
    ----------
    fs : float
        Sampling rate in Hz.
    levels : tuple
        Levels of the tree (0, 1, 1.6, 2, ...).
    n_bands : tuple
        Bands per level.
    kurtosis, negentropy : tuple of numpy.ndarray
        One array per level (negentropy: the mean of the time- and frequency-domain excess).
    band : tuple of float
        The chosen (lo, hi) in Hz.
    criterion : str
        What chose it: "kurtosis" or "negentropy".
    value : float
        Its value there.
    min_bandwidth : float
        The narrowest band in Hz.
    params : dict
        How it was made.

    Raises
    ------
    ParameterError
        Never for a ``vm.kurtogram`` result.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> kg = vm.kurtogram(vm.synth.machine(fault="bearing_outer_race", rpm=1797, duration=1.0, seed=1))
    >>> len(kg.levels) == len(kg.kurtosis)
    True
    """

    fs: float
    levels: tuple
    n_bands: tuple
    kurtosis: tuple
    negentropy: tuple
    band: tuple
    criterion: str
    value: float
    min_bandwidth: float
    params: dict = field(default_factory=dict)

    def best(self, criterion: str = "kurtosis") -> tuple:
        """The band with the largest kurtosis or negentropy.

        Parameters
        ----------
        criterion : {"kurtosis", "negentropy"}
            Which map.

        Returns
        -------
        tuple
            (lo, hi, level, value).

        Raises
        ------
        ParameterError
            For an unknown criterion.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> kg = vm.kurtogram(vm.synth.machine(fault="bearing_outer_race", rpm=1797, duration=1.0, seed=1))
        >>> len(kg.best())
        4
        """
        rows = self.kurtosis if criterion == "kurtosis" else self.negentropy
        best = (np.nan, np.nan, np.nan, -np.inf)
        for lev, nb, vals in zip(self.levels, self.n_bands, rows):
            if np.isfinite(vals).any() and np.nanmax(vals) > best[3]:
                i = int(np.nanargmax(vals))
                bw = self.fs / 2 / nb
                best = (i * bw, (i + 1) * bw, lev, float(vals[i]))
        return best

    def image(self, criterion: str = "kurtosis", n_cols: int = 768) -> np.ndarray:
        """The map as an image (levels x frequency columns) for plotting.

        Parameters
        ----------
        criterion : {"kurtosis", "negentropy"}
            Which map.
        n_cols : int
            Frequency columns.

        Returns
        -------
        numpy.ndarray
            (n_levels, n_cols).

        Raises
        ------
        ParameterError
            For an unknown criterion.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> kg = vm.kurtogram(vm.synth.machine(fault="bearing_outer_race", rpm=1797, duration=1.0, seed=1))
        >>> kg.image(n_cols=100).shape[1]
        100
        """
        rows = self.kurtosis if criterion == "kurtosis" else self.negentropy
        out = np.full((len(rows), n_cols), np.nan)
        for r, (nb, vals) in enumerate(zip(self.n_bands, rows)):
            out[r] = vals[np.minimum((np.arange(n_cols) * nb) // n_cols, nb - 1)]
        return out
