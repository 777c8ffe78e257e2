"""The one vibmeasure look (plotstyle.STYLE) and the one return type (the Figure) around every public
plotting function."""

from __future__ import annotations

import functools

from ..plotstyle import STYLE
from ._figure import as_figure


def _styled(fn):
    """Draw inside the one vibmeasure style (plotstyle.STYLE), and return the Figure of the axes the
    function drew (``_figure.as_figure``): the same look and the same return type for every picture."""
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        import matplotlib
        with matplotlib.rc_context(STYLE):
            return as_figure(fn(*args, **kwargs))
    return wrapper
