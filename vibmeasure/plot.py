"""Pictures of records and results (the only module that imports matplotlib).

Each function draws on the given axes (or new ones) and returns them; nothing is computed
here beyond what drawing needs.
"""

from __future__ import annotations

import numpy as np

import functools

from .core._validate import name_index, response_channel
from .core.errors import ParameterError
from .core.record import Record
from .core.results import ModalEstimate
from .plotstyle import ANNOTATION_SIZE, COLORS, STYLE

__all__ = ["plot_srs", "plot_singular_values", "plot_transmissibility", "plot_ringdown", "plot_spectrum", "plot_frf", "plot_nyquist", "plot_stabilisation", "plot_mac", "plot_diagnosis",
           "decay_model"]


def _styled(fn):
    """Draw inside the one vibmeasure style (plotstyle.STYLE): the same look for every figure."""
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        import matplotlib
        with matplotlib.rc_context(STYLE):
            return fn(*args, **kwargs)
    return wrapper


def decay_model(est: ModalEstimate, t: np.ndarray) -> np.ndarray:
    """The fitted free decay of an estimate at times t (s, from the fit start), summed over modes."""
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
    lines = [f"{fn:.5g} Hz, zeta {z:.4g}" + (f" ± {zs:.2g}" if np.isfinite(zs) else "")
             for fn, z, zs in zip(est.fn, est.zeta, est.zeta_std)]
    title = f"{est.method}: " + "; ".join(lines[:4]) + (" ..." if len(lines) > 4 else "")
    if est.flags:
        title += "\nflags: " + ", ".join(est.flags)
    ax.set_title(title, fontsize=9)
    what = c.quantity if c.quantity not in ("unknown", "", None) else c.name
    ax.set_ylabel(f"{what} [{c.unit or '-'}]")
    axr.set_xlabel("time [s]")
    ax.legend(loc="upper right", fontsize=8)
    return ax, axr


@_styled
def plot_spectrum(spec, *, ax=None, channel=None, peaks=None, lines=None, log: bool | None = None,
                  db: bool = False, fmax: float | None = None):
    """A spectrum (one or all channels) with optional picked peaks and labelled reference lines.

    ``lines`` maps a label to a frequency in Hz (e.g. {"BPFO": 107.4}); ``log`` defaults to a
    logarithmic amplitude axis for PSDs; ``db=True`` draws decibels re 1 unit (20 log10 of
    amplitudes, 10 log10 of powers). The frequency axis ends at ``fmax``, by default where the
    content ends (an envelope spectrum holds nothing above its demodulation bandwidth). Peak labels
    that would print on top of each other are left out, strongest peaks first.
    """
    import matplotlib.pyplot as plt
    from .core.results import Spectrum
    if not isinstance(spec, Spectrum):
        raise ParameterError(f"spec must be a vm.Spectrum, got {type(spec).__name__}")
    if fmax is not None:
        from .core._validate import positive
        try:
            fmax = positive(fmax, "fmax")
        except ParameterError:
            raise ParameterError(f"fmax={fmax!r} must be a positive frequency in Hz") from None
    if not isinstance(db, (bool, np.bool_)):
        raise ParameterError(f"db={db!r} must be True or False")
    if ax is None:
        _, ax = plt.subplots(figsize=(9, 4.5))
    rows = range(spec.n_channels) if channel is None else [name_index(spec.channels, channel)]
    power = spec.kind in ("psd", "power")

    def scaled(v):
        v = np.abs(np.asarray(v, float))
        if not db:
            return v
        return (10 if power else 20) * np.log10(np.maximum(v, 1e-300))
    for i in rows:
        ax.plot(spec.freq, scaled(spec.values[i]), lw=0.7, label=spec.channels[i])
    top = fmax if fmax is not None else _content_end(spec, rows)
    ax.set_xlim(spec.freq[0], min(top, spec.freq[-1]))
    if not db and (log if log is not None else power):
        ax.set_yscale("log")
    if db:
        vis = (spec.freq > 0) & (spec.freq <= top)
        peak = max(float(np.max(scaled(spec.values[i][vis]))) for i in rows) if vis.any() else 0.0
        ax.set_ylim(bottom=peak - (100 if power else 80), top=peak + 6)
    if peaks is not None and len(peaks):
        ax.plot(peaks.freq, scaled(peaks.amplitude), "v", color=COLORS["mode"], ms=5, label="peaks")
        _label_without_collisions(ax, peaks.freq[:10], scaled(peaks.amplitude[:10]),
                                  [f"{f:.4g}" for f in peaks.freq[:10]])
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


def _label_without_collisions(ax, xs, ys, texts, *, size: float = ANNOTATION_SIZE):
    """Label points (strongest first) just above them, each where it overlaps no label placed
    before; a label that fits nowhere near its point is left out."""
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
                ax.annotate(texts[k], (xs[k], ys[k]), textcoords="offset points", xytext=(2, dy), fontsize=size)
                placed.append(box)
                break


@_styled
def plot_frf(frf, *, est=None, output=0, input=0, axes=None):
    """Bode plot (magnitude, phase) of one FRF with its coherence, and the FRF synthesised from
    a fit_modes estimate when given. Returns (magnitude, phase, coherence) axes."""
    import matplotlib.pyplot as plt
    from .core.results import FRF
    if not isinstance(frf, FRF):
        raise ParameterError(f"frf must be a vm.FRF, got {type(frf).__name__}")
    o = name_index(frf.outputs, output, what="output")
    i = name_index(frf.inputs, input, what="input")
    if axes is None:
        fig, axes = plt.subplots(3, 1, sharex=True, figsize=(9, 7), gridspec_kw={"height_ratios": [3, 1.5, 1]})
    am, ap, ac = axes
    h = frf.h[o, i]
    am.semilogy(frf.freq, np.abs(h), lw=0.8, color=COLORS["measured"], label=f"{frf.outputs[o]}/{frf.inputs[i]} ({frf.estimator or 'data'})")
    ap.plot(frf.freq, np.degrees(np.angle(h)), lw=0.8, color=COLORS["measured"])
    if est is not None and "poles" in est.extras:
        from .identify.modal import synthesize_frf
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
    """Nyquist plot (real vs imaginary) of one FRF, optionally within a band."""
    import matplotlib.pyplot as plt
    if ax is None:
        _, ax = plt.subplots(figsize=(5.5, 5.5))
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
    """The stabilisation diagram of a fit_modes or oma_ssi estimate: poles per model order (o new, f
    stable in frequency, d also damping, s stable in frequency and damping, and for oma_ssi in shape),
    the chosen modes, and |H| (fit_modes, with ``frf``) or the outputs' mean PSD (oma_ssi) behind it."""
    import matplotlib.pyplot as plt
    if "stabilisation" not in est.extras:
        raise ParameterError("est must come from vm.fit_modes or vm.oma_ssi (it carries the stabilisation table)")
    if ax is None:
        _, ax = plt.subplots(figsize=(9, 5), layout="constrained")
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
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title("stabilisation diagram (red: chosen modes)", fontsize=9)
    return ax


@_styled
def plot_mac(matrix, *, labels=None, ax=None):
    """MAC matrix as an image with the values written in."""
    import matplotlib.pyplot as plt
    m = np.asarray(matrix, float)
    if ax is None:
        _, ax = plt.subplots(figsize=(4.5, 4))
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
def plot_diagnosis(rec, diag, *, axes=None):
    """The squared-envelope spectrum that carries the bearing evidence (in dB over its floor) with the
    winning family's comb at its slip, its sidebands and the other families' expected lines; the fast
    kurtogram of that channel with the chosen band; the amplitude spectrum with the shaft orders; an
    ISO 10816-3 severity gauge. Returns the axes (envelope, spectrum, gauge, kurtogram)."""
    import matplotlib.pyplot as plt
    from .signal.spectral import amplitude_spectrum
    if axes is None:
        fig = plt.figure(figsize=(12, 8), layout="constrained")
        gs = fig.add_gridspec(3, 5, height_ratios=(1.2, 1, 1))
        axes = (fig.add_subplot(gs[0, :4]), fig.add_subplot(gs[2, :4]), fig.add_subplot(gs[:, 4]),
                fig.add_subplot(gs[1, :4]))
    ax_e, ax_s, ax_g = axes[:3]
    ax_k = axes[3] if len(axes) > 3 else None
    colors = {"bearing_outer_race": "C3", "bearing_inner_race": "C1", "bearing_ball": "C4", "bearing_cage": "C5",
              "unbalance": "C0", "misalignment": "C2", "looseness": "C6", "gear_mesh": "C8"}
    ses = diag.extras.get("ses")
    if ses is not None:
        _plot_ses(ax_e, ses, diag, colors)
    else:
        why = ("the declared speed is contradicted" if "speed_contradicted" in diag.flags else "no bearing given")
        ax_e.text(0.5, 0.5, f"bearing faults not checked ({why})", ha="center", va="center",
                  transform=ax_e.transAxes)
        ax_e.set_axis_off()
    if ax_k is not None:
        kg = diag.extras.get("kurtogram")
        if kg is not None:
            _plot_kurtogram(ax_k, kg, ses["band_hz"] if ses else None)
        else:
            ax_k.set_axis_off()
    primary = diag.extras.get("primary")
    if primary is not None and primary in rec.names:
        rec = rec.select(primary)
    s = amplitude_spectrum(rec)
    f1 = (diag.speed.get("estimated_rpm") or diag.speed["declared_rpm"]) / 60
    sel = s.freq <= 12 * f1
    ax_s.plot(s.freq[sel], s.values[0, sel], lw=0.7, color="0.3")
    for k in range(1, 11):
        ax_s.axvline(k * f1, color="C0", lw=0.5, ls=":")
    ax_s.set_xlabel("frequency [Hz]")
    ax_s.set_ylabel(f"amplitude [{s.unit or '-'}]")
    ax_s.set_title(f"spectrum of {rec.names[0]} with shaft orders 1X..10X (1X = {f1:.2f} Hz)", fontsize=9)
    other = diag.speed.get("contradicting_rpm")
    if other is not None:   # the shaft comb that contradicts the declared speed, where it stands
        for k in range(1, 7):
            ax_s.axvline(k * other / 60, color="C3", lw=0.8, ls="--")
        what = (f"the bearing's lines stand where {other:.0f} rpm puts them (red: that speed's 1X-6X)"
                if diag.speed.get("contradicted_by") == "bearing lines" else
                f"a shaft comb stands at {other:.0f} rpm (red)")
        ax_s.text(0.5, 0.96, f"WARNING: the declared {diag.speed['declared_rpm']:g} rpm is contradicted:\n{what}; "
                  "no fault was looked for", transform=ax_s.transAxes,
                  ha="center", va="top", color="C3", fontsize=9, fontweight="bold")
    elif "speed_inconsistent" in diag.flags or not diag.speed.get("consistent", True):
        ax_s.text(0.5, 0.9, "WARNING: the speed check failed (see the diagnosis flags)", transform=ax_s.transAxes,
                  ha="center", color="C3", fontsize=9, fontweight="bold")
    elif "order_tracked" in diag.flags or "speed_varies" in diag.flags:
        est = " (speed estimated from the 1X)" if diag.speed.get("source") == "1X line" else ""
        msg = (f"the speed varies over the record: lines smear in this spectrum (the diagnosis ran in orders{est})"
               if "order_tracked" in diag.flags else
               "WARNING: the speed varies over the record and no tachometer was given: lines smear")
        ax_s.text(0.5, 0.9, msg, transform=ax_s.transAxes, ha="center", fontsize=8,
                  color="0.2" if "order_tracked" in diag.flags else "C3")
    if "order_tracked" in diag.flags:   # the SES and the kurtogram are in orders x the mean speed
        for ax in (ax_e, ax_k):
            if ax is not None and ax.get_xlabel():
                ax.set_xlabel(f"order x the mean speed {f1:.2f} Hz [Hz]")
    sev = diag.severity
    from .monitor.machinery import ISO_10816_3
    ab, bc, cd = ISO_10816_3[(sev["group"], sev["foundation"])]
    top = cd * 1.5
    for lo, hi, c, z in ((0, ab, "#3a3", "A"), (ab, bc, "#cc3", "B"), (bc, cd, "#e83", "C"), (cd, top, "#d33", "D")):
        ax_g.bar(0, hi - lo, bottom=lo, color=c, width=0.6)
        ax_g.text(0.34, (lo + hi) / 2, z, va="center", ha="left", fontsize=8)
    v = sev.get("velocity_rms_mm_s")
    if v is not None:
        ax_g.plot([-0.35, 0.35], [min(v, top)] * 2, color="k", lw=3)
        ax_g.set_title(f"ISO 10816-3\n{v:.2f} mm/s: zone {sev['zone']}", fontsize=8)
    ax_g.grid(False)
    ax_g.set_xlim(-0.5, 0.6)
    ax_g.set_ylim(0, top)
    ax_g.set_xticks([])
    ax_g.set_ylabel("velocity RMS [mm/s]")
    return axes


def _plot_ses(ax, ses, diag, colors):
    """SES in dB over its median floor, the winning comb (solid), its sidebands (dotted) and the other
    families' expected first harmonics (thin); where the cage comb stands, its harmonics (ticks along
    the top) and the stretches where its level was divided out (shaded, ``bearing_faults._cage_floor``)."""
    freq, amp = np.asarray(ses["freq"]), np.asarray(ses["amp"])
    tab = diag.faults.set_index("fault")
    fam = ses["family"]
    f0 = tab.loc[fam, "expected_hz"]
    fmax = min(freq[-1], 5.5 * float(tab.loc[tab.index.str.startswith("bearing"), "expected_hz"].max()))
    sel = (freq > 0) & (freq <= fmax)
    floor = np.median(amp[sel] ** 2)
    ax.plot(freq[sel], 10 * np.log10(np.maximum(amp[sel] ** 2, 1e-300) / floor), lw=0.6, color="0.35")
    # a ball called from its smeared comb (bearing_faults._smeared_ball): each hump's band shaded
    smeared = "smeared" in str(tab.loc[fam, "note"])
    for ln in ses["lines"]:
        style = "-" if ln["sideband"] == 0 else ":"
        ax.axvline(ln["hz"], color=colors.get(fam, "C3"), lw=0.9, ls=style, alpha=0.8)
        if smeared:
            from .monitor.bearing_faults import SMEAR_WIDTH
            ax.axvspan(ln["hz"] * (1 - SMEAR_WIDTH), ln["hz"] * (1 + SMEAR_WIDTH), color=colors.get(fam, "C3"),
                       alpha=0.15, lw=0)
        if ln["db"] >= 7.8:
            ax.plot(ln["hz"], ln["db"], "v", color=colors.get(fam, "C3"), ms=5)
    n_lab = 0
    for other, r in tab.iterrows():
        if other.startswith("bearing") and other != fam and np.isfinite(r.expected_hz):
            ax.axvline(r.expected_hz, color=colors.get(other, "0.5"), lw=0.5, ls="--", alpha=0.6)
            # staggered heights: families whose lines lie close do not print on top of each other
            ax.text(r.expected_hz, 0.03 + 0.3 * (n_lab % 3), f" {other.split('_', 1)[1]}",
                    transform=ax.get_xaxis_transform(), rotation=90, fontsize=6, color=colors.get(other, "0.5"))
            n_lab += 1
    # the cage comb where it stands: its harmonics ticked along the top, and the stretches where its
    # level was the floor of another family's lines (they count only by what they stand above it)
    cage = ses.get("cage_hz")
    if cage:
        ks = np.arange(1, int(fmax / cage) + 1)
        ax.plot(ks * cage, np.full(ks.size, 0.97), "|", color=colors["bearing_cage"], ms=6,
                transform=ax.get_xaxis_transform(), label="cage comb (FTF x k)")
    spans = [(lo, hi) for lo, hi, _ in ses.get("cage_floor", ()) if lo <= fmax]
    for lo, hi in spans:   # a few bins wide: marked at the top too, where they can be seen
        ax.axvspan(lo, hi, color=colors["bearing_cage"], alpha=0.3, lw=0)
    if spans:
        mid = np.array([(lo + hi) / 2 for lo, hi in spans])
        ax.plot(mid, np.full(mid.size, 0.91), "v", color=colors["bearing_cage"], ms=4, mfc="none",
                transform=ax.get_xaxis_transform(), label="cage comb's level divided out there")
    if cage or ses.get("cage_floor"):
        ax.legend(loc="upper right", fontsize=7)
    slip = ses.get("slip")
    p = tab.loc[fam, "p_value"]
    f1 = (diag.speed.get("estimated_rpm") or diag.speed["declared_rpm"]) / 60
    for k in range(1, int(fmax / f1) + 1):
        ax.axvline(k * f1, color="C0", lw=0.4, ls=(0, (1, 3)), alpha=0.5)
    import textwrap
    head = (f"squared-envelope spectrum ({ses['preprocessing']}, {ses['band_hz'][0]:.0f}-{ses['band_hz'][1]:.0f} Hz, "
            f"{ses['channel']}); top = {diag.top}")
    # wrapped to the axes' width: a long channel list ran into the severity gauge's title beside it
    width = max(40, int(ax.get_position().width * ax.figure.get_figwidth() * 72 / 4.6))
    ax.set_title("\n".join(textwrap.wrap(head, width) + [
                 f"{fam.split('_', 1)[1]} comb ({'smeared: humps shaded' if smeared else 'solid, sidebands dotted'}) at "
                 f"{f0:.2f} Hz x (1 {(slip if np.isfinite(slip) else 0) * 100:+.2f} % slip), p = {p:.2g}; "
                 "shaft orders faint blue"]), fontsize=8, loc="left")
    ax.set_ylabel("SES [dB over floor]")
    ax.set_xlabel("frequency [Hz]")
    ax.set_xlim(0, fmax)


def _plot_kurtogram(ax, kg, band):
    """Fast kurtogram (levels x frequency) with the band the evidence came from outlined."""
    img = kg.image("kurtosis")
    ax.grid(False)  # no grid lines across an image
    ax.imshow(img, aspect="auto", origin="upper", cmap="viridis", interpolation="nearest",
              extent=(0, kg.fs / 2, len(kg.levels) - 0.5, -0.5))
    ax.set_yticks(range(len(kg.levels)), [f"{lv:g}" for lv in kg.levels])
    ax.set_ylabel("level")
    ax.set_xlabel("frequency [Hz]")
    if band is not None:
        ax.axvspan(band[0], band[1], fill=False, ec="w", lw=1.2)
    lo, hi, lev, val = kg.best("kurtosis")
    top = kg.params.get("max_frequency_hz")
    edge = ""
    if top is not None and top < 0.99 * kg.fs / 2:   # above it a filter's stop band: left out
        ax.axvline(top, color="0.3", ls="--", lw=1.0)
        edge = f"; dashed: the measured band ends at {top:.0f} Hz"
    ax.set_title(f"fast kurtogram (cepstral-whitened): max kurtosis {val:.2f} in {lo:.0f}-{hi:.0f} Hz "
                 f"(level {lev:g}); outlined: band of the evidence{edge}", fontsize=8)


@_styled
def plot_trend(store, *, asset: str, point: str, metric: str, task: str | None = None, baseline_count: int = 8,
               ax=None):
    """One metric of one point over time: the measurements, the baseline band (mean +- std of the
    first ``baseline_count``), the watch and alarm limits of :func:`vibmeasure.trend` and the verdict."""
    import matplotlib.pyplot as plt
    from .io.store import Store
    from .monitor.trend import METRICS, trend
    st = store if isinstance(store, Store) else Store(store)
    tasks = [t for t, c, *_ in METRICS if c == metric and (task is None or t == task)]
    if not tasks:
        raise ParameterError(f"metric={metric!r} is not trended; one of {sorted({c for _, c, *_ in METRICS})}")
    df = next((d for d in (st.results(t, asset=asset, point=point) for t in tasks) if not d.empty and metric in d),
              None)
    if df is None:
        raise ParameterError(f"no {metric} results for {asset}/{point} in the store")
    tr = trend(st, asset=asset, point=point, baseline_count=baseline_count)
    row = tr[tr["metric"] == metric]
    if ax is None:
        _, ax = plt.subplots(figsize=(8, 3.5))
    ax.plot(df["time"], df[metric].astype(float), "o-", ms=3, lw=1, color="C0", label=metric)
    if not row.empty:
        r = row.iloc[0]
        mu, sd = r["baseline_mean"], r["baseline_std"]
        t_b = df["time"].iloc[:baseline_count]
        ax.axhspan(mu - sd, mu + sd, color="0.85", zorder=0, label=f"baseline (first {baseline_count})")
        ax.axvspan(t_b.iloc[0], t_b.iloc[-1], color="0.93", zorder=0)
        ax.axhline(r["watch_limit"], color="orange", ls="--", lw=1, label="watch")
        ax.axhline(r["alarm_limit"], color="red", ls="--", lw=1, label="alarm")
        ax.set_title(f"{asset}/{point}: {metric} - {r['verdict']}", fontsize=10)
    ax.set_xlabel("time")
    ax.set_ylabel(metric)
    ax.legend(fontsize=8, loc="best")
    ax.figure.autofmt_xdate()
    return ax


@_styled
def plot_backbone(est: ModalEstimate, *, mode: int = 0, axes=None):
    """The backbone of one mode of a ring-down estimate: fn and zeta versus amplitude (error bars:
    one std per window) with the weakly nonlinear model of ``extras["backbone_model"]`` drawn over."""
    import matplotlib.pyplot as plt
    bb = est.extras.get("backbone")
    if bb is None or len(bb) == 0 or mode not in set(bb["mode"]):
        raise ParameterError(f"mode={mode} has no backbone in this estimate (too few cycles above the noise)")
    b = bb[bb["mode"] == mode]
    if axes is None:
        _, axes = plt.subplots(1, 2, figsize=(9, 3.5), constrained_layout=True)
    unit = est.unit or "-"
    A = b["amplitude"].to_numpy(float)
    axes[0].errorbar(A, b["fn_hz"], yerr=b["fn_std_hz"], fmt="o", ms=3, lw=1, label="windows")
    axes[1].errorbar(A, b["zeta"], yerr=b["zeta_std"], fmt="o", ms=3, lw=1, label="windows")
    model = est.extras.get("backbone_model", {}).get(mode)
    if model:
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


def file_backend() -> None:
    """Select matplotlib's file backend (Agg), for programs that only write pictures (the CLI)."""
    import matplotlib
    matplotlib.use("Agg")


def save_figure(fig, path, *, dpi: int = 120) -> None:
    """Write a figure atomically (never a half-written picture, the usual file mode), then close it,
    also on failure."""
    from pathlib import Path
    import matplotlib.pyplot as plt
    from .io._common import atomic_path
    p = Path(path)
    try:
        if not p.parent.exists():
            raise ParameterError(f"{str(path)!r}: folder {str(p.parent)!r} does not exist")
        with atomic_path(p) as tmp:
            fig.savefig(tmp, dpi=dpi, bbox_inches="tight", format=(p.suffix[1:] or "png").lower())
    finally:
        plt.close(fig)


@_styled
def plot_comparison(cmp, *, rtol_fn: float = 0.02, rtol_zeta: float = 0.5, against: str = "model", ax=None):
    """Deviation of each measured fn from its prediction (%), coloured by verdict, with the alarm
    tolerance +-rtol_fn and, where known, one-std error bars; on a figure of its own also the zeta
    deviation (%) beside it, with its tolerance +-rtol_zeta. Returns the fn axes."""
    import matplotlib.pyplot as plt
    from .core._validate import positive
    rtol_fn, rtol_zeta = positive(rtol_fn, "rtol_fn"), positive(rtol_zeta, "rtol_zeta")
    ax_z = None
    if ax is None:
        _, (ax, ax_z) = plt.subplots(1, 2, figsize=(10, 4), width_ratios=(3, 2))
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
    return ax


@_styled
def plot_srs(spec, *, ax=None, tripartite: bool | None = None):
    """Shock response spectrum on log axes. For pseudo-velocity output (or ``tripartite=True`` with
    any output) the tripartite grid: pseudo-velocity against frequency, with lines of constant
    relative displacement (falling) and constant pseudo-acceleration (rising)."""
    import matplotlib.pyplot as plt
    if ax is None:
        _, ax = plt.subplots(figsize=(7, 5.5), layout="constrained")
    tri = spec.output == "pseudo_velocity" if tripartite is None else bool(tripartite)
    w = 2 * np.pi * spec.fn
    span = []
    for k, v in spec.values.items():
        y = v
        if tri and spec.output == "acceleration":
            from .core import units
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
        ax.set_ylabel("pseudo-velocity [m/s]")
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
        ax.set_ylabel(f"{qty.get(spec.output, spec.output)} [{spec.unit}]")
        ax.set_title(f"shock response spectrum of {spec.channel} ({q})", fontsize=9)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=8, loc="lower right")
    return ax


@_styled
def plot_singular_values(est, *, ax=None, n: int | None = None):
    """Singular values of the output cross-spectral matrix (oma_fdd), in dB, with the selected modes
    and their EFDD bells marked."""
    import matplotlib.pyplot as plt
    if "singular_values" not in est.extras:
        raise ParameterError("est must come from vm.oma_fdd (it carries the singular values)")
    if ax is None:
        _, ax = plt.subplots(figsize=(9, 4.5), layout="constrained")
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


@_styled
def plot_transmissibility(tr, *, ax=None):
    """Measured |T| (and the model's, where given) on log axes, coherence below, the isolation
    region (|T| < 1) shaded."""
    import matplotlib.pyplot as plt
    if ax is None:
        fig, (ax, axc) = plt.subplots(2, 1, figsize=(8, 6), sharex=True, height_ratios=(3, 1), layout="constrained")
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
    return ax
