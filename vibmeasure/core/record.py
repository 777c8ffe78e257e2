"""Channel and Record: samples that travel with their sampling rate, units and history."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Iterable, Mapping, Sequence

import numpy as np

from . import units as _units
from .errors import ParameterError

__all__ = ["Channel", "Record"]


@dataclass(frozen=True)
class Channel:
    """Metadata of one channel.

    Parameters
    ----------
    name : str
        The channel's name.
    quantity : str
        "displacement", "velocity", "acceleration", "force", "time" or "unknown".
    unit : str
        Its unit ("g", "m/s^2", "mm/s", "N", ...).
    location : str
        Where the sensor sits.

    Raises
    ------
    ParameterError
        For an unknown quantity, or a unit of another quantity.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> vm.Channel("acc1", "acceleration", "g").unit
    'g'
    """

    name: str
    quantity: str = "unknown"
    unit: str = ""
    location: str = ""

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise ParameterError(f"Channel name={self.name!r} must be a non-empty string")
        unit = _units.check_unit(self.quantity, self.unit)
        object.__setattr__(self, "unit", unit)
        if self.quantity == "unknown" and unit:
            # a unit names its quantity ("g" is an acceleration), as the readers and the CLI take it: left
            # "unknown", a record made with unit="g" would lose its ISO 10816 level in vm.diagnose
            object.__setattr__(self, "quantity", _units.quantity_of(unit))


def _freeze(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=np.float64, copy=True) if a.dtype != np.float64 else a.copy()
    a.setflags(write=False)
    return a


@dataclass(frozen=True)
class Record:
    """A multichannel time series sampled at ``fs`` Hz.

    Records are immutable; transforms return new records, and ``history`` holds one line per transform
    since the data were read or made (provenance). ``fs`` is required and never defaulted.

    Parameters
    ----------
    data : array_like
        (n_channels, n_samples), time on the last axis (a 1-D array is one channel).
    fs : float
        Sampling rate in Hz.
    channels : sequence of Channel or str
        One per row (default "ch0", "ch1", ... of unknown quantity).
    t0 : float
        Time of the first sample in s.
    meta : mapping
        Anything else the source states (rpm, time, source file).
    history : tuple of str
        Provenance lines.

    Raises
    ------
    ParameterError
        For NaN, inf or complex data, fs that is not positive, or channels that do not match the rows.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> rec = vm.Record(np.zeros((2, 100)), fs=100.0, channels=[vm.Channel("a", "acceleration", "g"), "b"])
    >>> rec.names, rec.duration
    (['a', 'b'], 1.0)
    """

    data: np.ndarray
    fs: float
    channels: tuple[Channel, ...] = ()
    t0: float = 0.0
    meta: Mapping[str, Any] = field(default_factory=dict)
    history: tuple[str, ...] = ()

    def __post_init__(self):
        data = np.asarray(self.data)
        if data.dtype.kind not in "fiub":
            raise ParameterError(f"data must be real numbers, got dtype {data.dtype}")
        if data.ndim == 1:
            data = data[np.newaxis, :]
        if data.ndim != 2:
            raise ParameterError(f"data must have shape (n_channels, n_samples), got {data.shape}")
        object.__setattr__(self, "data", _freeze(data))
        try:
            fs = float(self.fs)
        except (TypeError, ValueError):
            raise ParameterError(f"fs={self.fs!r} must be a number in Hz") from None
        if not np.isfinite(fs) or fs <= 0:
            raise ParameterError(f"fs={self.fs!r} must be a finite sampling rate > 0 Hz")
        object.__setattr__(self, "fs", fs)
        chans = tuple(self.channels) if self.channels else tuple(
            Channel(f"ch{i}") for i in range(data.shape[0]))
        if len(chans) != data.shape[0]:
            raise ParameterError(f"channels has {len(chans)} entries but data has {data.shape[0]} channels")
        chans = tuple(c if isinstance(c, Channel) else Channel(str(c)) for c in chans)
        names = [c.name for c in chans]
        if len(set(names)) != len(names):
            raise ParameterError(f"channel names must be unique, got {names}")
        object.__setattr__(self, "channels", chans)
        object.__setattr__(self, "t0", float(self.t0))
        object.__setattr__(self, "meta", MappingProxyType(dict(self.meta)))
        object.__setattr__(self, "history", tuple(self.history))

    # construction -----------------------------------------------------------------------
    @classmethod
    def from_array(cls, x, *, fs: float, quantity: str = "unknown", unit: str = "", name: str | None = None,
                   names: Sequence[str] | None = None, location: str = "", t0: float = 0.0,
                   meta: Mapping[str, Any] | None = None) -> "Record":
        """Make a record from an array: 1-D for one channel or (n_channels, n_samples).

        ``quantity`` and ``unit`` apply to every channel; ``name`` names a single channel,
        ``names`` several.
        """
        a = np.asarray(x)
        if a.size == 0:
            raise ParameterError(f"x is empty (shape {a.shape}): a record needs samples")
        n_ch = 1 if a.ndim == 1 else (a.shape[0] if a.ndim == 2 else -1)
        if n_ch < 0:
            raise ParameterError(f"x must be 1-D or (n_channels, n_samples), got shape {a.shape}")
        if names is None:
            names = [name or "ch0"] if n_ch == 1 else [f"{name or 'ch'}{i}" for i in range(n_ch)]
        if len(names) != n_ch:
            raise ParameterError(f"names has {len(names)} entries for {n_ch} channels")
        chans = tuple(Channel(n, quantity, unit, location) for n in names)
        return cls(a, fs, chans, t0=t0, meta=meta or {}, history=("from_array",))

    # shape and time ---------------------------------------------------------------------
    @property
    def n_channels(self) -> int:
        return self.data.shape[0]

    @property
    def n_samples(self) -> int:
        return self.data.shape[1]

    @property
    def duration(self) -> float:
        """Length in seconds, n_samples / fs."""
        return self.n_samples / self.fs

    @property
    def dt(self) -> float:
        return 1.0 / self.fs

    @property
    def time(self) -> np.ndarray:
        """Sample times in seconds, starting at ``t0``."""
        return self.t0 + np.arange(self.n_samples) / self.fs

    @property
    def names(self) -> list[str]:
        return [c.name for c in self.channels]

    # selection --------------------------------------------------------------------------
    def index(self, channel: str | int) -> int:
        """Index of a channel given by name or position.

        Parameters
        ----------
        channel : str or int
            Name or position.

        Returns
        -------
        int

        Raises
        ------
        ParameterError
            For an unknown name or a position out of range.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> vm.Record(np.zeros((2, 3)), fs=1.0, channels=["a", "b"]).index("b")
        1
        """
        if isinstance(channel, (int, np.integer)) and not isinstance(channel, bool):
            if not -self.n_channels <= channel < self.n_channels:
                raise ParameterError(f"channel={channel} is out of range for {self.n_channels} channels")
            return int(channel) % self.n_channels
        names = self.names
        if channel not in names:
            raise ParameterError(f"channel={channel!r} is not in this record; channels are {names}")
        return names.index(channel)

    def select(self, channels: str | int | Iterable[str | int]) -> "Record":
        """A record holding only the given channels, in that order.

        Parameters
        ----------
        channels : str, int or sequence
            Names or positions.

        Returns
        -------
        Record

        Raises
        ------
        ParameterError
            For an unknown channel.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> vm.Record(np.zeros((3, 4)), fs=1.0, channels=["a", "b", "c"]).select(["c", "a"]).names
        ['c', 'a']
        """
        if isinstance(channels, (str, int, np.integer)):
            channels = [channels]
        idx = [self.index(c) for c in channels]
        if not idx:
            raise ParameterError("channels must name at least one channel")
        return self.replace(data=self.data[idx], channels=tuple(self.channels[i] for i in idx),
                            note=f"select({[self.channels[i].name for i in idx]})")

    def __getitem__(self, channel: str | int) -> "Record":
        return self.select(channel)

    def channel(self, channel: str | int) -> np.ndarray:
        """The samples of one channel as a read-only 1-D array.

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
        >>> vm.Record(np.arange(6.0).reshape(2, 3), fs=1.0).channel(1).tolist()
        [3.0, 4.0, 5.0]
        """
        return self.data[self.index(channel)]

    def slice_time(self, start: float | None = None, stop: float | None = None) -> "Record":
        """The part of the record between ``start`` and ``stop`` seconds (relative to ``t0``).

        Parameters
        ----------
        start, stop : float, optional
            Seconds (default the record's ends).

        Returns
        -------
        Record

        Raises
        ------
        ParameterError
            For an empty or reversed interval.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> vm.Record(np.zeros(100), fs=10.0).slice_time(2.0, 4.0).n_samples
        20
        """
        i0 = 0 if start is None else int(round((start - self.t0) * self.fs))
        i1 = self.n_samples if stop is None else int(round((stop - self.t0) * self.fs))
        i0, i1 = max(i0, 0), min(i1, self.n_samples)
        if i1 <= i0:
            raise ParameterError(f"start={start}, stop={stop} select no samples of a record spanning "
                                 f"{self.t0}..{self.t0 + self.duration} s")
        return self.replace(data=self.data[:, i0:i1], t0=self.t0 + i0 / self.fs,
                            note=f"slice_time({start}, {stop})")

    # transforms -------------------------------------------------------------------------
    def replace(self, *, note: str | None = None, **changes) -> "Record":
        """A new record with fields changed; ``note`` appends a line to ``history``.

        Parameters
        ----------
        note : str, optional
            The provenance line.
        **changes
            Fields to change (data, fs, channels, t0, meta).

        Returns
        -------
        Record

        Raises
        ------
        ParameterError
            For changes that make an invalid record.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> vm.Record(np.zeros(10), fs=10.0).replace(fs=20.0, note="fs corrected").history[-1]
        'fs corrected'
        """
        hist = self.history + ((note,) if note else ())
        changes.setdefault("history", hist)
        return dataclasses.replace(self, **changes)

    def to_unit(self, unit: str, *, channel: str | int | None = None) -> "Record":
        """Convert one channel (or every channel of the unit's quantity) to ``unit``.

        Parameters
        ----------
        unit : str
            The target unit.
        channel : str or int, optional
            One channel (default every channel of that quantity).

        Returns
        -------
        Record

        Raises
        ------
        UnitError
            For a unit of another quantity, or a channel without a unit.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> rec = vm.Record.from_array(np.ones(3), fs=1.0, unit="g")
        >>> round(float(rec.to_unit("m/s^2").data[0, 0]), 5)
        9.80665
        """
        target_q = _units.quantity_of(unit)
        idx = range(self.n_channels) if channel is None else [self.index(channel)]
        data = np.array(self.data)
        chans = list(self.channels)
        done = []
        for i in idx:
            c = chans[i]
            if c.unit == "" or _units.quantity_of(c.unit) != target_q:
                if channel is not None:
                    raise ParameterError(f"channel {c.name!r} is in {c.unit or 'no unit'!s}; "
                                         f"cannot convert to {unit!r} ({target_q})")
                continue
            data[i] = _units.convert(data[i], c.unit, unit)
            chans[i] = dataclasses.replace(c, unit=_units.normalize_unit(unit), quantity=target_q)
            done.append(c.name)
        if not done:
            raise ParameterError(f"no channel of this record can be converted to unit={unit!r}")
        return self.replace(data=data, channels=tuple(chans), note=f"to_unit({unit!r}, {done})")

    def to_frame(self):
        """A pandas DataFrame with a time column (s) and one column per channel.

        Returns
        -------
        pandas.DataFrame

        Raises
        ------
        ParameterError
            Never for a valid record.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> list(vm.Record(np.zeros((1, 3)), fs=1.0, channels=["a"]).to_frame().columns)
        ['time', 'a']
        """
        import pandas as pd
        df = pd.DataFrame(self.data.T, columns=self.names)
        df.insert(0, "time", self.time)
        return df

    def __repr__(self) -> str:
        ch = ", ".join(f"{c.name}[{c.unit or '-'}]" for c in self.channels)
        return (f"Record({self.n_channels} ch x {self.n_samples} samples, fs={self.fs:g} Hz, "
                f"{self.duration:g} s; {ch})")

    def __eq__(self, other) -> bool:
        if not isinstance(other, Record):
            return NotImplemented
        return (self.fs == other.fs and self.t0 == other.t0 and self.channels == other.channels
                and self.data.shape == other.data.shape and bool(np.array_equal(self.data, other.data))
                and dict(self.meta) == dict(other.meta) and self.history == other.history)

    __hash__ = None  # mutable-looking numpy payload: not hashable
