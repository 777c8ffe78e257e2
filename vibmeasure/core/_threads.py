"""One BLAS thread for the small-matrix hot loops; a record's channels in threads.

Iterative fits multiply and factor matrices of a few dozen columns thousands of times. OpenBLAS
splits each of those across all cores; when another process keeps a core busy, every call waits
for a descheduled thread and a 0.03 s fit takes 0.3-1 s. Such matrices gain nothing from threads,
so the fits run with one BLAS thread (threadpoolctl, which restores the previous setting on exit).
Without threadpoolctl installed this is a no-op.
"""

from __future__ import annotations

import contextlib
import functools

__all__ = ["one_blas_thread", "single_threaded", "each_in_threads"]

_controller = None


def _get_controller():
    global _controller
    if _controller is None:
        try:
            import importlib
            importlib.import_module("scipy.linalg")  # scipy ships its own OpenBLAS: load it so it is controlled too
            from threadpoolctl import ThreadpoolController
            _controller = ThreadpoolController()
        except Exception:  # not installed, or a platform it cannot inspect
            _controller = False
    return _controller


def one_blas_thread():
    """Context manager: BLAS limited to one thread inside (nested use is harmless)."""
    ctl = _get_controller()
    if not ctl:
        return contextlib.nullcontext()
    return ctl.limit(limits=1, user_api="blas")


def single_threaded(func):
    """Decorator: run ``func`` with one BLAS thread."""
    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with one_blas_thread():
            return func(*args, **kwargs)
    return wrapper


def each_in_threads(func, items) -> list:
    """``[func(item) for item in items]``, the items in threads where there are two or more and two or
    more cores: a record's channels are analysed alike and apart, and their FFTs and array arithmetic
    release the GIL (a 12 kHz, 10 s record's three channels' bearing spectra: 115 -> 78 ms on two cores).
    The results, and the first exception raised, come in the items' order, as the loop gives them. A
    pool per call: a fork copies no idle worker it would wait for."""
    import os
    items = list(items)
    workers = min(len(items), os.cpu_count() or 1)
    if workers < 2:
        return [func(item) for item in items]
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(max_workers=workers, thread_name_prefix="vibmeasure-channel") as pool:
        return list(pool.map(func, items))
