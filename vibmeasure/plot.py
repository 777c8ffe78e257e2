"""Pictures of records and results (the only module that imports matplotlib).

Each function draws on the given axes (or new ones) and returns them; nothing is computed
here beyond what drawing needs.
"""

from __future__ import annotations

import numpy as np

from .core._validate import response_channel
from .core.errors import ParameterError
from .core.record import Record
from .core.results import ModalEstimate

__all__ = ["plot_ringdown", "plot_spectrum", "decay_model"]


def decay_model(est: ModalEstimate, t: np.ndarray) -> np.ndarray:
    """The fitted free decay of an estimate at times t (s, from the fit start), summed over modes."""
    y = np.zeros_like(t, dtype=float)
    for fn, z, a, ph in zip(est.fn, est.zeta, est.amplitude, est.phase):
        if not (np.isfinite(fn) and np.isfinite(z) and np.isfinite(a) and np.isfinite(ph)):
            continue
        wn = 2 * np.pi * fn
        y += a * np.exp(-z * wn * t) * np.cos(wn * np.sqrt(1 - z * z) * t + ph)
    return y


def plot_ringdown(rec: Record, est: ModalEstimate, *, channel=None, axes=None):
    """The record, the fitted decay and its envelope, and the residual (two stacked axes).

    Returns the pair of axes (signal, residual).
    """
    import matplotlib.pyplot as plt
    if not isinstance(rec, Record):
        raise ParameterError(f"rec must be a vm.Record, got {type(rec).__name__}")
    if not isinstance(est, ModalEstimate):
        raise ParameterError(f"est must be a vm.ModalEstimate, got {type(est).__name__}")
    ch = est.extras.get("channel", None) if channel is None else channel
    idx = response_channel(rec, ch)
    x = np.asarray(rec.data[idx], float)
    t = rec.time
    if axes is None:
        fig, axes = plt.subplots(2, 1, sharex=True, figsize=(9, 5.5), gridspec_kw={"height_ratios": [3, 1]})
    ax, axr = axes
    c = rec.channels[idx]
    ax.plot(t, x, lw=0.6, color="0.45", label=f"{c.name} (measured)")
    t0 = float(est.extras.get("start_s", rec.t0))
    if est.method == "ml" and np.isfinite(est.amplitude).any():
        sel = t >= t0
        span = float(est.extras.get("fit_span_s", t[-1] - t0))
        sel &= t <= t0 + span
        tt = t[sel] - t0
        model = decay_model(est, tt)
        offset = np.median(x[sel] - model)
        ax.plot(t[sel], model + offset, lw=0.8, color="C0", label="fitted decay")
        env = np.zeros_like(tt)
        for fn, z, a in zip(est.fn, est.zeta, est.amplitude):
            if np.isfinite(z) and np.isfinite(fn):
                env += abs(a) * np.exp(-z * 2 * np.pi * fn * tt)
        ax.plot(t[sel], offset + env, "--", lw=1.0, color="C3", label="envelope")
        ax.plot(t[sel], offset - env, "--", lw=1.0, color="C3")
        axr.plot(t[sel], x[sel] - model - offset, lw=0.5, color="C2")
        axr.set_ylabel("residual")
    else:
        axr.set_visible(False)
    ax.axvline(t0, color="k", lw=0.6, ls=":")
    lines = [f"{fn:.5g} Hz, zeta {z:.4g}" + (f" ± {zs:.2g}" if np.isfinite(zs) else "")
             for fn, z, zs in zip(est.fn, est.zeta, est.zeta_std)]
    title = f"{est.method}: " + "; ".join(lines[:4]) + (" ..." if len(lines) > 4 else "")
    if est.flags:
        title += "\nflags: " + ", ".join(est.flags)
    ax.set_title(title, fontsize=9)
    ax.set_ylabel(f"{c.quantity} [{c.unit or '-'}]")
    axr.set_xlabel("time [s]")
    ax.legend(loc="upper right", fontsize=8)
    return ax, axr


def plot_spectrum(spec, *, ax=None, channel=None, peaks=None, lines=None, log: bool | None = None):
    """A spectrum (one or all channels) with optional picked peaks and labelled reference lines.

    ``lines`` maps a label to a frequency in Hz (e.g. {"BPFO": 107.4}); ``log`` defaults to a
    logarithmic amplitude axis for PSDs.
    """
    import matplotlib.pyplot as plt
    from .core.results import Spectrum
    if not isinstance(spec, Spectrum):
        raise ParameterError(f"spec must be a vm.Spectrum, got {type(spec).__name__}")
    if ax is None:
        _, ax = plt.subplots(figsize=(9, 4.5))
    rows = range(spec.n_channels) if channel is None else [spec.channels.index(channel)
                                                           if isinstance(channel, str) else channel]
    for i in rows:
        ax.plot(spec.freq, np.abs(spec.values[i]), lw=0.7, label=spec.channels[i])
    if peaks is not None and len(peaks):
        ax.plot(peaks.freq, peaks.amplitude, "v", color="C3", ms=5, label="peaks")
        for f, a in zip(peaks.freq[:10], peaks.amplitude[:10]):
            ax.annotate(f"{f:.4g}", (f, a), textcoords="offset points", xytext=(3, 4), fontsize=7)
    for label, f in (lines or {}).items():
        ax.axvline(f, color="0.5", lw=0.6, ls="--")
        ax.text(f, 1.0, f" {label}", transform=ax.get_xaxis_transform(), rotation=90, va="top", fontsize=7)
    if log if log is not None else spec.kind in ("psd", "power"):
        ax.set_yscale("log")
    ax.set_xlabel("frequency [Hz]")
    ylab = {"amplitude": f"amplitude ({spec.params.get('scaling', 'peak')})", "psd": "PSD", "power": "power",
            "envelope": "squared-envelope spectrum"}.get(spec.kind, spec.kind)
    ax.set_ylabel(f"{ylab} [{spec.unit or '-'}]")
    ax.set_title(f"{spec.kind}: window {spec.params.get('window', '?')}, nperseg {spec.params.get('nperseg', '?')}, "
                 f"df {spec.df:.4g} Hz, {spec.params.get('n_averages', 1)} averages", fontsize=9)
    ax.legend(loc="upper right", fontsize=8)
    return ax
