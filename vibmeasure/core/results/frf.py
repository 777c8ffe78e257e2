"""FRF: frequency response functions with their coherence, random error and form."""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from ..errors import ParameterError

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

        from .._validate import select_names

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
