"""FRFs (Bode, Nyquist), the stabilisation diagram, MAC, singular values and model comparison."""

from __future__ import annotations

import numpy as np

from ..core._validate import name_index
from ..core.errors import ParameterError
from ..plotstyle import COLORS
from ._figure import new_figure
from ._style import _styled


@_styled
def plot_frf(frf, *, est=None, output=0, input=0, axes=None):
    """Bode plot (magnitude, phase) of one FRF with its coherence, and the FRF synthesised from a
    fit_modes estimate when given.

    Parameters
    ----------
    frf : FRF
        The FRFs.
    est : ModalEstimate, optional
        A ``fit_modes`` estimate to draw over.
    output, input : int or str
        The FRF row and column.
    axes : sequence of three Axes, optional
        Where to draw (magnitude, phase, coherence).

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on; ``fig.panels`` holds its axes (magnitude, phase, coherence) (the figure unpacks
        into them).

    Raises
    ------
    ParameterError
        For an unknown output or input.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure import plot
    >>> h = vm.synth.modal_frf(np.linspace(1, 100, 500), fn=[30.0], zeta=[0.02], shapes=[[1.0]])
    >>> fig = plot.plot_frf(h)
    """

    from ..core.results import FRF
    if not isinstance(frf, FRF):
        raise ParameterError(f"frf must be a vm.FRF, got {type(frf).__name__}")
    o = name_index(frf.outputs, output, what="output")
    i = name_index(frf.inputs, input, what="input")
    if axes is None:
        fig, axes = new_figure(3, 1, sharex=True, figsize=(9, 7), gridspec_kw={"height_ratios": [3, 1.5, 1]})
    am, ap, ac = axes
    h = frf.h[o, i]
    am.semilogy(frf.freq, np.abs(h), lw=0.8, color=COLORS["measured"], label=f"{frf.outputs[o]}/{frf.inputs[i]} ({frf.estimator or 'data'})")
    ap.plot(frf.freq, np.degrees(np.angle(h)), lw=0.8, color=COLORS["measured"])
    if est is not None and "poles" in est.extras:
        from ..identify.modal import synthesize_frf
        band = est.extras.get("band_hz", (frf.freq[0], frf.freq[-1]))
        sel = (frf.freq >= band[0]) & (frf.freq <= band[1]) & (frf.freq > 0)
        full = "residual_terms" in est.extras
        hs = synthesize_frf(est, frf.freq[sel], residuals=full)
        rows = est.extras.get("rows") or est.extras.get("outputs") or []
        name = f"{frf.outputs[o]}/{frf.inputs[i]}" if est.extras.get("rows") else frf.outputs[o]
        if name in rows:
            k = rows.index(name)
            am.semilogy(frf.freq[sel], np.abs(hs[k]), "--", lw=0.9, color=COLORS["fit"],
                        label="synthesised (modes + residual terms)" if full else "synthesised (modes only)")
        for f in est.fn:
            am.axvline(f, color="0.6", lw=0.5, ls=":")
    n_avg = frf.params.get("n_averages")
    if frf.coherence is not None and n_avg != 1:
        ac.plot(frf.freq, frf.coherence[o], lw=0.8, color="C2")
    else:  # one average: coherence is 1 by construction and says nothing
        ac.text(0.5, 0.5, "coherence not shown: " + ("one average (it is 1 by construction)" if n_avg == 1
                                                     else "not measured"),
                transform=ac.transAxes, ha="center", va="center", fontsize=8, color="0.4")
    ac.set_ylim(0, 1.05)
    am.set_ylabel(f"|H| {frf.form} [{frf.unit or '-'}]")
    ap.set_ylabel("phase [deg]")
    ac.set_ylabel("coherence [-]")
    ac.set_xlabel("frequency [Hz]")
    am.legend(loc="upper right")
    return am, ap, ac


@_styled
def plot_nyquist(frf, *, output=0, input=0, band=None, ax=None):
    """Nyquist plot (real against imaginary) of one FRF, optionally within a band.

    Parameters
    ----------
    frf : FRF
        The FRFs.
    output, input : int or str
        The FRF row and column.
    band : tuple of float, optional
        (lo, hi) Hz.
    ax : matplotlib.axes.Axes, optional
        Where to draw.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on; ``fig.panels`` holds its axes (nyquist,) (the figure unpacks
        into them).

    Raises
    ------
    ParameterError
        For an unknown output or input.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure import plot
    >>> h = vm.synth.modal_frf(np.linspace(1, 100, 500), fn=[30.0], zeta=[0.02], shapes=[[1.0]])
    >>> fig = plot.plot_nyquist(h, band=(25, 35))
    """
    if ax is None:
        _, ax = new_figure(figsize=(5.5, 5.5))
    o = name_index(frf.outputs, output, what="output")
    i = name_index(frf.inputs, input, what="input")
    sel = np.ones(frf.freq.size, bool) if band is None else (frf.freq >= band[0]) & (frf.freq <= band[1])
    h = frf.h[o, i, sel]
    ax.plot(h.real, h.imag, ".-", ms=3, lw=0.6)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"Re H [{frf.unit or '-'}]")
    ax.set_ylabel(f"Im H [{frf.unit or '-'}]")
    ax.set_title(f"Nyquist: {frf.outputs[o]}/{frf.inputs[i]} ({frf.form})", fontsize=9)
    return ax


@_styled
def plot_stabilisation(est, *, frf=None, ax=None):
    """The stabilisation diagram of a fit_modes or oma_ssi estimate.

    Poles per model order (o new, f stable in frequency, d also damping, s stable in frequency and
    damping, and for oma_ssi in shape), the chosen modes, and |H| (fit_modes, with ``frf``) or the
    outputs' mean PSD (oma_ssi) behind it.

    Parameters
    ----------
    est : ModalEstimate
        A ``fit_modes`` or ``oma_ssi`` estimate.
    frf : FRF, optional
        The FRFs behind a fit_modes diagram.
    ax : matplotlib.axes.Axes, optional
        Where to draw.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on; ``fig.panels`` holds its axes (stabilisation,) (the figure unpacks
        into them).

    Raises
    ------
    ParameterError
        For an estimate without a stabilisation table.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure import plot
    >>> h = vm.synth.modal_frf(np.linspace(1, 100, 1000), fn=[30.0], zeta=[0.02], shapes=[[1.0]])
    >>> fig = plot.plot_stabilisation(vm.fit_modes(h, band=(10, 60)), frf=h)
    """
    if "stabilisation" not in est.extras:
        raise ParameterError("est must come from vm.fit_modes or vm.oma_ssi (it carries the stabilisation table)")
    if ax is None:
        _, ax = new_figure(figsize=(9, 5), layout="constrained")
    tab = est.extras["stabilisation"]
    oma = est.method == "oma_ssi"
    style = {"o": dict(marker="o", color="0.7", ms=3, ls=""), "f": dict(marker="d", color="C1", ms=3, ls=""),
             "d": dict(marker="^", color="C2", ms=3, ls=""), "s": dict(marker="x", color="C0", ms=4, ls="")}
    labels = (("o", "new"), ("f", "stable f"), ("d", "stable f, zeta"), ("s", "stable f, zeta, shape")) if oma \
        else (("o", "new"), ("f", "stable f"), ("s", "stable f, zeta"))
    for key, label in labels:
        pts = [(row[1], row[0]) for row in tab if row[3] == key]
        if pts:
            ax.plot(*zip(*pts), label=label, **style[key])
    for f in est.fn:
        ax.axvline(f, color="C3", lw=0.8)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("model order")
    band = est.extras.get("band_hz")
    if frf is not None:
        ax2 = ax.twinx()
        sel = np.ones(frf.freq.size, bool) if not band else (frf.freq >= band[0]) & (frf.freq <= band[1])
        ax2.semilogy(frf.freq[sel], np.abs(frf.h[..., sel]).mean(axis=(0, 1)), color="0.3", lw=0.6)
        ax2.set_ylabel(f"mean |H| [{frf.unit or '-'}]")
    elif oma and "psd" in est.extras:
        p = est.extras["psd"]
        ax2 = ax.twinx()
        sel = np.ones(p["freq"].size, bool) if not band else (p["freq"] >= band[0]) & (p["freq"] <= band[1])
        ax2.semilogy(p["freq"][sel], p["values"][sel], color="0.3", lw=0.6)
        ax2.set_ylabel(f"mean PSD [{p['unit']}]")
    if band:
        ax.set_xlim(band[0], band[1])  # the fitted band, not the whole FRF
    # the legend under the axes, in one row: inside, it covered the poles of the lowest modes
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=6, fontsize=8, frameon=False)
    ax.set_title("stabilisation diagram (red: chosen modes)", fontsize=9)
    return ax


@_styled
def plot_mac(matrix, *, labels=None, ax=None):
    """A MAC matrix as an image with the values written in.

    Parameters
    ----------
    matrix : array_like
        The MAC matrix (``vm.mac``).
    labels : sequence of str, optional
        Mode labels.
    ax : matplotlib.axes.Axes, optional
        Where to draw.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on; ``fig.panels`` holds its axes (mac,) (the figure unpacks
        into them).

    Raises
    ------
    ParameterError
        For a matrix that is not 2-D.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure import plot
    >>> fig = plot.plot_mac(vm.mac(np.eye(3)))
    """
    m = np.asarray(matrix, float)
    if ax is None:
        _, ax = new_figure(figsize=(4.5, 4))
    ax.grid(False)  # no grid lines across an image
    im = ax.imshow(m, vmin=0, vmax=1, cmap="Blues")
    for (r, c), v in np.ndenumerate(m):
        ax.text(c, r, f"{v:.2f}", ha="center", va="center", fontsize=8, color="w" if v > 0.6 else "k")
    if labels is not None:
        ax.set_xticks(range(len(labels)), labels)
        ax.set_yticks(range(len(labels)), labels)
    ax.set_xlabel("mode (second set)")
    ax.set_ylabel("mode (first set)")
    ax.figure.colorbar(im, ax=ax, fraction=0.046)
    ax.set_title("MAC", fontsize=9)
    return ax


@_styled
def plot_comparison(cmp, *, rtol_fn: float = 0.02, rtol_zeta: float = 0.5, against: str = "model", ax=None):
    """Deviation of each measured fn from its prediction (%), coloured by verdict, with the alarm
    tolerance and, where known, one-std error bars; on a figure of its own also the zeta deviation.

    Parameters
    ----------
    cmp : Comparison
        A ``vm.compare`` result.
    rtol_fn : float
        The frequency tolerance drawn.
    rtol_zeta : float
        The damping tolerance drawn.
    against : {"model", "baseline"}
        What the prediction is, for the labels.
    ax : matplotlib.axes.Axes, optional
        Where to draw the fn deviations.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on; ``fig.panels`` holds its axes (fn, zeta) on a new figure, (fn,) on given axes (the figure unpacks
        into them).

    Raises
    ------
    ParameterError
        For an object that is no comparison.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure import plot
    >>> est = vm.ringdown(vm.synth.free_decay(fn=10.0, zeta=0.02, fs=500.0, duration=8.0, snr_db=40, seed=1))
    >>> cmp = vm.compare(est, vm.models.SDOF(m=1.0, k=(2 * np.pi * 10.1) ** 2, zeta=0.02))
    >>> fig = plot.plot_comparison(cmp)
    """

    from ..core._validate import positive
    rtol_fn, rtol_zeta = positive(rtol_fn, "rtol_fn"), positive(rtol_zeta, "rtol_zeta")
    ax_z = None
    if ax is None:
        _, (ax, ax_z) = new_figure(1, 2, figsize=(10, 4), width_ratios=(3, 2))
    colors = {"ok": COLORS["ok"], "watch": COLORS["watch"], "alarm": COLORS["alarm"]}
    labels = [f"{r['fn_predicted_hz']:.4g} Hz" for r in cmp.rows]

    def bars(axis, key, tol, what):
        for lab, r in zip(labels, cmp.rows):
            dev, sd = r.get(f"{key}_dev_pct"), r.get(f"{key}_dev_std")
            if dev is None or not np.isfinite(dev):
                axis.bar(lab, 0.0, color="none", edgecolor="0.6", hatch="//")
                continue
            err = abs(dev / sd) if sd not in (None, 0) and np.isfinite(sd) else None
            axis.bar(lab, dev, color=colors[r["verdict"]], yerr=err, capsize=3)
        axis.axhline(0, color="k", lw=0.6)
        for sgn in (-1, 1):
            axis.axhline(sgn * tol * 100, color=COLORS["alarm"], ls="--", lw=0.8)
        axis.set_ylabel(f"{what} deviation [%]")
        axis.set_xlabel("predicted mode")
    bars(ax, "fn", rtol_fn, "fn")
    ax.set_title(f"measured vs {against}: {cmp.verdict} (bars: one std; dashed: tolerance)")
    if ax_z is not None:
        bars(ax_z, "zeta", rtol_zeta, "zeta")
        ax_z.set_title("damping ratio")
    return ax if ax_z is None else (ax, ax_z)


@_styled
def plot_singular_values(est, *, ax=None, n: int | None = None):
    """Singular values of the outputs' cross-spectral matrix (oma_fdd) in dB, with the modes and their
    EFDD bells marked.

    Parameters
    ----------
    est : ModalEstimate
        A ``vm.oma_fdd`` estimate.
    ax : matplotlib.axes.Axes, optional
        Where to draw.
    n : int, optional
        How many singular values (default all).

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on; ``fig.panels`` holds its axes (singular values,) (the figure unpacks
        into them).

    Raises
    ------
    ParameterError
        For an estimate that is not from oma_fdd.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure import plot
    >>> chain = vm.models.MDOF(np.eye(2), np.array([[2e4, -1e4], [-1e4, 1e4]]), modal_zeta=[0.02, 0.02])
    >>> est = vm.oma_fdd(vm.synth.ambient(chain, fs=100.0, duration=300.0, seed=1), band=(1, 40))
    >>> fig = plot.plot_singular_values(est)
    """
    if "singular_values" not in est.extras:
        raise ParameterError("est must come from vm.oma_fdd (it carries the singular values)")
    if ax is None:
        _, ax = new_figure(figsize=(9, 4.5), layout="constrained")
    sv = est.extras["singular_values"]
    vals = np.asarray(sv["values"])
    for j in range(vals.shape[0] if n is None else min(n, vals.shape[0])):
        ax.plot(sv["freq"], 10 * np.log10(np.maximum(vals[j], 1e-300)), lw=0.9 if j == 0 else 0.6, label=f"s{j + 1}")
    for f, b in zip(est.fn, est.extras["bells"]):
        ax.axvspan(b["f_lo"], b["f_hi"], color="C3", alpha=0.08)
        ax.axvline(f, color="C3", lw=0.8)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(f"singular value [dB re 1 {sv['unit']}]")
    ax.set_title("frequency-domain decomposition (red: modes, shaded: EFDD bells)", fontsize=9)
    ax.legend(fontsize=8, loc="upper right")
    return ax
