"""What SSI and FDD share: the acceptance thresholds, the output channels' checks, the duration rule
and the band kurtosis that tells a harmonic from a random response."""

from __future__ import annotations

import numpy as np

from ...core._validate import select_names
from ...core.errors import ParameterError
from ...core.record import Record

STAB_DF = 0.01        # stable: frequency within 1 % of a pole at the previous order
STAB_DZ = 0.05        # damping within 5 %
STAB_MAC = 0.98       # and shape MAC >= 0.98
CLUSTER_DF = 0.01     # poles within 1 % and
CLUSTER_MAC = 0.9     # MAC >= 0.9 belong to one mode
N_GROUPS = 8          # EFDD jackknife: the segments in this many groups, each left out once
TONE_KURTOSIS = 2.2   # band kurtosis below this: a harmonic (sinusoid: 1.5), not a random response (3)
MIN_MPC = 0.7         # modal phase collinearity below this: not a real (normal) structural mode
MAX_ZETA = 0.2        # poles with more damping are noise or numerical
MIN_CYCLES = 100      # a mode needs this many cycles in the record for its damping to mean anything


def _normalise(phi: np.ndarray) -> np.ndarray:
    """Scale each shape so its largest component is 1 (real when the mode is real)."""
    phi = np.array(phi, complex)
    for j in range(phi.shape[1]):
        k = int(np.argmax(np.abs(phi[:, j])))
        phi[:, j] = phi[:, j] / phi[k, j]
    return phi


def _outputs(rec, channels, what: str, min_outputs: int):
    """The output channels (n_out, n) as float, checked: finite, not constant, enough of them."""
    if not isinstance(rec, Record):
        raise ParameterError(f"{what}: rec must be a vm.Record of the measured responses, got {type(rec).__name__}")
    idx = select_names(rec.names, channels, source="the record")
    if channels is None:
        idx = [i for i in idx if rec.channels[i].quantity != "force"]
    if len(idx) < min_outputs:
        raise ParameterError(f"{what} needs at least {min_outputs} output channels (a mode shape needs two "
                             f"points), got {len(idx)} ({[rec.names[i] for i in idx]}); for one channel use "
                             "vm.oma_fdd or vm.ringdown on a free decay")
    Y = np.asarray(rec.data[idx], float)
    if Y.shape[1] < 16:
        raise ParameterError(f"{what}: the record has {Y.shape[1]} samples; ambient responses need thousands")
    bad = ~np.isfinite(Y)
    if bad.any():
        i, k = np.argwhere(bad)[0]
        raise ParameterError(f"{what}: channel {rec.names[idx[i]]!r} has NaN/inf samples (first at t={k / rec.fs:g} "
                             "s); the rule is finite data: repair or cut the record first")
    const = [rec.names[i] for i, y in zip(idx, Y) if np.ptp(y) == 0]
    if const:
        raise ParameterError(f"{what}: channel(s) {const} are constant: there is no response to analyse")
    return Y - Y.mean(axis=1, keepdims=True), [rec.names[i] for i in idx]


class OutputSpectra:
    """The outputs' FFT, taken once: a record's band kurtoses (one per peak, pole and neighbouring
    line) project and mask it instead of transforming the record again. The record is zero-padded to
    a fast FFT length: a length with a large prime factor (30001 = 19 x 1579) takes ten times longer,
    and the padding lies outside the middle of the record the kurtosis is taken over. ``shape`` is
    the outputs' (n_out, n)."""

    def __init__(self, Y):
        from scipy.fft import next_fast_len
        self.Y = np.atleast_2d(np.asarray(Y, float))
        self.shape = self.Y.shape
        self.n_fft = next_fast_len(self.shape[1], real=True)
        self.X = np.fft.rfft(self.Y, self.n_fft, axis=1)


def band_kurtosis(Y, fs, f0, half_width, shape=None) -> float:
    """Kurtosis of the outputs projected on ``shape`` (default: the first output) and band-passed to
    f0 +- half_width (FFT mask over the whole record, the ends trimmed): about 3 for a mode's random
    response (narrow-band Gaussian), 1.5 for a harmonic (a sinusoid). Brincker's harmonic test.
    ``Y`` is the outputs (n_out, n) or their :class:`OutputSpectra`."""
    sp = Y if isinstance(Y, OutputSpectra) else OutputSpectra(Y)
    if shape is None:
        X = sp.X[0].copy()
    else:
        v = np.asarray(shape, complex)
        v = v * np.exp(-1j * np.angle(np.sum(v ** 2)) / 2)   # rotate to the best real vector
        X = np.real(v) @ sp.X                                  # the FFT is linear: project the spectra
    n = sp.shape[1]
    f = np.fft.rfftfreq(sp.n_fft, 1 / fs)
    X[np.abs(f - f0) > half_width] = 0
    x = np.fft.irfft(X, sp.n_fft)[n // 10: n - n // 10]
    x2 = x * x   # (x ** 4 is a pow call per sample: 5x slower than squaring twice)
    p2 = np.mean(x2)
    return float(np.mean(x2 * x2) / p2 ** 2) if p2 > 0 else float("nan")


def harmonic_by_kurtosis(kurt: float, half_width: float, duration: float) -> bool:
    """Whether a band kurtosis proves a harmonic: below TONE_KURTOSIS and below what a random response
    gives once in a thousand. A narrow band over a short record holds few independent samples
    (N ~ 1.5 x bandwidth x duration, the band 2 half_width wide over the middle 80 % of the record)
    and its kurtosis scatters: the 0.1 % quantile of a Gaussian band (2000 records per width) is
    2.03 / 2.15 / 2.32 / 2.51 at N = 24 / 48 / 96 / 192, about 3 - 2.8 N^(-1/3). A narrow mode at 1.2 Hz
    over 600 s read 2.16 and was refused as a harmonic by 2.2 alone; a sinusoid reads 1.5-1.7."""
    n_eff = 1.5 * 2.0 * half_width * 0.8 * duration
    return bool(kurt < min(TONE_KURTOSIS, 3.0 - 2.8 * max(n_eff, 1.0) ** (-1.0 / 3.0)))


def _check_duration(n: int, fs: float, f_hi: float, what: str):
    """The record must hold MIN_CYCLES cycles of the band's top: below that no mode in the band can be
    identified. A mode the record holds fewer cycles of is flagged ``few_cycles`` (its damping is
    poorly determined), not refused: the rule is on the modes, not on the band's lower edge."""
    need = MIN_CYCLES / f_hi
    if n / fs < need:
        raise ParameterError(f"{what}: the record lasts {n / fs:.4g} s; even the band's top, {f_hi:.4g} Hz, needs "
                             f"at least {MIN_CYCLES} cycles for a damping estimate: a minimum duration of {need:.4g} s "
                             f"(1000 cycles of the lowest mode, for damping within a few %)")