"""The one vibmeasure look (plotstyle.STYLE) applied around every public plotting function."""

from __future__ import annotations

import functools

from ..plotstyle import STYLE


def _styled(fn):
    """Draw inside the one vibmeasure style (plotstyle.STYLE): the same look for every figure."""
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        import matplotlib
        with matplotlib.rc_context(STYLE):
            return fn(*args, **kwargs)
    return wrapper
