"""Spectra with their labelled peaks, shock response spectra and transmissibility."""

from __future__ import annotations

import numpy as np

from ..core._validate import name_index
from ..core.errors import ParameterError
from ..plotstyle import ANNOTATION_SIZE, COLORS
from ._figure import new_figure
from ._style import _styled


@_styled
def plot_spectrum(spec, *, ax=None, channel=None, peaks=None, lines=None, log: bool | None = None,
                  db: bool = False, fmax: float | None = None):
    """A spectrum (one or all channels) with picked peaks and labelled reference lines.

    Peak labels that would print on top of each other are left out, strongest peaks first.

    Parameters
    ----------
    spec : Spectrum
        The spectrum.
    ax : matplotlib.axes.Axes, optional
        Where to draw.
    channel : str or int, optional
        One channel (default all).
    peaks : Peaks or list of Peaks, optional
        Picked peaks to mark and label, each channel's in its line's colour.
    lines : dict, optional
        Label -> frequency in Hz (e.g. {"BPFO": 107.4}).
    log : bool, optional
        Logarithmic amplitude axis (default for PSDs).
    db : bool
        Decibels re 1 unit (20 log10 of amplitudes, 10 log10 of powers).
    fmax : float, optional
        End of the frequency axis (default where the content ends).

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on; ``fig.panels`` holds its axes (spectrum,) (the figure unpacks
        into them).

    Raises
    ------
    ParameterError
        For an unknown channel.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure import plot
    >>> rec = vm.synth.machine(rpm=1797, duration=1.0, seed=1)
    >>> spec = vm.amplitude_spectrum(rec)
    >>> fig = plot.plot_spectrum(spec, peaks=vm.pick_peaks(spec, n=5), lines={"1X": 29.95})
    """

    from ..core.results import Spectrum
    if not isinstance(spec, Spectrum):
        raise ParameterError(f"spec must be a vm.Spectrum, got {type(spec).__name__}")
    if fmax is not None:
        from ..core._validate import positive
        try:
            fmax = positive(fmax, "fmax")
        except ParameterError:
            raise ParameterError(f"fmax={fmax!r} must be a positive frequency in Hz") from None
    if not isinstance(db, (bool, np.bool_)):
        raise ParameterError(f"db={db!r} must be True or False")
    if ax is None:
        _, ax = new_figure(figsize=(9, 4.5))
    rows = range(spec.n_channels) if channel is None else [name_index(spec.channels, channel)]
    power = spec.kind in ("psd", "power")

    def scaled(v):
        v = np.abs(np.asarray(v, float))
        if not db:
            return v
        return (10 if power else 20) * np.log10(np.maximum(v, 1e-300))
    colour = {}
    for i in rows:
        (ln,) = ax.plot(spec.freq, scaled(spec.values[i]), lw=0.7, label=spec.channels[i])
        colour[spec.channels[i]] = ln.get_color()
    top = fmax if fmax is not None else _content_end(spec, rows)
    ax.set_xlim(spec.freq[0], min(top, spec.freq[-1]))
    if not db and (log if log is not None else power):
        ax.set_yscale("log")
    if db:
        vis = (spec.freq > 0) & (spec.freq <= top)
        peak = max(float(np.max(scaled(spec.values[i][vis]))) for i in rows) if vis.any() else 0.0
        ax.set_ylim(bottom=peak - (100 if power else 80), top=peak + 6)
    _mark_peaks(ax, peaks, scaled, colour)
    for label, f in (lines or {}).items():
        ax.axvline(f, color="0.5", lw=0.6, ls="--")
        ax.text(f, 1.0, f" {label}", transform=ax.get_xaxis_transform(), rotation=90, va="top",
                fontsize=ANNOTATION_SIZE)
    ax.set_xlabel("frequency [Hz]")
    ylab = {"amplitude": f"amplitude ({spec.params.get('scaling', 'peak')})", "psd": "PSD", "power": "power",
            "envelope": "squared-envelope spectrum"}.get(spec.kind, spec.kind)
    unit = spec.unit or "-"
    ax.set_ylabel(f"{ylab} [dB re 1 {unit}]" if db else f"{ylab} [{unit}]")
    ax.set_title(f"{spec.kind}: window {spec.params.get('window', '?')}, nperseg {spec.params.get('nperseg', '?')}, "
                 f"df {spec.df:.4g} Hz, {spec.params.get('n_averages', 1)} averages")
    ax.legend(loc="upper right")
    return ax


def _content_end(spec, rows) -> float:
    """The frequency above which every drawn channel stays 60 dB (amplitude) below its largest
    non-DC line, with a 5 % margin; the whole axis when the content reaches Nyquist."""
    f = spec.freq
    power = spec.kind in ("psd", "power")
    last = 0.0
    for i in rows:
        v = np.abs(np.asarray(spec.values[i], float))
        v = v ** 0.5 if power else v
        nz = f > 0
        if not nz.any() or not np.any(v[nz] > 0):
            return float(f[-1])
        above = np.flatnonzero(nz & (v > 1e-3 * np.max(v[nz])))
        last = max(last, float(f[above[-1]]))
    return float(f[-1]) if last >= 0.95 * f[-1] else min(float(f[-1]), 1.05 * last)


def _mark_peaks(ax, peaks, scaled, colour):
    """Each channel's peaks (a Peaks or a list of them, one per channel) in its line's colour, the ten
    strongest of each labelled with their frequency in that colour."""
    from ..core.results import Peaks
    plist = [peaks] if isinstance(peaks, Peaks) else [p for p in (peaks or []) if p is not None]
    xs, ys, texts, cols = [], [], [], []
    for pk in plist:
        if not len(pk):
            continue
        c = colour.get(pk.channel, COLORS["mode"])
        ax.plot(pk.freq, scaled(pk.amplitude), "v", color=c, ms=5,
                label="peaks" if len(plist) == 1 else f"peaks {pk.channel}")
        xs += list(pk.freq[:10])
        ys += list(scaled(pk.amplitude[:10]))
        texts += [f"{f:.4g}" for f in pk.freq[:10]]
        cols += [c] * min(10, len(pk))
    if xs:
        _label_without_collisions(ax, np.array(xs), np.array(ys), texts, colors=cols)


def _label_without_collisions(ax, xs, ys, texts, *, size: float = ANNOTATION_SIZE, colors=None):
    """Label points (strongest first) just above them, each where it overlaps no label placed
    before; a label lifted above its first place gets a leader line to its point, and a label that
    fits nowhere near its point is left out."""
    ax.autoscale_view()
    to_px = ax.transData.transform
    pt = ax.figure.dpi / 72.0
    placed: list[tuple[float, float, float, float]] = []
    for k in np.argsort(-np.asarray(ys, float), kind="stable"):
        px, py = to_px((xs[k], ys[k]))
        w, h = 0.62 * size * len(texts[k]) * pt, 1.25 * size * pt
        for dy in (4.0, 4.0 + 1.4 * size, 4.0 + 2.8 * size):
            box = (px + 2 * pt, px + 2 * pt + w, py + dy * pt, py + dy * pt + h)
            if not any(box[0] < b[1] and b[0] < box[1] and box[2] < b[3] and b[2] < box[3] for b in placed):
                lead = {"arrowprops": {"arrowstyle": "-", "lw": 0.5, "color": "0.4", "shrinkA": 0, "shrinkB": 2}} \
                    if dy > 4.0 else {}
                ax.annotate(texts[k], (xs[k], ys[k]), textcoords="offset points", xytext=(2, dy), fontsize=size,
                            color=colors[k] if colors is not None else "black", **lead)
                placed.append(box)
                break


@_styled
def plot_srs(spec, *, ax=None, tripartite: bool | None = None):
    """Shock response spectrum on log axes.

    For pseudo-velocity output (or ``tripartite=True``) the tripartite grid: pseudo-velocity against
    frequency with lines of constant relative displacement (falling) and pseudo-acceleration (rising).

    Parameters
    ----------
    spec : ShockSpectrum
        A ``vm.srs`` result.
    ax : matplotlib.axes.Axes, optional
        Where to draw (default a new figure).
    tripartite : bool, optional
        Draw the tripartite grid (default for pseudo-velocity output).

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on; ``fig.panels`` holds its axes (srs,) (the figure unpacks
        into them).

    Raises
    ------
    ParameterError
        For an object that is no shock response spectrum.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure import plot
    >>> t = np.arange(1000) / 20000.0
    >>> sp = vm.srs(vm.Record.from_array(np.where(t < 0.002, 50 * np.sin(np.pi * t / 0.002), 0.0), fs=20000.0, unit="g"))
    >>> fig = plot.plot_srs(sp)
    """
    if ax is None:
        _, ax = new_figure(figsize=(7, 5.5), layout="constrained")
    tri = spec.output == "pseudo_velocity" if tripartite is None else bool(tripartite)
    w = 2 * np.pi * spec.fn
    span = []
    for k, v in spec.values.items():
        y = v
        if tri and spec.output == "acceleration":
            from ..core import units
            y = units.convert(v, spec.unit, "m/s^2") / w if spec.unit else v / w
        elif tri and spec.output == "relative_displacement":
            y = v * w
        ax.loglog(spec.fn, y, lw=1.6 if k == "maximax" else 1.0, label=k)
        if k == "maximax":
            span = [float(np.min(y[y > 0])) / 3 if np.any(y > 0) else 1e-12, float(np.max(y)) * 3]
    if span:   # a residual that decayed to nothing would stretch the axis over hundreds of decades
        ax.set_ylim(*span)
    ax.set_xlabel("natural frequency [Hz]")
    q = f"Q {1 / (2 * spec.zeta):.3g}" if spec.zeta > 0 else "undamped"
    if tri:
        ax.set_ylabel("pseudo-velocity [m/s]" if spec.unit else "pseudo-velocity [input unit x s]")
        lo, hi = ax.get_ylim()
        f0, f1 = spec.fn[0], spec.fn[-1]
        for d in 10.0 ** np.arange(-9, 2):
            ax.loglog([f0, f1], [2 * np.pi * f0 * d, 2 * np.pi * f1 * d], color="0.85", lw=0.5, zorder=0)
        for a in 10.0 ** np.arange(-3, 7):
            ax.loglog([f0, f1], [a / (2 * np.pi * f0), a / (2 * np.pi * f1)], color="0.85", lw=0.5, ls="--", zorder=0)
        ax.set_ylim(lo, hi)
        ax.set_title(f"shock response spectrum, tripartite ({q}; grey: constant displacement m, dashed: constant "
                     "acceleration m/s^2)", fontsize=8)
    else:
        qty = {"acceleration": "peak acceleration", "relative_displacement": "peak relative displacement"}
        ax.set_ylabel(f"{qty.get(spec.output, spec.output)} [{spec.unit or 'input unit, not stated'}]")
        ax.set_title(f"shock response spectrum of {spec.channel} ({q})", fontsize=9)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=8, loc="lower right")
    return ax


@_styled
def plot_transmissibility(tr, *, ax=None):
    """Measured |T| (and the model's, where given) on log axes, coherence below, the isolation region
    (|T| < 1) shaded.

    Parameters
    ----------
    tr : Transmissibility
        A ``vm.transmissibility`` result.
    ax : matplotlib.axes.Axes, optional
        Where to draw |T|.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on; ``fig.panels`` holds its axes (|T|, coherence) on a new figure, (|T|,) on given axes (the figure unpacks
        into them).

    Raises
    ------
    ParameterError
        For an object that is no transmissibility.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure import plot
    >>> iso = vm.models.SDOF(m=1.0, k=3948.0, zeta=0.05)
    >>> tr = vm.transmissibility(vm.synth.base_excited(iso, fs=500.0, duration=30.0, seed=1), base="base", top="top")
    >>> fig = plot.plot_transmissibility(tr)
    """
    if ax is None:
        fig, (ax, axc) = new_figure(2, 1, figsize=(8, 6), sharex=True, height_ratios=(3, 1), layout="constrained")
    else:
        axc = None
    ax.loglog(tr.freq, tr.magnitude, lw=1.0, label=f"measured {tr.top}/{tr.base}")
    if tr.model is not None:
        ax.loglog(tr.freq, tr.model, "k--", lw=0.9, label="model")
    ax.axhline(1.0, color="0.5", lw=0.6)
    iso = tr.isolation_hz
    if np.isfinite(iso):
        ax.axvspan(iso, tr.freq[-1], color="C2", alpha=0.08, label=f"isolation above {iso:.3g} Hz")
    ax.set_ylabel("transmissibility |T| [-]")
    ax.legend(fontsize=8)
    if axc is not None:
        axc.semilogx(tr.freq, tr.coherence, lw=0.8)
        axc.set_ylim(0, 1.05)
        axc.set_ylabel("coherence [-]")
        axc.set_xlabel("frequency [Hz]")
    else:
        ax.set_xlabel("frequency [Hz]")
    return ax if axc is None else (ax, axc)
