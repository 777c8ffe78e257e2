"""Result objects: data and derived properties, no algorithms."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from .errors import ParameterError

__all__ = ["ModalEstimate", "Spectrum", "Spectrogram", "Peaks", "FRF", "Kurtogram", "FLAG_TEXT", "jsonable", "Diagnosis"]

# Every quality flag a result may carry, with the sentence a report prints for it.
FLAG_TEXT = {
    "few_cycles": "fewer than 5 cycles of decay above the noise: damping is poorly determined",
    "noise_floor": "the decay reached the noise floor before the record ended; the fit stops there",
    "resolution_limited": "sampling or frequency resolution too coarse for a sound estimate",
    "clipped": "clipped samples (3 or more in a row at the extreme) were excluded",
    "close_modes": "another mode lies within a few half-power bandwidths: estimates interact",
    "overdamped": "no oscillation: the system is critically or over damped (zeta >= 1); no frequency",
    "coulomb_friction": "the envelope decays linearly, as with dry (Coulomb) friction: viscous zeta does "
                        "not describe it; see friction decay per cycle",
    "amplitude_dependent": "damping changes with amplitude (nonlinear damping); zeta is an average",
    "amplitude_dependent_frequency": "the natural frequency changes with amplitude (nonlinear stiffness); fn is "
                                     "an average: see extras['backbone'] and extras['backbone_model']",
    "colored_noise": "the noise near this mode is stronger than the broadband level: std scaled up",
    "low_snr": "the mode is weak compared with the noise",
    "start_detected": "the decay starts after the beginning of the record (trigger/impact found)",
    # machine diagnosis
    "bearing_not_checked": "no bearing given: bearing faults were not searched",
    "band_limited": "a channel measures only up to a filter's edge, too low to demodulate above the shaft "
                    "harmonics: the bearing evidence is weak",
    "speed_varies": "the 1X line moves over the record and the speed was not measured: where the 1X follows "
                    "a curve the speed is estimated from it and the record analysed in orders; else the lines "
                    "smear and no shaft-order fault is called",
    "order_tracked": "the speed varies: the record was resampled at equal steps of shaft angle and analysed in "
                     "orders",
    "spikes_removed": "isolated spikes (single samples, or two, far from their neighbours, which no accelerometer "
                      "behind an anti-alias filter makes) were replaced by their AR interpolation",
    "dropouts": "runs of equal samples (a converter or link that held or zeroed its output): the vibration "
                "there is lost; they were filled by AR interpolation for the envelope analysis",
    "saturated": "runs of samples sit at the record's extremes: the sensor or converter saturated, the level "
                 "reads low and the clipping adds harmonics",
}


def _arr(x, n, name, fill=np.nan):
    if x is None:
        return np.full(n, fill)
    a = np.atleast_1d(np.asarray(x, dtype=float))
    if a.shape != (n,):
        raise ParameterError(f"{name} must have one value per mode ({n}), got shape {a.shape}")
    return a


@dataclass(frozen=True)
class ModalEstimate:
    """Natural frequencies and damping ratios of one or more modes, with their uncertainty.

    Parameters
    ----------
    fn : array_like
        Undamped natural frequencies in Hz.
    zeta : array_like
        Viscous damping ratios (a ratio, not %).
    fn_std, zeta_std : array_like, optional
        Standard deviations (NaN only where a method gives none).
    method : str
        The method that made it.
    flags : tuple of str
        Quality findings for the whole estimate (``FLAG_TEXT`` says what each means).
    mode_flags : tuple of tuple of str, optional
        Findings per mode.
    amplitude, phase : array_like, optional
        Per mode (ring-downs).
    shapes : array_like, optional
        Mode shapes (n_outputs, n_modes).
    unit : str
        The amplitude's unit.
    extras : mapping
        Method-specific detail (noise level, backbone, stabilisation table, rejected modes, ...).

    Raises
    ------
    ParameterError
        For arrays of different lengths.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> est = vm.ModalEstimate(fn=[10.0], zeta=[0.02], fn_std=[0.01], zeta_std=[0.001])
    >>> est.n_modes, est.mode(0)["fn_hz"]
    (1, 10.0)
    """

    fn: np.ndarray
    zeta: np.ndarray
    fn_std: np.ndarray | None = None
    zeta_std: np.ndarray | None = None
    method: str = ""
    flags: tuple[str, ...] = ()
    mode_flags: tuple[tuple[str, ...], ...] | None = None
    amplitude: np.ndarray | None = None
    phase: np.ndarray | None = None
    shapes: np.ndarray | None = None
    unit: str = ""
    extras: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        fn = np.atleast_1d(np.asarray(self.fn, dtype=float))
        if fn.ndim != 1:
            raise ParameterError(f"fn must be 1-D (one value per mode), got shape {fn.shape}")
        n = fn.size
        object.__setattr__(self, "fn", fn)
        object.__setattr__(self, "zeta", _arr(self.zeta, n, "zeta"))
        object.__setattr__(self, "fn_std", _arr(self.fn_std, n, "fn_std"))
        object.__setattr__(self, "zeta_std", _arr(self.zeta_std, n, "zeta_std"))
        object.__setattr__(self, "amplitude", _arr(self.amplitude, n, "amplitude"))
        object.__setattr__(self, "phase", _arr(self.phase, n, "phase"))
        mf = self.mode_flags if self.mode_flags is not None else ((),) * n
        if len(mf) != n:
            raise ParameterError(f"mode_flags must have one entry per mode ({n}), got {len(mf)}")
        object.__setattr__(self, "mode_flags", tuple(tuple(f) for f in mf))
        allflags = list(dict.fromkeys(list(self.flags) + [f for m in self.mode_flags for f in m]))
        object.__setattr__(self, "flags", tuple(allflags))
        object.__setattr__(self, "extras", MappingProxyType(dict(self.extras)))
        for a in (self.fn, self.zeta, self.fn_std, self.zeta_std, self.amplitude, self.phase):
            a.setflags(write=False)

    @property
    def n_modes(self) -> int:
        return self.fn.size

    def __len__(self) -> int:
        return self.n_modes

    @property
    def wn(self) -> np.ndarray:
        """Undamped natural angular frequency, rad/s."""
        return 2 * np.pi * self.fn

    @property
    def fd(self) -> np.ndarray:
        """Damped natural frequency fn*sqrt(1 - zeta^2), Hz (NaN where zeta >= 1)."""
        with np.errstate(invalid="ignore"):
            return self.fn * np.sqrt(1 - self.zeta ** 2)

    @property
    def log_decrement(self) -> np.ndarray:
        """Logarithmic decrement per cycle, 2 pi zeta / sqrt(1 - zeta^2)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return 2 * np.pi * self.zeta / np.sqrt(1 - self.zeta ** 2)

    def mode(self, i: int) -> dict:
        """One mode as a dict with the documented JSON keys.

        Parameters
        ----------
        i : int
            The mode.

        Returns
        -------
        dict
            fn_hz, fn_std_hz, zeta, zeta_std, amplitude, phase, flags, ...

        Raises
        ------
        ParameterError
            For a mode out of range.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> vm.ModalEstimate(fn=[10.0], zeta=[0.02]).mode(0)["zeta"]
        0.02
        """
        return {
            "fn_hz": _num(self.fn[i]), "zeta": _num(self.zeta[i]),
            "fn_std_hz": _num(self.fn_std[i]), "zeta_std": _num(self.zeta_std[i]),
            "amplitude": _num(self.amplitude[i]), "method": self.method,
            "flags": list(self.mode_flags[i]),
        }

    def to_dict(self) -> dict:
        """JSON-ready dict: ``modes`` (per-mode dicts), ``method``, ``flags``, ``unit``, ``extras``.

        Returns
        -------
        dict

        Raises
        ------
        ParameterError
            Never for a valid estimate.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> sorted(vm.ModalEstimate(fn=[10.0], zeta=[0.02]).to_dict())[:3]
        ['extras', 'flags', 'method']
        """
        return {"method": self.method, "flags": list(self.flags), "unit": self.unit,
                "modes": [self.mode(i) for i in range(self.n_modes)],
                "extras": jsonable(dict(self.extras))}

    def to_frame(self):
        """A pandas table, one row per mode.

        Returns
        -------
        pandas.DataFrame

        Raises
        ------
        ParameterError
            Never for a valid estimate.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> vm.ModalEstimate(fn=[10.0, 20.0], zeta=[0.02, 0.01]).to_frame()["fn_hz"].tolist()
        [10.0, 20.0]
        """
        import pandas as pd
        return pd.DataFrame({"fn_hz": self.fn, "fn_std_hz": self.fn_std, "zeta": self.zeta,
                             "zeta_std": self.zeta_std, "amplitude": self.amplitude,
                             "flags": [",".join(f) for f in self.mode_flags]})

    def __repr__(self) -> str:
        rows = "; ".join(f"fn={f:.6g}±{fs:.2g} Hz zeta={z:.5g}±{zs:.2g}"
                         for f, fs, z, zs in zip(self.fn, self.fn_std, self.zeta, self.zeta_std))
        fl = f" flags={list(self.flags)}" if self.flags else ""
        return f"ModalEstimate({self.method}: {rows}{fl})"


def _num(x):
    x = float(x)
    return None if not np.isfinite(x) else x


_PLAIN = (str, int, bool, type(None))


def jsonable(obj):
    """obj with numpy scalars and arrays, tuples, NaN and inf turned into what ``json.dumps`` writes
    (lists, floats, None): the one conversion every ``to_dict`` and the CLI's ``--json`` use."""
    t = type(obj)
    if t in _PLAIN:   # the common leaves first: no abstract-class checks (a batch converts ~10^5 values)
        return obj
    if t is float:
        return obj if math.isfinite(obj) else None
    if t is dict:
        return {str(k): jsonable(v) for k, v in obj.items()}
    if t is list or t is tuple:
        return [jsonable(v) for v in obj]
    if hasattr(obj, "to_dict") and hasattr(obj, "columns"):  # a pandas DataFrame: its rows
        return [jsonable(r) for r in obj.to_dict(orient="records")]
    if isinstance(obj, Mapping):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return [jsonable(v) for v in obj.tolist()]
    if isinstance(obj, (float, np.floating)):
        return _num(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (np.bool_,)):
        return bool(obj)
    return obj


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
        from ._validate import name_index
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


_FORM_ORDER = {"receptance": 0, "mobility": 1, "accelerance": 2}


FORM_OF_QUANTITY = {"displacement": "receptance", "velocity": "mobility", "acceleration": "accelerance"}


def form_of(quantity: str) -> str:
    """FRF form for an output quantity (acceleration -> accelerance); 'unknown' otherwise."""
    return FORM_OF_QUANTITY.get(quantity, "unknown")


@dataclass(frozen=True)
class FRF:
    """Frequency response functions: complex ``h`` (n_out, n_in, n_freq) at ``freq`` (Hz).

    Parameters
    ----------
    freq : array_like
        Frequencies in Hz.
    h : array_like
        Complex (n_out, n_in, n_freq).
    form : str
        "receptance" (displacement/force), "mobility" (velocity/force), "accelerance" or "unknown".
    coherence : array_like, optional
        (n_out, n_freq): ordinary coherence for one input, multiple for several.
    estimator : str
        "H1", "H2", "Hv" or "" (synthesised).
    outputs, inputs : tuple of str
        Channel names.
    unit : str
        The FRF's unit.
    random_error : array_like, optional
        Normalised random error of |H| per line.
    params : mapping
        How it was made (estimator, window, nperseg, n_averages, exp_window_tau_s, flags).

    Raises
    ------
    ParameterError
        For shapes that do not match or an unknown form.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> h = vm.synth.modal_frf(np.linspace(1, 100, 100), fn=[30.0], zeta=[0.02], shapes=[[1.0]])
    >>> h.n_outputs, h.form
    (1, 'receptance')
    """

    freq: np.ndarray
    h: np.ndarray
    form: str = "receptance"
    coherence: np.ndarray | None = None
    estimator: str = ""
    outputs: tuple[str, ...] = ()
    inputs: tuple[str, ...] = ()
    unit: str = ""
    random_error: np.ndarray | None = None
    params: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        f = np.asarray(self.freq, dtype=float)
        h = np.asarray(self.h, dtype=complex)
        if h.ndim == 1:
            h = h[np.newaxis, np.newaxis]
        elif h.ndim == 2:
            h = h[:, np.newaxis]
        if f.ndim != 1 or h.ndim != 3 or h.shape[2] != f.size:
            raise ParameterError(f"h must have shape (n_out, n_in, {f.size}) (or 1-D for one pair), got "
                                 f"{np.shape(self.h)}")
        if self.form not in (*_FORM_ORDER, "unknown"):
            raise ParameterError(f"form={self.form!r} must be 'receptance', 'mobility', 'accelerance' or 'unknown'")
        if f.size > 1 and np.any(np.diff(f) <= 0):
            raise ParameterError("freq must increase")
        outs = tuple(self.outputs) or tuple(f"out{i}" for i in range(h.shape[0]))
        ins = tuple(self.inputs) or tuple(f"in{i}" for i in range(h.shape[1]))
        if len(outs) != h.shape[0] or len(ins) != h.shape[1]:
            raise ParameterError(f"outputs/inputs name {len(outs)}/{len(ins)} channels for h of shape {h.shape}")
        coh = None if self.coherence is None else np.asarray(self.coherence, float).reshape(h.shape[0], f.size)
        err = None if self.random_error is None else np.asarray(self.random_error, float).reshape(h.shape)
        for a in (f, h) + tuple(x for x in (coh, err) if x is not None):
            a.setflags(write=False)
        object.__setattr__(self, "freq", f)
        object.__setattr__(self, "h", h)
        object.__setattr__(self, "coherence", coh)
        object.__setattr__(self, "random_error", err)
        object.__setattr__(self, "outputs", outs)
        object.__setattr__(self, "inputs", ins)
        object.__setattr__(self, "params", MappingProxyType(dict(self.params)))

    @property
    def n_outputs(self) -> int:
        return self.h.shape[0]

    @property
    def n_inputs(self) -> int:
        return self.h.shape[1]

    @property
    def df(self) -> float:
        return float(self.freq[1] - self.freq[0]) if self.freq.size > 1 else float("nan")

    def to(self, form: str) -> "FRF":
        """The same FRF in another form, multiplying by (i w)^k; converting back returns the data exactly.

        Parameters
        ----------
        form : {"receptance", "mobility", "accelerance"}
            The target form.

        Returns
        -------
        FRF

        Raises
        ------
        ParameterError
            For an unknown form, or an FRF whose form is unknown.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> h = vm.synth.modal_frf(np.linspace(1, 100, 100), fn=[30.0], zeta=[0.02], shapes=[[1.0]])
        >>> h.to("mobility").form
        'mobility'
        """
        import dataclasses
        if form not in _FORM_ORDER:
            raise ParameterError(f"form={form!r} must be 'receptance', 'mobility' or 'accelerance'")
        if self.form == "unknown":
            raise ParameterError("this FRF's form is unknown (output quantity not given): cannot convert")
        origin = self.params.get("_origin")
        if origin is not None and origin[0] == form:
            h = origin[1]
        else:
            k = _FORM_ORDER[form] - _FORM_ORDER[self.form]
            jw = 2j * np.pi * self.freq
            with np.errstate(divide="ignore", invalid="ignore"):
                h = self.h * jw ** k
            origin = origin or (self.form, self.h)
        return dataclasses.replace(self, h=h, form=form, unit="", params=dict(self.params, _origin=origin))

    def select(self, outputs=None, inputs=None) -> "FRF":
        """A sub-FRF with the named (or indexed) outputs and inputs.

        Parameters
        ----------
        outputs, inputs : str, int or sequence, optional
            Default all.

        Returns
        -------
        FRF

        Raises
        ------
        ParameterError
            For an unknown or out-of-range output or input.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> h = vm.synth.modal_frf(np.linspace(1, 100, 100), fn=[30.0], zeta=[0.02], shapes=[[1.0], [0.5]])
        >>> h.select(outputs=[1]).n_outputs
        1
        """
        import dataclasses

        from ._validate import select_names

        def pick(names, want, what):
            return select_names(names, want, source=f"this FRF's {what}s")
        io_, ii = pick(self.outputs, outputs, "output"), pick(self.inputs, inputs, "input")
        return dataclasses.replace(
            self, h=self.h[np.ix_(io_, ii)], outputs=tuple(self.outputs[i] for i in io_),
            inputs=tuple(self.inputs[i] for i in ii),
            coherence=None if self.coherence is None else self.coherence[io_],
            random_error=None if self.random_error is None else self.random_error[np.ix_(io_, ii)],
            params={k: v for k, v in self.params.items() if k != "_origin"})

    def to_frame(self):
        """A long pandas table: freq_hz, output, input, re, im, magnitude, phase_deg (and coherence).

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
        >>> h = vm.synth.modal_frf(np.linspace(1, 100, 100), fn=[30.0], zeta=[0.02], shapes=[[1.0]])
        >>> len(h.to_frame())
        100
        """
        import pandas as pd
        rows = []
        for o in range(self.n_outputs):
            for i in range(self.n_inputs):
                h = self.h[o, i]
                d = {"freq_hz": self.freq, "output": self.outputs[o], "input": self.inputs[i], "re": h.real,
                     "im": h.imag, "magnitude": np.abs(h), "phase_deg": np.degrees(np.angle(h))}
                if self.coherence is not None:
                    d["coherence"] = self.coherence[o]
                rows.append(pd.DataFrame(d))
        return pd.concat(rows, ignore_index=True)

    def __repr__(self) -> str:
        return (f"FRF({self.form}, {self.n_outputs} out x {self.n_inputs} in x {self.freq.size} lines, "
                f"df={self.df:.4g} Hz, {self.estimator or 'given'})")


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


@dataclass(frozen=True)
class Diagnosis:
    """A machine diagnosis (``vm.diagnose``).

    Attributes
    ----------
    top : str
        The answer: none, unbalance, misalignment, looseness, bearing_outer_race, bearing_inner_race,
        bearing_ball, gear_mesh, resonance or electrical.
    confidence : float
        The probability that ``top`` is right, calibrated on synthetic machines
        (monitor/calibration.py); ``extras["score"]`` is the raw evidence score it was mapped from.
    reason : str
        Why, in words: the evidence, the strongest candidate of a "none", what was not checked.
    faults : pandas.DataFrame
        One row per fault family: evidence, p-value (bearing families), channel, pre-processing, band.
    speed : dict
        Declared and estimated rpm, the 1X line's height, consistency with fs and the note.
    severity : dict
        ISO 10816-3 velocity RMS (mm/s), its band, group, foundation and zone.
    envelope_band_hz : tuple
        The demodulation band of the envelope spectrum that carries the top (or strongest) bearing family.
    flags : tuple of str
        Quality flags (``speed_corrected``, ``unit_unknown``, ``band_limited``, ...).
    extras : dict
        The bearing test per family, that envelope spectrum and the kurtogram (for plots), the data
        quality findings.
    channel : str
        The channel that carries the top's evidence.
    bearing_checked : bool
        False without a bearing, or where the declared speed is contradicted.

    Raises
    ------
    ParameterError
        Never for a ``vm.diagnose`` result.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> rec = vm.synth.machine(fault="unbalance", rpm=1797, duration=4.0, seed=1)
    >>> d = vm.diagnose(rec, rpm=1797, bearing="6205-2RS")
    >>> d.top
    'unbalance'
    """

    top: str
    confidence: float
    reason: str
    faults: object
    speed: dict
    severity: dict
    envelope_band_hz: tuple
    flags: tuple = ()
    extras: dict = field(default_factory=dict)
    channel: str = ""
    bearing_checked: bool = False

    def to_dict(self) -> dict:
        """The diagnosis as plain JSON-ready values (the CLI's ``--json`` document).

        Returns
        -------
        dict
            top, confidence, score, reason, channel, bearing_checked, faults (records), speed, severity,
            envelope_band_hz, flags, also, measured_top_hz.

        Raises
        ------
        ParameterError
            Never for a valid object.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> d = vm.diagnose(vm.synth.machine(fault="unbalance", rpm=1797, duration=2.0, seed=1), rpm=1797)
        >>> d.to_dict()["top"]
        'unbalance'
        """
        return jsonable({"top": self.top, "confidence": self.confidence, "score": self.extras.get("score"),
                         "reason": self.reason,
                         "channel": self.channel, "bearing_checked": self.bearing_checked,
                         "faults": self.faults.to_dict(orient="records"), "speed": self.speed,
                         "severity": self.severity, "envelope_band_hz": list(self.envelope_band_hz),
                         "flags": list(self.flags), "also": list(self.extras.get("also", ())),
                         "measured_top_hz": self.extras.get("measured_top_hz")})

    def __repr__(self) -> str:
        return f"Diagnosis(top={self.top!r}, confidence={self.confidence:.2f}: {self.reason})"
