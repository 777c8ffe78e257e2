"""What every public plotting function returns: the Figure, its panels in a documented order.

A function draws on the axes it is given or on new ones, and returns the Figure either way (one type
for every picture: save it, show it, embed it). A figure the function made itself is a
``PanelFigure``: ``fig.panels`` holds the axes it drew in the order its docstring lists, and the
figure unpacks into them (``ax, ax_res = plot_ringdown(...)``), which keeps scripts written for the
axes-returning functions of 0.1 working. On a figure the caller made, ``fig.panels`` is set too.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure


class PanelFigure(Figure):
    """A matplotlib Figure that knows which of its axes are the plotting function's panels."""

    panels: tuple = ()

    def __iter__(self):
        return iter(self.panels)

    def __getitem__(self, i):
        return self.panels[i]

    def __getattr__(self, name):
        # only reached for a name the Figure does not have: an Axes method called on the returned
        # value by a script that expects the axes, which gets the way to them instead of a bare error
        if name.startswith("_") or name == "panels":
            raise AttributeError(name)
        raise AttributeError(f"{type(self).__name__} has no attribute {name!r}: plotting functions return the "
                             f"Figure; its axes are fig.panels (fig.panels[0] is the main one)")


def new_figure(nrows: int = 1, ncols: int = 1, **kwargs):
    """(fig, axes) as ``plt.subplots`` gives them, the figure a PanelFigure."""
    import matplotlib.pyplot as plt
    return plt.subplots(nrows, ncols, FigureClass=PanelFigure, **kwargs)


def as_figure(drawn):
    """The Figure of what a plotting function drew (one Axes or several), its panels attached."""
    axes = tuple(np.ravel(np.asarray(drawn, dtype=object))) if not hasattr(drawn, "figure") else (drawn,)
    fig = axes[0].figure
    try:
        fig.panels = axes
    except AttributeError:   # a SubFigure or a frozen object: its axes are still fig.axes
        pass
    return fig

