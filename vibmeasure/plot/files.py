"""Writing pictures: matplotlib's file backend and atomic saves."""

from __future__ import annotations

from ..core.errors import ParameterError


def file_backend() -> None:
    """Select matplotlib's file backend (Agg), for programs that only write pictures (the command line).

    Returns
    -------
    None

    Raises
    ------
    ParameterError
        Never.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure import plot
    >>> plot.file_backend()
    """
    import matplotlib
    matplotlib.use("Agg")


def save_figure(fig, path, *, dpi: int = 120) -> None:
    """Write a figure atomically (never a half-written picture), then close it, also on failure.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : str or os.PathLike
        The file; its ending chooses the format (png, svg, pdf).
    dpi : int
        Resolution of a raster picture.

    Returns
    -------
    None

    Raises
    ------
    ParameterError
        For a folder that does not exist.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure import plot
    >>> import tempfile, pathlib
    >>> fig = plot.plot_mac(vm.mac(np.eye(2)))
    >>> plot.save_figure(fig, pathlib.Path(tempfile.mkdtemp()) / "mac.png")
    """
    from pathlib import Path

    import matplotlib.pyplot as plt

    from ..io._common import atomic_path
    p = Path(path)
    try:
        if not p.parent.exists():
            raise ParameterError(f"{str(path)!r}: folder {str(p.parent)!r} does not exist")
        with atomic_path(p) as tmp:
            fig.savefig(tmp, dpi=dpi, bbox_inches="tight", format=(p.suffix[1:] or "png").lower())
    finally:
        plt.close(fig)
