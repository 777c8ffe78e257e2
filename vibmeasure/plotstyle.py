"""The one look of every vibmeasure figure: matplotlib settings and the meaning of colours.

vibmeasure.plot applies :data:`STYLE` around each public plotting function (``matplotlib.rc_context``), so
a figure made in a script, by the command line or inside an HTML report looks the same. Nothing
here imports matplotlib; the settings are plain names and values.

To draw your own figures in the same style::

    import matplotlib
    from vibmeasure.plotstyle import STYLE
    with matplotlib.rc_context(STYLE):
        ...
"""

from __future__ import annotations

#: matplotlib rcParams for every vibmeasure figure
STYLE: dict = {
    "figure.constrained_layout.use": True,   # labels never clipped or overlapping between panels
    "figure.facecolor": "white",
    "savefig.facecolor": "white",
    "font.size": 9.0,
    "axes.titlesize": 9.0,
    "axes.labelsize": 9.0,
    "xtick.labelsize": 8.0,
    "ytick.labelsize": 8.0,
    "legend.fontsize": 8.0,
    "legend.framealpha": 0.85,
    "legend.edgecolor": "0.8",
    "axes.grid": True,
    "axes.axisbelow": True,
    "grid.linewidth": 0.4,
    "grid.alpha": 0.6,
    "grid.color": "0.85",
    "lines.linewidth": 1.0,
    "lines.markersize": 4.0,
    "image.cmap": "viridis",
    "text.parse_math": False,                 # names are text: a channel called "$x$" is printed, not typeset
    "axes.formatter.use_mathtext": False,
    "axes.formatter.limits": (-4, 5),        # scientific notation only for very large or small numbers
}

#: what a colour means, the same in every figure
COLORS: dict = {
    "measured": "0.35",     # the data as recorded
    "fit": "C0",            # an estimate drawn over the data (fitted decay, synthesised FRF)
    "model": "k",           # a prediction of a model
    "envelope": "C3",
    "residual": "C2",
    "coherence": "C2",
    "mode": "C3",           # chosen modes, fault combs
    "shaft": "C0",          # shaft orders
    "ok": "C2",
    "watch": "C1",
    "alarm": "C3",
}

#: text sizes used for annotations inside axes (points)
ANNOTATION_SIZE = 7.0
