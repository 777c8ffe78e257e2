"""Stepped-sine (sine-dwell) FRF: one tone at a time, each channel's amplitude and phase by least squares.

Steps, each a function below: cut the record into its dwells, keep the settled part's whole cycles, fit
a cos + b sin + offset + drift (and harmonics 2 and 3) to every channel, divide response by force, then
check what the estimate rests on: a settled (steady) response, a linear (sinusoidal) response and a tone
well above the noise. The std of each tone's H follows from the fit's residual.
"""

from __future__ import annotations

import numpy as np

from ..core._validate import as_record, positive
from ..core.errors import ParameterError, warn_quality
from ..core.results import FRF, form_of
from .frf import _io

__all__ = ["stepped_sine"]

MIN_CYCLES = 4            # whole cycles a tone's fit needs after settling (two per half for the settling check)
SETTLED_SIGMAS = 3.0      # halves further apart than 3 combined stds (and 0.5 %) have not settled
SETTLED_FLOOR = 0.005
DISTORTION_LIMIT = 0.05   # harmonics 2-3 above 5 % of the tone: the structure (or shaker) is not linear
SNR_LIMIT = 10.0          # a tone's amplitude below 10 stds of its estimate: H is noise-dominated


def stepped_sine(rec, freqs, *, input="force", outputs=None, dwell: float | None = None, settle: float = 0.3,
                 fs: float | None = None) -> FRF:
    """FRF from a stepped-sine test: dwells of equal length, one tone each, one after the other.

    Parameters
    ----------
    rec : Record
        Force and responses, the dwells back to back from the record's start.
    freqs : array_like
        The tone of each dwell in Hz, in the order played.
    input : str or int
        The force channel ("force": the channel whose quantity is force).
    outputs : str, int or list, optional
        Response channels (default every other channel).
    dwell : float, optional
        Length of each dwell in s (default the record's duration over the number of tones).
    settle : float
        Share of each dwell left out at its start while the transient of the step dies out.
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    FRF
        ``h`` per tone (estimator "stepped-sine"), ``random_error`` the relative std of |H| per tone (also
        the std of its phase in rad: noise, plus half the change of H between the dwell's two halves); ``params["flags"]`` lists per tone what failed a check
        (``not_settled``, ``distorted``, ``low_snr``), ``params["thd"]`` the harmonic distortion.

    Raises
    ------
    ParameterError
        For tones at or above Nyquist, dwells that do not fit the record, or fewer than 4 settled cycles.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> s = vm.models.SDOF(m=1.0, k=(2 * np.pi * 20) ** 2, zeta=0.05)
    >>> tones, fs, dwell = np.array([10.0, 20.0, 30.0]), 2000.0, 4.0
    >>> t = np.arange(int(dwell * fs)) / fs
    >>> f = np.concatenate([np.sin(2 * np.pi * ft * t) for ft in tones])
    >>> x = s.response(np.arange(f.size) / fs, f)
    >>> rec = vm.Record(np.vstack([f, x]), fs=fs, channels=[vm.Channel("F", "force", "N"),
    ...                                                   vm.Channel("x", "displacement", "m")])
    >>> frf = vm.stepped_sine(rec, tones, settle=0.5)     # 2 s settle: 12 time constants
    >>> err = np.abs(frf.h[0, 0] / s.frf(tones) - 1)
    >>> bool(np.all(err < 1e-3))
    True
    """
    rec = as_record(rec, fs=fs)
    freqs = _tones(freqs, rec.fs)
    ii, oo = _io(rec, input, outputs)
    if len(ii) != 1:
        raise ParameterError("stepped_sine takes one force channel: a tone excites through one input at a time")
    spans = _dwells(rec, freqs, dwell, settle)
    chans = [ii[0]] + oo
    for o in oo:
        if not np.all(np.isfinite(rec.data[o])):
            raise ParameterError(f"output channel {rec.names[o]!r} holds NaN or inf samples: the rule is finite data "
                                 "(repair or cut the record first)")
    fits = [_fit_tone(rec.data[chans][:, a:b], f, rec.fs) for f, (a, b) in zip(freqs, spans)]
    h, rel, thd, snr, halves = _ratios(fits)
    flags = _checks(freqs, rel, thd, snr, halves)
    out_q = {rec.channels[o].quantity for o in oo}
    form = form_of(out_q.pop()) if len(out_q) == 1 else "unknown"
    return FRF(freq=freqs, h=h[:, None, :], form=form, estimator="stepped-sine",
               outputs=tuple(rec.names[o] for o in oo), inputs=(rec.names[ii[0]],),
               unit=f"{rec.channels[oo[0]].unit}/{rec.channels[ii[0]].unit}", random_error=rel,
               params={"estimator": "stepped-sine", "settle": settle, "flags": flags, "thd": thd,
                       "phase_std_rad": rel})


def _tones(freqs, fs):
    try:
        f = np.atleast_1d(np.asarray(freqs, float))
    except (TypeError, ValueError):
        raise ParameterError("freqs must be numbers (Hz)") from None
    if f.ndim != 1 or f.size == 0 or not np.all(np.isfinite(f)) or np.any(f <= 0):
        raise ParameterError("freqs must be one or more positive, finite frequencies in Hz")
    if np.any(f >= fs / 2):
        raise ParameterError(f"freqs reach {f.max():g} Hz, at or above Nyquist ({fs / 2:g} Hz at fs={fs:g})")
    return f


def _dwells(rec, freqs, dwell, settle):
    if not 0 <= float(settle) < 0.9:
        raise ParameterError(f"settle={settle!r} must be a share of each dwell in [0, 0.9)")
    d = rec.duration / freqs.size if dwell is None else positive(dwell, "dwell")
    n = int(round(d * rec.fs))
    if n * freqs.size > rec.n_samples:
        raise ParameterError(f"{freqs.size} dwells of {d:g} s need {n * freqs.size} samples; the record holds "
                             f"{rec.n_samples}")
    spans = []
    for i, f in enumerate(freqs):
        a = i * n + int(np.ceil(settle * n))
        per = rec.fs / f
        cycles = int(((i + 1) * n - a) / per)
        if cycles < MIN_CYCLES:
            raise ParameterError(f"the {f:g} Hz dwell holds {cycles} whole cycles after settling; at least "
                                 f"{MIN_CYCLES} are needed: lengthen the dwell or lower settle")
        spans.append((a, a + int(round(cycles * per))))
    return spans


def _design(n, f, fs, harmonics=(1, 2, 3)):
    t = np.arange(n) / fs
    cols = []
    for h in harmonics:
        cols += [np.cos(2 * np.pi * h * f * t), np.sin(2 * np.pi * h * f * t)]
    return np.column_stack(cols + [np.ones(n), t - t.mean()])


def _fit_tone(y, f, fs):
    """Per channel: complex amplitude X (y = Re(X e^(i w t))), its std, harmonic ratio, and the two halves' X."""
    n = y.shape[1]
    A = _design(n, f, fs)
    coef, *_ = np.linalg.lstsq(A, y.T, rcond=None)
    resid = y.T - A @ coef
    sigma = np.sqrt(np.sum(resid ** 2, axis=0) / max(n - A.shape[1], 1))
    X = coef[0] - 1j * coef[1]
    std = sigma * np.sqrt(2.0 / n)           # per real component of X, for whole cycles
    harm = np.hypot(coef[2], coef[3]) + np.hypot(coef[4], coef[5])
    halves, B = [], _design(n, f, fs, harmonics=(1,))    # one time base: the halves' phases compare
    for s in (slice(0, n // 2), slice(n // 2, n)):
        c, *_ = np.linalg.lstsq(B[s], y[:, s].T, rcond=None)
        halves.append(c[0] - 1j * c[1])
    return X, std, harm / np.maximum(np.abs(X), 1e-300), halves


def _ratios(fits):
    X = np.array([f[0] for f in fits]).T          # (channels, tones), channel 0 the force
    S = np.array([f[1] for f in fits]).T
    thd = np.array([f[2] for f in fits]).T
    h = X[1:] / X[0]
    first, second = np.array([f[3][0] for f in fits]).T, np.array([f[3][1] for f in fits]).T
    # noise, plus half the difference between the two halves' H: a response still settling (or drifting)
    # biases H by about that much, and the std says so
    unsettled = np.abs(second[1:] / second[0] - first[1:] / first[0]) / (2 * np.abs(h))
    rel = np.sqrt((S[1:] / np.abs(X[1:])) ** 2 + (S[0] / np.abs(X[0])) ** 2 + unsettled ** 2)
    snr = np.abs(X) / np.maximum(S, 1e-300)
    return h, rel, thd, snr, (first, second, S)


def _checks(freqs, rel, thd, snr, halves):
    first, second, S = halves
    flags = []
    for k, f in enumerate(freqs):
        tone = []
        drift = np.abs(second[:, k] - first[:, k])
        limit = SETTLED_SIGMAS * 2 * S[:, k] + SETTLED_FLOOR * np.abs(second[:, k])
        if np.any(drift > limit):
            tone.append("not_settled")
        if np.any(thd[:, k] > DISTORTION_LIMIT):
            tone.append("distorted")
        if np.any(snr[:, k] < SNR_LIMIT):
            tone.append("low_snr")
        flags.append(tone)
    bad = {name: [float(f) for f, t in zip(freqs, flags) if name in t]
           for name in ("not_settled", "distorted", "low_snr")}
    said = [f"{name} at {', '.join(f'{v:g}' for v in fl)} Hz" for name, fl in bad.items() if fl]
    if said:
        warn_quality("stepped_sine: " + "; ".join(said) + " (not_settled: lengthen the dwell or raise settle; "
                     "distorted: lower the level, the response is not linear; low_snr: raise the level)",
                     stacklevel=4)
    return flags
