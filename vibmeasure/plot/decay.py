"""Ring-down pictures: the record with its fitted decay and residual, and a mode's backbone."""

from __future__ import annotations

import numpy as np

from ..core._validate import response_channel
from ..core.errors import ParameterError
from ..core.record import Record
from ..core.results import ModalEstimate
from ..core.results._common import shown_flags
from ..core.rounding import with_std
from ..plotstyle import COLORS
from ._figure import new_figure
from ._style import _styled


def decay_model(est: ModalEstimate, t: np.ndarray) -> np.ndarray:
    """The fitted free decay of an estimate at times t (s, from the fit start), summed over modes.

    Parameters
    ----------
    est : ModalEstimate
        A ``vm.ringdown`` estimate.
    t : numpy.ndarray
        Times in s from the fit's start.

    Returns
    -------
    numpy.ndarray

    Raises
    ------
    ParameterError
        Never for a ringdown estimate; modes without amplitude or phase are left out.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure import plot
    >>> rec = vm.synth.free_decay(fn=10.0, zeta=0.02, fs=500.0, duration=4.0, snr_db=40, seed=1)
    >>> y = plot.decay_model(vm.ringdown(rec), np.arange(100) / 500.0)
    >>> y.shape
    (100,)
    """
    y = np.zeros_like(t, dtype=float)
    for fn, z, a, ph in zip(est.fn, est.zeta, est.amplitude, est.phase):
        if not (np.isfinite(fn) and np.isfinite(z) and np.isfinite(a) and np.isfinite(ph)):
            continue
        wn = 2 * np.pi * fn
        y += a * np.exp(-z * wn * t) * np.cos(wn * np.sqrt(1 - z * z) * t + ph)
    return y


@_styled
def plot_ringdown(rec: Record, est: ModalEstimate, *, channel=None, axes=None):
    """The record, the fitted decay and its envelope, and the residual (two stacked axes).

    Parameters
    ----------
    rec : Record
        The ring-down.
    est : ModalEstimate
        Its ``vm.ringdown`` estimate.
    channel : str or int, optional
        The channel (default the one the estimate was fitted on).
    axes : sequence of two Axes, optional
        Where to draw (signal, residual).

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on; ``fig.panels`` holds its axes (signal, residual) (the figure unpacks
        into them).

    Raises
    ------
    ParameterError
        For a channel the estimate does not belong to.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure import plot
    >>> rec = vm.synth.free_decay(fn=10.0, zeta=0.02, fs=500.0, duration=4.0, snr_db=40, seed=1)
    >>> fig = plot.plot_ringdown(rec, vm.ringdown(rec))
    >>> [ax.get_xlabel() for ax in fig.panels]
    ['', 'time [s]']
    """
    if not isinstance(rec, Record):
        raise ParameterError(f"rec must be a vm.Record, got {type(rec).__name__}")
    if not isinstance(est, ModalEstimate):
        raise ParameterError(f"est must be a vm.ModalEstimate, got {type(est).__name__}")
    ch = est.extras.get("channel", None) if channel is None else channel
    idx = response_channel(rec, ch)
    x = np.asarray(rec.data[idx], float)
    t = rec.time
    if axes is None:
        fig, axes = new_figure(2, 1, sharex=True, figsize=(9, 5.5), gridspec_kw={"height_ratios": [3, 1]})
    ax, axr = axes
    c = rec.channels[idx]
    band = est.extras.get("band_hz")
    what_data = "measured"
    if band:  # the fit reports the band's modes: show the band's signal, or an impact transient hides the fit
        from scipy import signal as _sig
        lo, hi = float(band[0]), min(float(band[1]), 0.49 * rec.fs)
        sos = _sig.butter(4, (max(lo, 1e-3 * rec.fs), hi), btype="bandpass", fs=rec.fs, output="sos")
        x = _sig.sosfiltfilt(sos, x - np.median(x))
        what_data = f"measured, band-passed {lo:.4g}-{hi:.4g} Hz"
    ax.plot(t, x, lw=0.6, color=COLORS["measured"], label=f"{c.name} ({what_data})")
    t0 = float(est.extras.get("start_s", rec.t0))
    if est.method == "ml" and np.isfinite(est.amplitude).any():
        sel = t >= t0
        span = float(est.extras.get("fit_span_s", t[-1] - t0))
        sel &= t <= t0 + span
        tt = t[sel] - t0
        model = decay_model(est, tt)
        offset = np.median(x[sel] - model)
        ax.plot(t[sel], model + offset, lw=0.8, color=COLORS["fit"], label="fitted decay")
        env = np.zeros_like(tt)
        for fn, z, a in zip(est.fn, est.zeta, est.amplitude):
            if np.isfinite(z) and np.isfinite(fn):
                env += abs(a) * np.exp(-z * 2 * np.pi * fn * tt)
        ax.plot(t[sel], offset + env, "--", lw=1.0, color=COLORS["envelope"], label="envelope")
        ax.plot(t[sel], offset - env, "--", lw=1.0, color=COLORS["envelope"])
        axr.plot(t[sel], x[sel] - model - offset, lw=0.5, color=COLORS["residual"])
        axr.set_ylabel(f"residual [{rec.channels[idx].unit or '-'}]")
    else:
        axr.set_visible(False)
    if band:  # frame the decay, not the filter's start-up on the record's first samples
        settled = t >= t[0] + 3.0 / max(float(band[0]), 1e-3 * rec.fs)
        if settled.sum() > 16:
            top = float(np.max(np.abs(x[settled])))
            fitted = est.method == "ml" and np.isfinite(est.amplitude).any()
            if fitted:
                top = max(top, float(np.max(np.abs(model + offset))))
            ax.set_ylim(-1.15 * top, 1.15 * top)
            if fitted:
                late = settled[sel]
                r = np.abs((x[sel] - model - offset)[late])
                if r.size:
                    axr.set_ylim(-1.3 * r.max(), 1.3 * r.max())
    ax.axvline(t0, color="k", lw=0.6, ls=":")
    nan = np.full(est.n_modes, np.nan)
    fn_std, zeta_std = (nan if s is None else s for s in (est.fn_std, est.zeta_std))
    lines = [f"{with_std(fn, fs_)[0]} Hz, zeta " + " ± ".join(v for v in with_std(z, zs) if v != "n/a")
             for fn, fs_, z, zs in zip(est.fn, fn_std, est.zeta, zeta_std)]
    title = f"{est.method}: " + "; ".join(lines[:4]) + (" ..." if len(lines) > 4 else "")
    flags = shown_flags(est.flags, est.mode_flags)   # the report's flag table lists the same ones
    if flags:
        title += "\nflags: " + ", ".join(flags)
    ax.set_title(title, fontsize=9)
    what = c.quantity if c.quantity not in ("unknown", "", None) else c.name
    ax.set_ylabel(f"{what} [{c.unit or '-'}]")
    axr.set_xlabel("time [s]")
    ax.legend(loc="upper right", fontsize=8)
    return ax, axr


@_styled
def plot_backbone(est: ModalEstimate, *, mode: int = 0, axes=None):
    """The backbone of one mode of a ring-down estimate: fn and zeta against amplitude (error bars: one
    std per window) with the weakly nonlinear model of ``extras["backbone_model"]`` drawn over.

    Parameters
    ----------
    est : ModalEstimate
        A ``vm.ringdown`` estimate.
    mode : int
        The mode.
    axes : sequence of two Axes, optional
        Where to draw (fn, zeta).

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on; ``fig.panels`` holds its axes (fn, zeta) (the figure unpacks
        into them).

    Raises
    ------
    ParameterError
        For a mode without a backbone (too few cycles above the noise).

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure import plot
    >>> rec = vm.synth.free_decay(fn=10.0, zeta=0.01, fs=500.0, duration=20.0, snr_db=50, seed=1)
    >>> fig = plot.plot_backbone(vm.ringdown(rec))
    """
    bb = est.extras.get("backbone")
    if bb is None or len(bb) == 0 or mode not in set(bb["mode"]):
        raise ParameterError(f"mode={mode} has no backbone in this estimate (too few cycles above the noise)")
    b = bb[bb["mode"] == mode]
    if axes is None:
        _, axes = new_figure(1, 2, figsize=(9, 3.5), constrained_layout=True)
    unit = est.unit or "-"
    A = b["amplitude"].to_numpy(float)
    axes[0].errorbar(A, b["fn_hz"], yerr=b["fn_std_hz"], fmt="o", ms=3, lw=1, label="windows")
    axes[1].errorbar(A, b["zeta"], yerr=b["zeta_std"], fmt="o", ms=3, lw=1, label="windows")
    model = est.extras.get("backbone_model", {}).get(mode)
    if model and model.get("fits", True):   # a model that does not fit the windows is not drawn
        a = np.linspace(A.min(), A.max(), 200)
        w2 = (2 * np.pi * model["fn0_hz"]) ** 2 + 0.75 * model["k3_over_m"] * a ** 2
        axes[0].plot(a, np.sqrt(np.maximum(w2, 0)) / (2 * np.pi), "r-", lw=1, label="Duffing model")
        axes[1].plot(a, model["zeta_viscous"] + model["friction_term"] / a + model["quadratic_term"] * a, "r-",
                     lw=1, label="viscous + friction + quadratic")
    for ax, lab in zip(axes, ("natural frequency fn [Hz]", "damping ratio zeta [-]")):
        ax.set_xlabel(f"amplitude [{unit}]")
        ax.set_ylabel(lab)
        ax.legend(fontsize=8)
    axes[0].set_title(f"backbone of the {est.fn[mode]:.4g} Hz mode", fontsize=10)
    return axes
