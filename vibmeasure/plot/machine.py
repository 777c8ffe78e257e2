"""Machine diagnosis (spectra, envelope spectrum, kurtogram, severity gauge) and fleet trends."""

from __future__ import annotations

import numpy as np

from ..core.labels import label
from ._figure import PanelFigure, new_figure
from ._style import _styled


@_styled
def plot_diagnosis(rec, diag, *, axes=None):
    """The picture of a machine diagnosis.

    The squared-envelope spectrum that carries the bearing evidence (in dB over its floor) with the
    winning family's comb at its slip, its sidebands and the other families' expected lines; the fast
    kurtogram of that channel with the chosen band; the amplitude spectrum with the shaft orders; an
    ISO 10816-3 severity gauge.

    Parameters
    ----------
    rec : Record
        The record diagnosed.
    diag : Diagnosis
        Its ``vm.diagnose`` result.
    axes : sequence of Axes, optional
        Where to draw (envelope, spectrum, gauge, kurtogram).

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on; ``fig.panels`` holds its axes (envelope, spectrum, gauge, kurtogram) (the figure unpacks
        into them).

    Raises
    ------
    ParameterError
        For a diagnosis of another record.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure import plot
    >>> rec = vm.synth.machine(fault="bearing_outer_race", rpm=1797, duration=2.0, seed=1)
    >>> fig = plot.plot_diagnosis(rec, vm.diagnose(rec, rpm=1797, bearing="6205-2RS"))
    """
    import matplotlib.pyplot as plt

    from ..signal.spectral import amplitude_spectrum
    if axes is None:
        fig = plt.figure(figsize=(12, 8), layout="constrained", FigureClass=PanelFigure)
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
    _plot_gauge(ax_g, diag.severity)
    return axes


def _plot_gauge(ax_g, sev):
    """The ISO 10816-3 severity gauge: the zones of the machine's group and foundation, the measured
    velocity as a bar, the scale on the right."""
    from ..monitor.diagnosis import ISO_10816_3
    ab, bc, cd = ISO_10816_3[(sev["group"], sev["foundation"])]
    top = cd * 1.5
    for lo, hi, c, z in ((0, ab, "#3a3", "A"), (ab, bc, "#cc3", "B"), (bc, cd, "#e83", "C"), (cd, top, "#d33", "D")):
        ax_g.bar(0, hi - lo, bottom=lo, color=c, width=0.6)
        ax_g.text(0.34, (lo + hi) / 2, z, va="center", ha="left", fontsize=8)
    v = sev.get("velocity_rms_mm_s")
    if v is not None:
        ax_g.plot([-0.35, 0.35], [min(v, top)] * 2, color="k", lw=3)
        ax_g.set_title(f"ISO 10816-3\n{v:.2f} mm/s: zone {sev['zone'] or 'withheld'}", fontsize=8)
    ax_g.grid(False)
    ax_g.set_xlim(-0.5, 0.6)
    ax_g.set_ylim(0, top)
    ax_g.set_xticks([])
    ax_g.yaxis.tick_right()                  # the label beside its own scale, clear of the plots on the left
    ax_g.yaxis.set_label_position("right")
    ax_g.set_ylabel("velocity RMS [mm/s]")


def _plot_ses(ax, ses, diag, colors):
    """SES in dB over its median floor, the winning comb (solid), its sidebands (dotted) and the other
    families' expected first harmonics (thin); where the cage comb stands, its harmonics (ticks along
    the top) and the stretches where its level was divided out (shaded, ``bearing.cage._cage_floor``)."""
    freq, amp = np.asarray(ses["freq"]), np.asarray(ses["amp"])
    tab = diag.faults.set_index("fault")
    fam = ses["family"]
    f0 = tab.loc[fam, "expected_hz"]
    fmax = min(freq[-1], 5.5 * float(tab.loc[tab.index.str.startswith("bearing"), "expected_hz"].max()))
    sel = (freq > 0) & (freq <= fmax)
    floor = np.median(amp[sel] ** 2)
    ax.plot(freq[sel], 10 * np.log10(np.maximum(amp[sel] ** 2, 1e-300) / floor), lw=0.6, color="0.35")
    # a ball called from its smeared comb (bearing.smeared._smeared_ball): each hump's band shaded
    smeared = "smeared" in str(tab.loc[fam, "note"])
    for ln in ses["lines"]:
        style = "-" if ln["sideband"] == 0 else ":"
        ax.axvline(ln["hz"], color=colors.get(fam, "C3"), lw=0.9, ls=style, alpha=0.8)
        if smeared:
            from ..monitor.bearing.smeared import SMEAR_WIDTH
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
    im = ax.imshow(img, aspect="auto", origin="upper", cmap="viridis", interpolation="nearest",
                   extent=(0, kg.fs / 2, len(kg.levels) - 0.5, -0.5))
    ax.figure.colorbar(im, ax=ax, pad=0.01, fraction=0.04, label="spectral kurtosis")
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
    """One metric of one point over time: the measurements, the baseline band (mean +- std of the first
    ``baseline_count``), the watch and alarm limits of :func:`vibmeasure.trend` and the verdict.

    Parameters
    ----------
    store : str, os.PathLike or Store
        The store.
    asset, point : str
        The asset and its measurement point.
    metric : str
        A trended metric (velocity_rms_mm_s, bearing_evidence, rms, fn1_hz).
    task : str, optional
        The task whose results hold the metric.
    baseline_count : int
        Measurements in the baseline.
    ax : matplotlib.axes.Axes, optional
        Where to draw.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on; ``fig.panels`` holds its axes (trend,) (the figure unpacks
        into them).

    Raises
    ------
    ParameterError
        For a metric that is not trended, or no result of it for the point.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure import plot
    >>> import tempfile, pathlib, warnings
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = vm.synth.fleet(folder / "fleet", n_measurements=6, fault_onset=3)
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("ignore")
    ...     _ = vm.batch(task="diagnose", store=folder / "s.h5", manifest=folder / "fleet" / "machines.csv")
    >>> fig = plot.plot_trend(folder / "s.h5", asset="pump-3", point="DE", metric="velocity_rms_mm_s", baseline_count=3)
    """

    from ..monitor.trend import metric_history
    df, r = metric_history(store, asset=asset, point=point, metric=metric, task=task, baseline_count=baseline_count)
    if ax is None:
        _, ax = new_figure(figsize=(8, 3.5))
    ax.plot(df["time"], df[metric].astype(float), "o-", ms=3, lw=1, color="C0", label=label(metric))
    if r is not None:
        mu, sd = r["baseline_mean"], r["baseline_std"]
        t_b = df["time"].iloc[:baseline_count]
        ax.axhspan(mu - sd, mu + sd, color="0.85", zorder=0, label=f"baseline (first {baseline_count})")
        ax.axvspan(t_b.iloc[0], t_b.iloc[-1], color="0.93", zorder=0)
        ax.axhline(r["watch_limit"], color="orange", ls="--", lw=1, label="watch")
        ax.axhline(r["alarm_limit"], color="red", ls="--", lw=1, label="alarm")
        ax.set_title(f"{asset}/{point}: {label(metric)} - {r['verdict']}", fontsize=10)
    ax.set_xlabel("time")
    ax.set_ylabel(label(metric))
    ax.legend(fontsize=8, loc="best")
    ax.figure.autofmt_xdate()
    return ax
