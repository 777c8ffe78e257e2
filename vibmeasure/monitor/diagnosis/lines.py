"""Spectral lines: a line's height over its local floor, its sub-bin frequency, the primary channel's
amplitude and velocity spectra, and the fault table's row."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from scipy import fft as _sfft

from ...signal.spectral import symmetric_window
from ...signal.whiten import CACHED_SAMPLES

if TYPE_CHECKING:   # for annotations only
    from .job import Job



LINE_DB = 12.0     # a line counts as present this far above its local floor (noise maxima reach ~10 dB)
TOP_CONFIDENCE = 0.5   # a fault is named from this confidence on (``decide``)


def _line(freq, values, f, tol, floor_halfwidth):
    """Strongest value within f +- tol and its height (dB) over the local median floor."""
    sel = np.abs(freq - f) <= tol
    if not sel.any():
        return None, 0.0, -np.inf
    k = np.flatnonzero(sel)[np.argmax(values[sel])]
    ring = (np.abs(freq - f) <= floor_halfwidth) & ~sel
    floor = np.median(values[ring]) if ring.sum() >= 5 else np.median(values)
    return float(freq[k]), float(values[k]), float(20 * np.log10(values[k] / max(floor, 1e-300)))


# --- spectrum, speed, severity -------------------------------------------------------------------------

def _spectrum(job: Job, window="hann"):
    """Amplitude spectrum of the primary channel (acceleration) and the velocity spectrum from it.
    Hann for lines; Blackman-Harris (sidelobes below -92 dB) where the floor beside a strong line
    is measured, so the line's own leakage is not taken for a raised floor."""
    last = _LAST["spectrum"]   # one snapshot: another thread may replace it meanwhile
    if last is not None and last[0] is job.a and last[1] == (job.fs, window):
        return last[2]
    n = job.a.size
    win = symmetric_window(window, n)
    A = np.abs(_sfft.rfft((job.a - job.a.mean()) * win)) * 2 / win.sum()   # scipy's: 2x numpy's at awkward n
    f = np.fft.rfftfreq(n, 1 / job.fs)
    V = np.where(f > 0, A / (2 * np.pi * np.maximum(f, 1e-12)), 0.0)  # velocity amplitude
    for arr in (f, A, V):
        arr.flags.writeable = False
    if n <= CACHED_SAMPLES:   # a long record's spectrum is not held after the analysis
        _LAST["spectrum"] = (job.a, (job.fs, window), (f, A, V))
    return f, A, V


# The speed step and the shaft-order step ask for the same primary channel's spectrum when no supply
# line is taken out of it: the last one is kept (read-only), keyed on the very array it was taken of
# (a job's arrays are never changed in place; a new one replaces them).
_LAST: dict = {"spectrum": None}


def _lines_standing(f, A, k, need):
    """(refined frequency, height in dB) of each local maximum among the bins k that stands ``need`` dB
    above its local floor."""
    k = k[(k >= 1) & (k < A.size - 1)]
    for i in k[(A[k] >= A[k - 1]) & (A[k] > A[k + 1])]:
        db = _line(f, A, f[i], 0.6 * f[1], f[i] + 5 * f[1])[2]
        if db >= need:
            yield _refine(f, A, f[i]), db


def _harmonic_support(f, A, fc) -> int:
    """How many of the harmonics 2X-6X of a 1X candidate at fc stand LINE_DB above their floor, within
    0.2 % (at least 1.5 lines) of k x fc."""
    df = f[1]
    return sum(_line(f, A, k * fc, max(1.5 * df, 0.002 * k * fc), k * fc + 5 * df)[2] >= LINE_DB
               for k in range(2, 7))


def _refine(f, A, f0):
    """Sub-bin frequency of the line at f0 (parabola through the log amplitudes of the Hann peak)."""
    k = int(round(f0 / f[1]))
    if not 1 <= k < A.size - 1:
        return f0
    a, b, c = np.log(np.maximum(A[k - 1: k + 2], 1e-300))
    den = a - 2 * b + c
    return float(f0 + (0.5 * (a - c) / den if den < 0 else 0.0) * f[1])


def _row(fault, expected, found_hz, amp, db, conf, note="", **more):
    return {"fault": fault, "expected_hz": expected, "found_hz": found_hz, "amplitude": amp, "evidence_db": db,
            "confidence": float(np.clip(conf, 0, 1)), "note": note, **more}
