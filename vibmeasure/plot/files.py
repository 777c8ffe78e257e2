"""Writing pictures: matplotlib's file backend and atomic saves."""

from __future__ import annotations

from ..core.errors import ParameterError


def file_backend() -> None:
    """Select matplotlib's file backend (Agg), for programs that only write pictures (the CLI)."""
    import matplotlib
    matplotlib.use("Agg")


def save_figure(fig, path, *, dpi: int = 120) -> None:
    """Write a figure atomically (never a half-written picture, the usual file mode), then close it,
    also on failure."""
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
