"""Damping from a measured force-displacement loop: the energy one cycle dissipates is the loop's area.

Steps, each a function below: check the inputs, cut whole cycles at the displacement's upward mean
crossings, integrate each closed loop, take the in-phase stiffness, then check the assumptions the
equivalent values rest on (steady amplitude, harmonic motion, energy dissipated rather than supplied).
"""

from __future__ import annotations

import numpy as np

from ..core._validate import positive
from ..core.errors import FitError, ParameterError, warn_quality
from ..core.results import LoopDamping

__all__ = ["loop_damping"]

MIN_SAMPLES_PER_CYCLE = 16   # the trapezoid loop area is within 1 % of a sine's from 16 samples a cycle
AMPLITUDE_STEADY = 0.05      # cycle amplitudes further apart than 5 % are not one steady state
HARMONIC_LIMIT = 0.05        # displacement harmonics above 5 % of the fundamental: not a harmonic motion


def loop_damping(displacement, force, *, fs: float) -> LoopDamping:
    """Energy dissipated per cycle, loss factor and equivalent viscous damping from a force-displacement loop.

    For each whole cycle W = the loop's area (the integral of F dx), X = half its peak-to-peak displacement,
    w its frequency; eta = W / (pi k X^2) with k the in-phase stiffness (least squares of F on x and dx/dt),
    and c_eq = W / (pi w X^2). Linear viscous damping gives W = pi c w X^2, hysteretic W = pi eta k X^2,
    dry friction W = 4 F_f X.

    Parameters
    ----------
    displacement : array_like
        Relative displacement across the element in m.
    force : array_like
        Force through the element in N, positive when it resists positive displacement.
    fs : float
        Sampling rate in Hz.

    Returns
    -------
    LoopDamping

    Raises
    ------
    ParameterError
        For arrays of different lengths, values that are not finite, or a constant displacement.
    FitError
        For less than one whole cycle, too few samples per cycle, or a loop that supplies energy.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> t = np.arange(4000) / 1000.0                      # 4 s of 5 Hz at 1 mm
    >>> x = 1e-3 * np.sin(2 * np.pi * 5 * t)
    >>> F = 2e4 * x + 30.0 * np.gradient(x, t)            # k = 20 kN/m, c = 30 N s/m
    >>> r = vm.loop_damping(x, F, fs=1000.0)
    >>> round(r.c_equivalent, 1), round(r.loss_factor, 4)     # c w / k = 0.0471
    (30.0, 0.0471)
    """
    x, F, fs = _inputs(displacement, force, fs)
    edges = _cycles(x, fs)
    W, X, w = _cycle_energies(x, F, fs, edges)
    k = _in_phase_stiffness(x, F, fs, edges)
    flags = _assumptions(x, W, X, edges)
    return _result(W, X, w, k, flags)


def _inputs(displacement, force, fs):
    fs = positive(fs, "fs")
    try:
        x = np.asarray(displacement, float).reshape(-1)
        F = np.asarray(force, float).reshape(-1)
    except (TypeError, ValueError):
        raise ParameterError("displacement and force must be arrays of numbers") from None
    if x.size != F.size:
        raise ParameterError(f"displacement ({x.size} samples) and force ({F.size}) must have the same length")
    for a, name in ((x, "displacement"), (F, "force")):
        if not np.all(np.isfinite(a)):
            raise ParameterError(f"{name} holds NaN or inf samples: remove or interpolate them first")
    if x.size < 3 or np.ptp(x) == 0:
        raise ParameterError("displacement is constant or empty: a loop needs motion")
    return x, F, fs


def _cycles(x, fs):
    """Fractional sample positions of the displacement's upward crossings of its mid-range."""
    d = x - (x.max() + x.min()) / 2
    i = np.flatnonzero((d[:-1] < 0) & (d[1:] >= 0))
    edges = i + d[i] / (d[i] - d[i + 1])
    # a crossing closer than half a median period to the previous is noise on the slope, not a cycle
    if edges.size >= 2:
        keep = [edges[0]]
        half = np.median(np.diff(edges)) / 2
        for e in edges[1:]:
            if e - keep[-1] > half:
                keep.append(e)
        edges = np.array(keep)
    if edges.size < 2:
        raise FitError(f"loop_damping: {max(edges.size - 1, 0)} whole cycles of displacement; at least one is needed")
    per = float(np.median(np.diff(edges)))
    if per < MIN_SAMPLES_PER_CYCLE:
        raise FitError(f"loop_damping: {per:.1f} samples per cycle; at least {MIN_SAMPLES_PER_CYCLE} trace the loop "
                       f"(the cycle is {per / fs * 1e3:.3g} ms at fs={fs:g} Hz)")
    return edges


def _at(a, pos):
    j = int(np.floor(pos))
    return a[j] + (pos - j) * (a[min(j + 1, a.size - 1)] - a[j])


def _loop(x, F, a, b):
    """One cycle's samples, closed by its interpolated start and end points."""
    j = np.arange(int(np.floor(a)) + 1, int(np.floor(b)) + 1)
    return np.r_[_at(x, a), x[j], _at(x, b)], np.r_[_at(F, a), F[j], _at(F, b)]


def _cycle_energies(x, F, fs, edges):
    W, X, w = [], [], []
    for a, b in zip(edges[:-1], edges[1:]):
        xs, Fs = _loop(x, F, a, b)
        W.append(float(np.sum((Fs[1:] + Fs[:-1]) / 2 * np.diff(xs))))   # trapezoid integral of F dx
        X.append(float(np.ptp(xs)) / 2)
        w.append(2 * np.pi * fs / (b - a))
    return np.array(W), np.array(X), np.array(w)


def _in_phase_stiffness(x, F, fs, edges):
    """k of F = k x + c dx/dt + F0 over the whole cycles (the part of the force in phase with x)."""
    s = slice(int(np.ceil(edges[0])), int(np.floor(edges[-1])) + 1)
    xs, Fs = x[s], F[s]
    A = np.column_stack([xs, np.gradient(xs) * fs, np.ones(xs.size)])
    coef, *_ = np.linalg.lstsq(A, Fs, rcond=None)
    return float(coef[0])


def _assumptions(x, W, X, edges):
    flags = []
    if np.mean(W) <= 0:
        raise FitError(f"loop_damping: the loop supplies {-np.mean(W):.3g} J per cycle instead of dissipating it: "
                       "force and displacement have opposite sign conventions (a force measured on the other side of "
                       "the element); negate one of them")
    if W.size == 1:
        flags.append("one_cycle")
    if np.ptp(X) > AMPLITUDE_STEADY * np.mean(X):
        flags.append("amplitude_varies")
    s = slice(int(np.ceil(edges[0])), int(np.floor(edges[-1])) + 1)
    seg = x[s] - np.mean(x[s])
    spec = np.abs(np.fft.rfft(seg * np.hanning(seg.size)))
    k1 = int(np.argmax(spec))
    harm = [spec[max(h * k1 - 2, 0): h * k1 + 3].max() for h in range(2, 6) if h * k1 + 3 <= spec.size]
    if harm and max(harm) > HARMONIC_LIMIT * spec[k1]:
        flags.append("not_harmonic")
    if flags:
        warn_quality(f"loop_damping: {', '.join(flags)}", stacklevel=4)
    return tuple(flags)


def _result(W, X, w, k, flags):
    n = W.size
    eta = W / (np.pi * k * X ** 2) if k > 0 else np.full(n, np.nan)
    c = W / (np.pi * w * X ** 2)

    def mean_std(v):
        return float(np.mean(v)), (float(np.std(v, ddof=1) / np.sqrt(n)) if n > 1 else float("nan"))

    (Wm, Ws), (em, es), (cm, cs) = mean_std(W), mean_std(eta), mean_std(c)
    return LoopDamping(energy_per_cycle=Wm, energy_std=Ws, loss_factor=em, loss_factor_std=es, c_equivalent=cm,
                       c_std=cs, stiffness=k, amplitude=float(np.mean(X)), freq=float(np.mean(w) / (2 * np.pi)),
                       n_cycles=int(n), flags=flags)
