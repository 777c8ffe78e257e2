"""Step 1, prepare: per channel, pre-whitened squared-envelope spectra (SES) in their demodulation
bands, each line divided by its local floor (``_SES``, ``_spectra``), and the channels' fused view."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
from scipy import fft as _fft

from ...signal.kurtogram import kurtogram_of, ses_power
from ...signal.whiten import (ar_order, ar_residual, cepstral_spectrum, edit_lines, measured_top, synchronous_part,
                              tapered_spectrum)
from .rules import R_CAP, R_LINE


@dataclass
class _SES:
    channel: str
    prep: str
    band: tuple
    freq: np.ndarray
    amp: np.ndarray
    r: np.ndarray
    n_valid: int
    results: dict = field(default_factory=dict)
    primary: str | None = None   # the family that claimed its lines first
    kurtogram: object = None
    r_base: np.ndarray | None = None
    base_results: dict | None = None   # each family's comb on r_base (``families._explain``'s first pass)
    shape: int = 1               # r is the mean of this many independent spectra (Gamma(shape)/shape)
    cage_floor: dict = field(default_factory=dict)   # multiple of n_balls x FTF -> (lo Hz, hi Hz, level)
    parts: tuple = ()            # a fused view's channels, each with its own band: ((channel, band), ...)

    @property
    def sources(self) -> tuple:
        """The data this spectrum is made of: ((channel, band), ...), one pair unless channels were fused."""
        return self.parts or ((self.channel, self.band),)

    @property
    def r_line(self) -> float:
        """The level a single line must reach (R_LINE); on a mean of several spectra it is kept as is,
        which is stricter there (their noise spreads less): measured, a per-spectrum equivalent
        threshold added false calls on the development recordings."""
        return R_LINE

    @property
    def given(self) -> bool:
        """Whether this spectrum is of the user's band (``_candidates``)."""
        return GIVEN in self.prep


def _floor_ratio(amp: np.ndarray, df: float, halfwidth_hz: float) -> np.ndarray:
    """Power over the local median floor (converted to a mean: median of Exp(1) is ln 2), mapped so that
    under noise it is exactly Exp(1) (``_exact_exponential``)."""
    from scipy.ndimage import median_filter
    P = amp ** 2
    w = int(max(20, round(halfwidth_hz / df)))
    floor = median_filter(P, size=2 * w + 1, mode="reflect") / np.log(2.0)
    r = _exact_exponential(P / np.maximum(floor, 1e-300), 2 * w + 1)
    r[:3] = 0.0  # the envelope's mean and the window's main lobe
    return r


def _exact_exponential(r: np.ndarray, W: int) -> np.ndarray:
    """The ratio of an Exp(1) power to the median of a W-bin window over ln 2 has a heavier tail than
    Exp(1): the median is itself uncertain (relative spread about 1.25 / sqrt(W)). A bin above the
    median sees as floor the k-th smallest (k = (W + 1) / 2) of the W - 1 others, which by the Renyi
    representation is M = sum_{j<k} E_j / (W - 1 - j); so P(ratio > t) = prod_{j<k} (W - 1 - j) /
    (W - 1 - j + t / ln 2) exactly, and -log of it is Exp(1) in the tail, where lines are judged.
    Measured on white noise: with 41 bins (a 1 s record) the raw ratio exceeded 10 at 5.8x the Exp(1)
    rate, and single-record false alarms followed; with 167 bins (10 s) at 1.7x. Mapped: 1.0x."""
    k = (W + 1) // 2
    grid, g = _exponential_map(W)
    out = np.interp(r, grid, g)
    far = r > grid[-1]   # there every factor is t / (ln 2 (W - j)): the map grows as k log t
    if far.any():
        out[far] = g[-1] + k * np.log(r[far] / grid[-1])
    return out


@lru_cache(maxsize=8)
def _exponential_map(W: int) -> tuple[np.ndarray, np.ndarray]:
    """The grid of ratios and -log P(ratio > t) on it for a W-bin median floor (``_exact_exponential``),
    read-only: every spectrum of a record has the same W, and the map costs a thousand sums of (W + 1) / 2
    logarithms."""
    k = (W + 1) // 2
    grid = np.concatenate([np.linspace(0.0, 4.0 * R_CAP, 801)[:-1], np.geomspace(4.0 * R_CAP, 1e8, 200)])
    g = np.log1p(grid[:, None] / (np.log(2.0) * (W - 1 - np.arange(k)[None, :]))).sum(axis=1)
    grid.flags.writeable = g.flags.writeable = False
    return grid, g


# --- spectra to test ------------------------------------------------------------------------------

WHITENING = ("cepstral", "ar")
# Share of the record tapered (Tukey window, half at each end) before the spectrum that is whitened. A
# record's ends do not meet: the jump leaks across the whole spectrum (1/f), and so does an off-bin
# tone. Whitening lifts that leakage to full height where the signal is weak (above a low-pass edge,
# around a strong tone), and it becomes an impulse at the record's ends with high kurtosis. On the
# development records, with the measured band's edge already in place, a tone 20 dB above the RMS
# at 0.4 fs turned 3 "none" into wrong calls and low-passing at 0.4 fs gave 5 wrong calls; with the
# taper, none and 0 (benchmarks/diagnosis_robustness.py).
TAPER = 0.05


def _limits(fs, f1, freqs, f_top_band=None):
    """(highest fault line, narrowest band, cyclic range needed, lowest band edge); f_top_band is the
    upper edge of the measured band (default Nyquist)."""
    top = fs / 2 if f_top_band is None else f_top_band
    f_top = max(freqs["BPFI"] + f1, freqs["2xBSF"] + freqs["FTF"], freqs["BPFO"])
    min_bw = min(3.0 * f_top, 0.4 * top)  # the envelope must carry the third harmonic
    f_need = min(5.0 * f_top, fs / 2)
    # demodulation bands start above the shaft-harmonic region: 10 x BPFI, at least 500 Hz
    f_lo = min(max(10.0 * freqs["BPFI"], 500.0), top - 2 * min_bw)
    return f_top, min_bw, f_need, f_lo


GIVEN = " (band given)"   # the pre-processing label of the spectra in a user's band


def _candidates(x, fs, f1, freqs, band, whitening):
    """(pre-processing, band, spectrum of the pre-processed signal, kurtogram) to demodulate.

    cepstral: the whole measured band above the shaft region, the fast kurtogram's band and the
    infogram's; ar: shaft-synchronous part and remaining discrete lines removed, AR-whitened,
    kurtogram band; with a user band, that band too, cepstral-whitened and raw. Above the measured band
    (``measured_top``: a filter's stop band, the converter's floor) the whitened spectra are zero.

    A user's band is one view of the record among the others, never the only one: alone it decided
    by itself (the two-view rule waived for a single channel), and a band that missed the bearing's
    resonance named what its clutter made (on the development records, four bands of a user's choice
    gave 22 confident wrong calls: healthy CWRU Normal_0 outer race, inner race or ball by the band,
    fan-end B021_0 outer race at 1.00). With the record's own bands beside it, a finding in the user's
    band alone needs the single-view evidence (``evidence._one_view``), and one the record's bands
    contradict meets their claims."""
    X = tapered_spectrum(x, TAPER)
    f_hi = measured_top(X, fs, x.size)
    k_hi = int(np.floor(f_hi * x.size / fs))
    f_top, min_bw, f_need, f_lo = _limits(fs, f1, freqs, f_hi)
    Xw = cepstral_spectrum(X, k_hi)
    out = []
    if band is not None:
        out += [("cepstral" + GIVEN, tuple(band), cepstral_spectrum(X), None), ("raw" + GIVEN, tuple(band), X, None)]
    if "cepstral" in whitening:
        kg = kurtogram_of(None, fs, n=x.size, min_bandwidth=min_bw, max_level=None, criterion="kurtosis",
                           cyclic_max=f_need, X=Xw, f_lo=f_lo, f_hi=f_hi)
        out.append(("cepstral", (f_lo, f_hi), Xw, kg))
        # a measured band only about twice the narrowest width leaves the kurtogram no band to choose
        # (NaN): the whole band stands alone
        if _finite(kg.band):
            out.append(("cepstral + kurtogram", kg.band, Xw, None))
        info = tuple(kg.best("negentropy")[:2])
        if _finite(info) and info != tuple(kg.band):
            out.append(("cepstral + infogram", info, Xw, None))
    if "ar" in whitening:
        y = edit_lines(x - synchronous_part(x, fs, f1))
        Xa = _fft.rfft(ar_residual(y, ar_order(y, fs, f_top)))
        Xa[k_hi + 1:] = 0
        kga = kurtogram_of(None, fs, n=x.size, min_bandwidth=min_bw, max_level=None, criterion="kurtosis",
                            cyclic_max=f_need, X=Xa, f_lo=f_lo, f_hi=f_hi)
        out.append(("synchronous removed + AR + kurtogram", kga.band, Xa, kga if not out else None) if _finite(kga.band)
                   else ("synchronous removed + AR", (f_lo, f_hi), Xa, kga if not out else None))
    return out, f_hi


def _finite(band) -> bool:
    return bool(np.all(np.isfinite(np.asarray(band, float))))


def _spectra(x: np.ndarray, fs: float, name: str, f1: float, freqs: dict, band,
             whitening=("cepstral",)) -> tuple[list[_SES], float]:
    """The normalised SES of each pre-processing and band of one channel, and the upper edge of the
    band the channel measures."""
    _, _, f_need, _ = _limits(fs, f1, freqs)
    out = []
    cands, f_hi = _candidates(x, fs, f1, freqs, band, whitening)
    for prep, b, X, kg in cands:
        freq, amp, f_valid = ses_power(X, x.size, fs, b, f_need)
        df = freq[1]
        r = _floor_ratio(amp, df, max(5.0, 0.5 * freqs["FTF"], 0.25 * f1))
        out.append(_SES(name, prep, tuple(float(v) for v in b), freq, amp, r, min(freq.size, int(f_valid / df)),
                        kurtogram=kg))
    return out, f_hi


def _fused(spectra: list) -> list:
    """Per pre-processing, the mean of the channels' normalised spectra: a fault that shows weakly in
    several sensors adds up (under noise the mean of C ratios is Gamma(C)/C)."""
    out = []
    channels = list(dict.fromkeys(s.channel for s in spectra))
    if len(channels) < 2:
        return out
    for prep in dict.fromkeys(s.prep for s in spectra):
        group = [s for s in spectra if s.prep == prep]
        if len(group) < 2:
            continue
        n = min(s.r.size for s in group)
        nv = min(s.n_valid for s in group)
        r = np.mean([s.r[:n] for s in group], axis=0)
        amp = np.sqrt(np.mean([s.amp[:n] ** 2 for s in group], axis=0))
        bands = {s.band for s in group}
        band = group[0].band if len(bands) == 1 else (min(b[0] for b in bands), max(b[1] for b in bands))
        label = prep + (" (channels fused)" if len(bands) == 1 else " (channels fused, each in its own band)")
        floor: dict = {}
        for s in group:   # the comb's level under each channel's lines, the highest of them
            for k, v in s.cage_floor.items():
                floor[k] = max(floor.get(k, v), v, key=lambda t: t[2])
        out.append(_SES("+".join(s.channel for s in group), label, band, group[0].freq[:n], amp, r, nv,
                        shape=len(group), cage_floor=floor, parts=tuple((s.channel, s.band) for s in group)))
    return out
