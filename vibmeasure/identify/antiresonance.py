"""Anti-resonances of an FRF, and the drive-point test they allow.

A driving-point FRF (response where the force acts) of a passive structure alternates resonance,
anti-resonance, resonance: between two modes of the same sign of residue its magnitude must pass through
a zero. A transfer FRF may skip anti-resonances (neighbouring residues of opposite sign give a minimum
without a zero). So a "drive-point" FRF that does not alternate was not measured where the force acts,
or its sensor sits on a node, its channels are swapped, or two close modes were not resolved.
"""

from __future__ import annotations

import numpy as np

from ..core._validate import positive
from ..core.errors import ParameterError, warn_quality
from ..core.results import FRF

__all__ = ["antiresonances"]


def antiresonances(frf: FRF, *, output=0, input=0, band=None, prominence_db: float = 6.0,
                   drive_point: bool = True) -> dict:
    """Anti-resonance and resonance frequencies of one FRF, and whether they alternate.

    Each is a local minimum (maximum) of 20 log10 |H| that stands ``prominence_db`` out of its
    surroundings, refined by a parabola through the three lines around it; a minimum is an anti-resonance
    (a zero of H) only where the phase turns back by more than 90 degrees across it.

    Parameters
    ----------
    frf : FRF
        The measured or synthesised FRF.
    output, input : int or str
        Which response and which force (index or name).
    band : (float, float), optional
        Frequencies to search, in Hz (default the whole FRF except 0 Hz).
    prominence_db : float
        How far a minimum or maximum must stand out to count (noise ripples do not).
    drive_point : bool
        The FRF is a driving point (response where the force acts): check the alternation and warn when
        it fails.

    Returns
    -------
    dict
        "antiresonances" and "resonances" (Hz), "depth_db" (each anti-resonance's prominence), "minima"
        (Hz: dips where the phase does not turn back, so not zeros of H, as between two modes of a transfer
        FRF whose residues have opposite signs),
        "alternates" (bool: every pair of neighbouring resonances has one anti-resonance between them
        and no two anti-resonances stand side by side), "advice" (text; empty when they alternate).

    Raises
    ------
    ParameterError
        For an unknown channel, a band outside the FRF, or a prominence that is not positive.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> two = vm.models.chain([1.0, 0.5], [2e4, 1e4], modal_zeta=0.01)     # drive point: mass 1
    >>> f = np.linspace(1, 60, 6000)
    >>> h = vm.FRF(freq=f, h=two.frf(f)[0, 0])
    >>> r = vm.antiresonances(h)
    >>> round(float(r["antiresonances"][0]), 2), r["alternates"]       # at sqrt(k2 / m2) / (2 pi)
    (22.51, True)
    """
    from scipy.signal import find_peaks
    if not isinstance(frf, FRF):
        raise ParameterError(f"frf must be a vm.FRF, got {type(frf).__name__}")
    io, ii = _index(output, frf.outputs, frf.n_outputs, "output"), _index(input, frf.inputs, frf.n_inputs, "input")
    p = positive(prominence_db, "prominence_db")
    f = np.asarray(frf.freq, float)
    if band is not None:
        try:
            lo, hi = (float(v) for v in band)
        except (TypeError, ValueError):
            raise ParameterError(f"band={band!r} must be two frequencies (lo, hi) in Hz") from None
        if not (np.isfinite(lo) and np.isfinite(hi) and 0 <= lo < hi):
            raise ParameterError(f"band={band!r} must satisfy 0 <= lo < hi (Hz)")
    sel = f > 0 if band is None else (f >= lo) & (f <= hi) & (f > 0)
    if np.count_nonzero(sel) < 5:
        raise ParameterError(f"band={band!r} holds {np.count_nonzero(sel)} lines of the FRF; at least 5 are needed")
    f, h = f[sel], frf.h[io, ii][sel]
    db = 20 * np.log10(np.maximum(np.abs(h), 1e-300))
    lo, plo = find_peaks(-db, prominence=p)
    hi, _ = find_peaks(db, prominence=p)
    zero = _phase_rises(np.unwrap(np.angle(h)), lo, hi)
    anti, res = _refine(f, db, lo[zero]), _refine(f, db, hi)
    ok, advice = _alternation(anti, res)
    if drive_point and not ok:
        warn_quality(f"antiresonances: {advice}", stacklevel=2)
    return {"antiresonances": anti, "resonances": res, "depth_db": plo["prominences"][zero],
            "minima": _refine(f, db, lo[~zero]), "alternates": ok, "advice": advice}


def _index(which, names, n, what):
    if isinstance(which, str):
        if which not in names:
            raise ParameterError(f"{what}={which!r} is not one of {list(names)}")
        return list(names).index(which)
    if isinstance(which, bool) or not isinstance(which, (int, np.integer)) or not 0 <= which < n:
        raise ParameterError(f"{what}={which!r} must be a name or an index below {n}")
    return int(which)


def _phase_rises(phase, lo, hi):
    """Which minima are zeros of H: across a zero the phase turns the other way from a resonance's (a
    lightly damped mode turns it by -180 degrees, a zero by +180); a minimum between two modes of opposite
    residue sign is not a zero and the phase runs on. The sign convention is read off the resonances."""
    def turn(k, others):
        near = np.abs(np.asarray(others, int) - k)
        near = near[near > 0]
        w = max(int(near.min() // 2) if near.size else 10, 1)
        a, b = max(k - w, 0), min(k + w, phase.size - 1)
        return phase[b] - phase[a]
    extremes = np.sort(np.r_[lo, hi])
    sign = -1.0
    if hi.size:
        sign = np.sign(np.median([turn(k, extremes) for k in hi])) or -1.0
    return np.array([turn(k, extremes) * sign < -np.pi / 2 for k in lo], dtype=bool)


def _refine(f, db, idx):
    """Parabolic vertex through the three lines around each extremum (uniform or not)."""
    out = []
    for k in idx:
        if 0 < k < f.size - 1:
            x, y = f[k - 1:k + 2], db[k - 1:k + 2]
            a, b, _ = np.polyfit(x - f[k], y, 2)
            out.append(f[k] - b / (2 * a) if a != 0 else f[k])
        else:
            out.append(f[k])
    return np.array(out)


def _alternation(anti, res):
    events = sorted([(v, "A") for v in anti] + [(v, "R") for v in res])
    kinds = [k for _, k in events]
    doubled = [(events[i][0], k) for i, k in enumerate(kinds[1:]) if k == kinds[i]]
    if not doubled:
        return True, ""
    v, k = doubled[0]
    what = "two resonances with no anti-resonance" if k == "R" else "two anti-resonances with no resonance"
    return False, (f"{what} between them from {v:.4g} Hz: a driving-point FRF alternates. Check that the response "
                   "is measured where the force acts and off a node, that input and output are not swapped, or "
                   "resolve close modes with a finer frequency line spacing")
