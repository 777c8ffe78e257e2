"""Pictures of records and results (with report/, the only code that imports matplotlib).

Each function draws a result it is given on the given axes (or new ones) and returns the Figure, its
axes in ``fig.panels`` (``_figure.PanelFigure``); nothing is computed here beyond what drawing needs.
One module per kind of result.
"""

from .decay import decay_model, plot_backbone, plot_ringdown
from .files import file_backend, save_figure
from .machine import plot_diagnosis, plot_trend
from .modal import plot_comparison, plot_frf, plot_mac, plot_nyquist, plot_singular_values, plot_stabilisation
from .spectra import plot_spectrum, plot_srs, plot_transmissibility

__all__ = ["plot_srs", "plot_singular_values", "plot_transmissibility", "plot_ringdown", "plot_spectrum", "plot_frf",
           "plot_nyquist", "plot_stabilisation", "plot_mac", "plot_diagnosis", "plot_trend", "plot_backbone",
           "plot_comparison", "decay_model", "file_backend", "save_figure"]
