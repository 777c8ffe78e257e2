"""Shared pieces of the free-decay methods: noise level, clipping, decay start, cycle peaks."""

from __future__ import annotations

import functools

import numpy as np
from scipy import signal as _sig
from scipy.ndimage import uniform_filter1d

from ..core.errors import FitError
from ..core.record import Record

CLIP_RUN = 3  # consecutive samples at the extreme that count as clipping


def clipped_mask(x: np.ndarray) -> np.ndarray:
    """True where a run of CLIP_RUN or more consecutive samples sits at the record's max or min."""
    mask = np.zeros(x.size, bool)
    hi, lo = x.max(), x.min()
    tol = 1e-12 * max(hi - lo, np.finfo(float).tiny)
    med = None
    for ext in (hi, lo):
        at = np.abs(x - ext) <= tol
        if at.sum() < CLIP_RUN:
            continue
        if med is None:
            med = np.median(x)
            reach = max(hi - med, med - lo)
        if abs(ext - med) < 0.5 * reach:  # a plateau near the resting value is not clipping
            continue
        d = np.diff(np.concatenate(([0], at.view(np.int8), [0])))
        starts, ends = np.flatnonzero(d == 1), np.flatnonzero(d == -1)
        for s, e in zip(starts, ends):
            if e - s >= CLIP_RUN:
                mask[s:e] = True
    return mask


def noise_std(x: np.ndarray, fs: float) -> float:
    """Broadband noise std from the median level of a Welch PSD (robust to sparse spectral lines).

    Segments of at most 4096 samples, each linearly detrended and Hann-windowed, half overlapping;
    processed a block of segments at a time, so memory stays bounded for any record length.
    """
    n = x.size
    nper = int(min(n, max(64, 2 ** int(np.log2(max(n // 16, 64))))))
    nper = min(nper, 4096)
    p = _welch_linear(x, fs, nper)
    p = p[1:-1] if p.size > 4 else p
    segs = max(1, 2 * n // nper - 1)
    # median of an average of K chi^2_2 variables: mean * (1 - 2/(9K))^3 (Wilson-Hilferty)
    k = segs
    med_to_mean = (1 - 2 / (9 * k)) ** 3 if k > 1 else np.log(2)
    level = np.median(p) / med_to_mean
    welch_std = float(np.sqrt(level * fs / 2))
    # a record that has decayed ends in noise alone: its last tenth, detrended, is the noise
    tail_std = float(np.std(detrend_linear(x[-max(16, n // 10):])))
    return min(welch_std, tail_std)


def band_noise_std(x: np.ndarray, fs: float, band) -> float:
    """Equivalent white-noise std of the noise inside a band: the median Welch level over the band's
    lines (robust to the few lines a lightly damped mode's peak covers) as sqrt(level fs / 2). Below
    the broadband std when the noise is coloured out of the band (machinery, impact transients)."""
    n = x.size
    nper = int(min(4096, max(64, 2 ** int(np.log2(max(n // 16, 64))))))
    p = _welch_linear(x, fs, min(nper, n))
    f = np.arange(p.size) * fs / min(nper, n)
    sel = (f >= band[0]) & (f <= band[1])
    if sel.sum() < 8:
        return noise_std(x, fs)
    k = max(1, 2 * n // nper - 1)
    med_to_mean = (1 - 2 / (9 * k)) ** 3 if k > 1 else np.log(2)
    return float(np.sqrt(np.median(p[sel]) / med_to_mean * fs / 2))


def detrend_linear(x: np.ndarray) -> np.ndarray:
    """x less its least-squares straight line (closed form: no Vandermonde matrix)."""
    n = x.size
    if n < 2:
        return x - x.mean() if n else x.copy()
    k = np.arange(n, dtype=float) - (n - 1) / 2
    slope = float(k @ x) / float(k @ k)
    return x - x.mean() - slope * k


@functools.lru_cache(maxsize=16)
def _hann(nper: int) -> np.ndarray:
    w = _sig.get_window("hann", nper)
    w.flags.writeable = False
    return w


def _welch_linear(x: np.ndarray, fs: float, nper: int, detrend: str = "linear") -> np.ndarray:
    """One-sided Welch PSD (Hann, 50 % overlap, linear or constant detrend per segment) in bounded
    memory.

    Same estimate as ``scipy.signal.welch(x, fs, nperseg=nper, detrend=detrend)``; the detrend is
    a projection on an orthonormal (1, k) basis, done for a block of segments at once. Written out
    because the ring-down calls it on short decays many times over (EFDD: a dozen fits per mode),
    where scipy's general path costs 1.4 ms a call against 0.2 ms here.
    """
    x = np.asarray(x, float)
    if x.size <= nper:
        nper = x.size
    step = max(1, nper // 2)
    nseg = (x.size - nper) // step + 1
    win = _hann(nper)
    k = np.arange(nper, dtype=float)
    q1 = np.full(nper, 1 / np.sqrt(nper))
    q2 = k - k.mean()
    q2 /= np.sqrt(q2 @ q2) if nper > 1 else 1.0
    acc = np.zeros(nper // 2 + 1)
    segs = np.lib.stride_tricks.as_strided(x, shape=(nseg, nper), strides=(x.strides[0] * step, x.strides[0]),
                                           writeable=False)
    blk = max(1, (1 << 21) // nper)
    for s0 in range(0, nseg, blk):
        b = segs[s0:s0 + blk]
        b = b - np.outer(b @ q1, q1)
        if detrend == "linear":
            b = b - np.outer(b @ q2, q2)
        acc += np.sum(np.abs(np.fft.rfft(b * win, axis=1)) ** 2, axis=0)
    p = acc / (nseg * fs * (win @ win))
    if nper % 2 == 0:
        p[1:-1] *= 2
    else:
        p[1:] *= 2
    return p


def decay_start(rec: Record, idx: int, x: np.ndarray) -> tuple[int, str]:
    """Index where the free decay starts and how it was found.

    After the last sample of the force pulse when the record has a force channel; after the
    trigger when the record begins with quiet pre-trigger data; otherwise at the first sample.
    """
    forces = [i for i, c in enumerate(rec.channels) if c.quantity == "force" and i != idx]
    if forces:
        f = np.abs(np.asarray(rec.data[forces[0]], float) - np.median(rec.data[forces[0]]))
        ip = int(np.argmax(f))
        above = f[ip:] > 0.02 * f[ip]
        end = ip + (int(np.argmin(above)) if not above.all() else above.size)
        return min(end + 1, x.size - 1), "after force pulse"
    nb = max(8, x.size // 400)
    nblk = x.size // nb
    if nblk < 4:
        return 0, "start"
    blocks = x[: nblk * nb].reshape(nblk, nb) - np.median(x)
    rms = np.sqrt(np.mean(blocks ** 2, axis=1))
    if rms[0] >= 0.25 * rms.max():
        # an impulsive start (rising from near zero to the peak within the first block) is an
        # impact response: the free decay begins at the peak, after the excitation
        y = np.abs(x - np.median(x))
        ip = int(np.argmax(y))
        if 0 < ip < max(nb, x.size // 50) and y[0] < 0.2 * y[ip]:
            return ip, "after impact peak"
        return 0, "start"
    j = int(np.argmax(rms > 0.5 * rms.max()))
    seg = np.abs(x[j * nb:(j + 2) * nb] - np.median(x[: max(nb, j * nb)]))
    return j * nb + int(np.argmax(seg)), "after trigger"


def trim_to_decay(x: np.ndarray, fs: float, flags: list | None = None) -> int:
    """Length to keep of a long record whose decay has long sunk into the noise (the record is cut
    there before any full-record work; "noise_floor" is added to ``flags`` when it is).

    The envelope is the RMS of 256-sample blocks; the last block above 1.5 x the noise std (11
    standard errors of a noise block) is where the slowest component is about 1.6 x the noise.
    The cut leaves the time that component needs, at the rate implied by the first block, to fall
    on to 0.3 x the noise (where the fit's own trim stops), plus 20 %. Tones that never decay keep
    the whole record.
    """
    nb = 256
    if x.size < 64 * nb:
        return x.size
    nblk = x.size // nb
    rms = np.sqrt(np.mean((x[:nblk * nb].reshape(nblk, nb) - np.median(x)) ** 2, axis=1))
    noise = noise_std(x, fs)
    if noise <= 0:
        return x.size
    above = np.flatnonzero(rms > 1.5 * noise)
    if above.size == 0:
        return x.size
    t1 = (above[-1] + 1) * nb
    a0 = np.sqrt(2) * float(rms.max())
    per_tau = np.log(max(a0 / (1.6 * noise), np.e ** 0.5))  # time constants from the peak to t1
    n_end = int(1.2 * t1 * (1 + np.log(1.6 / 0.3) / per_tau)) + 4 * nb
    if n_end >= 0.8 * x.size:
        return x.size
    if flags is not None and "noise_floor" not in flags:
        flags.append("noise_floor")
    return n_end


def baseline_line(x: np.ndarray, fs: float, fd: float) -> np.ndarray:
    """Offset + drift line under an oscillation, from the midpoints of consecutive extremes.

    (v[i-1] + 2 v[i] + v[i+1]) / 4 cancels the oscillation to second order in the decay per half
    cycle, so a line through these points is the baseline, not the decay's own mean.
    """
    tk, vk = extremes(x, fs, fd)
    t = np.arange(x.size) / fs
    if tk.size < 5:
        return np.polyval(np.polyfit(t, x, 1), t)
    m = 0.25 * (vk[:-2] + 2 * vk[1:-1] + vk[2:])
    return np.polyval(np.polyfit(tk[1:-1], m, 1), t)


def extremes(x: np.ndarray, fs: float, fd: float) -> tuple[np.ndarray, np.ndarray]:
    """Times (s) and values of the half-cycle extremes of an oscillation at about ``fd`` Hz.

    Extremes are searched between zero crossings of the signal less its one-period moving
    average (with hysteresis against noise-born crossings) and refined by a least-squares
    parabola over +-0.1 period. Vectorised: the only loop runs once per kept half cycle.
    """
    per = fs / fd
    if not np.isfinite(per) or per > x.size / 3 or per < 2:
        return np.empty(0), np.empty(0)
    base = uniform_filter1d(x, size=max(3, int(round(per))), mode="nearest")
    y = x - base
    h = max(1, int(round(0.1 * per)))
    zc = np.flatnonzero(np.diff(np.signbit(y)))
    if zc.size < 3:
        return np.empty(0), np.empty(0)
    # hysteresis: a crossing counts only 0.3 period after the last one kept (noise-born crossings
    # near zero are skipped by a binary search, not visited one by one)
    gap = 0.3 * per
    zf = zc.astype(float)  # searched with a float key: no cast of the whole array per search
    keep = [zf[0]]
    while True:
        j = int(zf.searchsorted(keep[-1] + gap))
        if j >= zf.size:
            break
        keep.append(zf[j])
    zc = np.asarray(keep, dtype=np.int64)
    if zc.size < 2:
        return np.empty(0), np.empty(0)
    # the largest |y| between consecutive kept crossings: a segment-wise argmax, done a block of
    # segments at a time so the index arrays stay small
    ay = np.abs(y)
    i = np.concatenate([_segment_argmax(ay, zc[j0:j0 + 4097] + 1) for j0 in range(0, zc.size - 1, 4096)])
    i = i[(i - h >= 0) & (i + h < y.size)]
    if i.size == 0:
        return np.empty(0), np.empty(0)
    u = np.arange(-h, h + 1, dtype=float)
    pinv = np.linalg.pinv(np.vstack([np.ones_like(u), u, u * u]).T)
    c0, c1, c2 = pinv @ x[i[None, :] + np.arange(-h, h + 1)[:, None]]
    with np.errstate(divide="ignore", invalid="ignore"):
        du = -c1 / (2 * c2)
        v = c0 - c1 * c1 / (4 * c2)
    ok = (c2 != 0) & (np.abs(du) <= h)
    return (i[ok] + du[ok]) / fs, v[ok]


def _segment_argmax(v: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Index of the (first) largest v in each [edges[j], edges[j+1]); the segments are contiguous
    and non-empty. Linear: a reduceat for the maxima, one comparison pass for their places."""
    a0, b1 = int(edges[0]), int(edges[-1])
    lens = np.diff(edges)
    seg_max = np.maximum.reduceat(v[a0:b1], edges[:-1] - a0)
    hit = np.flatnonzero(v[a0:b1] == np.repeat(seg_max, lens))
    seg = np.searchsorted(edges[1:] - a0, hit, side="right")
    first = np.r_[True, seg[1:] != seg[:-1]]
    return hit[first] + a0


def cycle_peaks(x: np.ndarray, fs: float, fd: float) -> tuple[np.ndarray, np.ndarray]:
    """Half-cycle amplitudes of an oscillation at about ``fd`` Hz: (times in s, amplitudes).

    Three consecutive extremes (peak, trough, peak or the reverse) half a period apart give
    |(v[i-1] + v[i+1]) / 2 - v[i]| / 2 at the middle one: offset and linear drift cancel exactly,
    and the constant factors from the parabola and the decay within the triple drop out of any
    log-slope.
    """
    tk, vk = extremes(x, fs, fd)
    if tk.size < 3:
        return np.empty(0), np.empty(0)
    per = fs / fd
    amp = 0.5 * np.abs(0.5 * (vk[:-2] + vk[2:]) - vk[1:-1])
    half = np.diff(tk) * fs
    even = np.abs(half[1:] - half[:-1]) < 0.1 * per  # evenly spaced: no missed extreme inside
    alt = np.sign(vk[1:-1] - vk[:-2]) != np.sign(vk[2:] - vk[1:-1])
    ok = even & alt
    return tk[1:-1][ok], amp[ok]


def spectral_peak(x: np.ndarray, fs: float, band=None) -> float:
    """Frequency of the strongest spectral line, optionally inside a band (a start value).

    No taper: a decay is its own window, and a Hann taper would hide a decay that is over in
    the first part of the record. The line is found on the unpadded spectrum, then located by a
    log-parabola through the DTFT sampled at a quarter bin around it (what a 4x zero-padded FFT
    gives, without its memory).
    """
    n = x.size
    y = detrend_linear(x)  # offset and drift out
    nfft = int(2 ** np.ceil(np.log2(max(4 * n, 1024))))
    f_lo = 2 * fs / n  # at least two cycles in the record
    lo, hi = (f_lo, fs / 2) if band is None else (max(band[0], f_lo), band[1])
    if lo > hi:
        lo, hi = 1e-300, fs / 2
    m = n if n >= 256 else 256
    X = np.abs(np.fft.rfft(y, m))
    f = np.fft.rfftfreq(m, 1 / fs)
    sel = (f >= lo) & (f <= hi)
    if not sel.any():
        sel = f > 0
    # the five strongest coarse maxima are refined: two lines of nearly equal height may swap
    # order between the coarse and the fine grid
    idx = np.flatnonzero(sel)
    Xs = X[idx]
    loc = np.flatnonzero(np.r_[True, Xs[1:] >= Xs[:-1]] & np.r_[Xs[:-1] >= Xs[1:], True])
    cand = idx[loc[np.argsort(-Xs[loc])[:5]]]
    # a line between two bins reads at most 3.92 dB (x 1.57) low on the unpadded grid (rectangular
    # window): a candidate below the strongest by more than that cannot win the refinement
    cand = cand[X[cand] >= X[cand[0]] / 1.6]
    best = (-1.0, 0.0)
    for kc in cand:
        best = max(best, _refine_peak(y, fs, float(f[kc]), m, nfft, lo, hi))
    return best[1]


def _refine_peak(y, fs, f0, m, nfft, lo, hi) -> tuple[float, float]:
    """(height, frequency) of the line near f0 on the quarter-bin grid of the padded FFT.

    The grid window follows the maximum when it sits on the window's edge (noise can move a broad
    peak's top away from the coarse maximum).
    """
    gmax = nfft // 2
    g_lo, g_hi = int(np.ceil(lo * nfft / fs)), int(np.floor(hi * nfft / fs))
    if g_lo > g_hi:
        g_lo, g_hi = 0, gmax
    c = f0 * nfft / fs
    half = 1.5 * nfft / m
    for _ in range(8):
        g = np.arange(max(np.floor(c - half), g_lo, 0), min(np.ceil(c + half), g_hi, gmax) + 1)
        D = np.abs(_dtft(y, g / nfft))
        j = int(np.argmax(D))
        if (j == 0 and g[0] > max(g_lo, 0)) or (j == D.size - 1 and g[-1] < min(g_hi, gmax)):
            c = g[j]
            continue
        break
    if 0 < j < D.size - 1:
        a, b, cc = np.log(D[j - 1:j + 2] + 1e-300)
        d = 0.5 * (a - cc) / (a - 2 * b + cc) if (a - 2 * b + cc) != 0 else 0.0
        return float(D[j]), float((g[j] + d) * fs / nfft)
    return float(D[j]), float(g[j] * fs / nfft)


def _dtft(y: np.ndarray, nu: np.ndarray, chunk: int = 1 << 14) -> np.ndarray:
    """sum_k y[k] exp(-2 pi i nu k) at a few normalised frequencies ``nu``, in bounded memory.

    One kernel exp(-2 pi i nu j), j < chunk, serves every chunk through its start phase.
    """
    # the kernel as an outer product of two short ones (j = 128 j1 + j2): 256 exponentials per
    # frequency instead of one per sample
    B = 128
    chunk = B * max(1, min(chunk, y.size + B - 1) // B)
    hi = np.exp(-2j * np.pi * np.outer(nu, B * np.arange(chunk // B)))
    lo = np.exp(-2j * np.pi * np.outer(nu, np.arange(B)))
    E = (hi[:, :, None] * lo[:, None, :]).reshape(nu.size, chunk)
    out = np.zeros(nu.size, complex)
    for s0 in range(0, y.size, chunk):
        seg = y[s0:s0 + chunk]
        out += np.exp(-2j * np.pi * nu * s0) * (E[:, :seg.size] @ seg)
    return out


DECIMATE_MIN_SAMPLES = 20_000   # shorter decays cost little at their own rate
DECIMATE_FS_OVER_F = 20.0       # the decimated rate: 20 samples per cycle of the highest line (Nyquist at 10 x it)


def decimation_factor(x: np.ndarray, fs: float, band=None) -> tuple[int, float]:
    """(q, f_top): the decimation a decay sampled far above its content allows, and its highest line.

    The highest line is the highest line of the Hann periodogram of the whole record above the level
    that white noise passes with a 1 % chance over all lines. The periodic Hann window is the
    three-line convolution 0.5 X[k] - 0.25 X[k-1] - 0.25 X[k+1] of the transform: the sidelobes of a
    strong line (and of the decay's abrupt start and end) then fall as 1/f^6, not 1/f^2, and do not
    pass for content far from it. Lines below two cycles in the record, where the mean would show,
    are not searched. The decimated rate keeps 20 samples per cycle of that line (or of the band's top),
    so everything up to ten times its frequency stays; q = 1 for records under DECIMATE_MIN_SAMPLES."""
    import scipy.fft as _fft
    if x.size < DECIMATE_MIN_SAMPLES:
        return 1, 0.0
    X = _fft.rfft(x)
    P = np.abs(0.5 * X[1:-1] - 0.25 * (X[:-2] + X[2:])) ** 2
    f = np.arange(1, P.size + 1) * fs / x.size
    level = np.median(P[1:]) / np.log(2) * np.log(P.size / 0.01)
    strong = f[(P > level) & (f > 2 * fs / x.size)]
    f_top = max(float(strong.max()) if strong.size else 0.0, band[1] if band else 0.0)
    if f_top <= 0:
        return 1, 0.0
    return max(1, int(fs / (DECIMATE_FS_OVER_F * f_top))), f_top


def _hp_nfft(n: int) -> int:
    """FFT length for the half-power spectrum: 16x padding, within 2^25 lines (768 MiB of spectrum)
    for long records."""
    return int(2 ** np.ceil(np.log2(min(16 * n, max(1 << 25, n)))))

def _halfpower_points(x, fs, band, *, details: bool = False):
    """Interpolated half-power frequencies of the strongest peak of a decay's spectrum (16x padded);
    with ``details`` (the noise's mean power taken off every line first) also the phase of the decay
    at its start (from the complex peak) and the standard deviations of f1 + f2 and of f2 - f1 from
    the noise in the lines."""
    n = x.size
    y = x - np.median(x[-max(8, n // 20):])
    nfft = _hp_nfft(n)
    X = np.fft.rfft(y, nfft)
    # white noise of std s puts n s^2 into every line's |X|^2 on average (padding adds none): taken off,
    # so the floor does not lift the half-power level
    var_line = n * noise_std(y, fs) ** 2 if details else 0.0
    P = np.maximum(np.abs(X) ** 2 - var_line, 0.0)
    f = np.fft.rfftfreq(nfft, 1 / fs)
    sel = np.ones_like(f, bool) if band is None else (f >= band[0]) & (f <= band[1])
    sel[0] = False
    idx = np.flatnonzero(sel)
    k = idx[int(np.argmax(P[sel]))]
    if band is not None and k in (idx[0], idx[-1]):
        raise FitError(f"half_power: the strongest line in band={band} sits on its edge ({f[k]:.4g} Hz): no peak "
                       "inside the band")
    f1, f2, lo, hi = half_power_crossings(f, P, k, lower_msg="a half-power point lies outside the spectrum "
                                          "(damping too high or the peak at the band edge)")
    if not details:
        return f1, f2
    sigma, wd = np.pi * (f2 - f1), np.pi * (f1 + f2)
    phase = float(np.angle(X[k]) + np.arctan2(2 * np.pi * f[k] - wd, sigma))
    # at a crossing P = |S + N|^2 moves by about sqrt(2 P n s^2), and the half level with the peak's
    # own noise: both crossings move apart or together by that over their slopes dP/df
    slopes = [abs(P[j + 1] - P[j]) / (f[j + 1] - f[j]) for j in (lo, hi - 1)]
    if min(slopes) <= 0:
        return f1, f2, phase, (np.inf, np.inf)
    sd_cross = [float(np.sqrt(2 * P[k] / 2 * var_line)) / sl for sl in slopes]
    sd_level = float(np.sqrt(2 * P[k] * var_line)) / 2 * (1 / slopes[0] + 1 / slopes[1])
    stds = (float(np.hypot(sd_cross[0], sd_cross[1])), float(np.hypot(np.hypot(*sd_cross), sd_level)))
    return f1, f2, phase, stds

def half_power_crossings(freq, P, k, *, lower_msg: str):
    """Frequencies where the power P falls to half its value at line k on either side, linearly
    interpolated between lines; FitError when a crossing lies outside the data."""
    half = P[k] / 2
    lo = k
    while lo > 0 and P[lo] > half:
        lo -= 1
    hi = k
    while hi < P.size - 1 and P[hi] > half:
        hi += 1
    if P[lo] > half or freq[lo] <= 0:
        raise FitError(f"half_power: {lower_msg}")
    if P[hi] > half:
        raise FitError("half_power: the upper half-power point lies beyond the data")
    f1 = freq[lo] + (half - P[lo]) * (freq[lo + 1] - freq[lo]) / (P[lo + 1] - P[lo])
    f2 = freq[hi - 1] + (half - P[hi - 1]) * (freq[hi] - freq[hi - 1]) / (P[hi] - P[hi - 1])
    return float(f1), float(f2), lo, hi


ALIVE_DB = 20.0   # a component is alive while its band holds this much more power than the noise would


def alive_until(x: np.ndarray, fs: float, f0: float, sig: float, noise: float) -> int:
    """Samples of ``x`` up to the end of the last half-overlapping block in which the component at
    ``f0`` (decay rate ``sig``) still stands ALIVE_DB over white noise of std ``noise`` in its band
    (+-max(3 decay rates, 5 % of f0)); blocks hold at least 4 cycles and resolve the band. An
    exponential extrapolation of the start's decay rate cuts a decay whose damping falls with its
    amplitude (a real beam: zeta 0.9 % at the start, 0.25 % after 12 s) long before it sinks."""
    bw = max(3 * sig / (2 * np.pi), 0.05 * f0)
    nper = int(min(x.size, 2 ** np.ceil(np.log2(max(4 * fs / f0, fs / bw, 16)))))
    if nper < 16 or not noise > 0:
        return 0
    w = np.hanning(nper)
    f = np.fft.rfftfreq(nper, 1 / fs)
    sel = np.abs(f - f0) <= bw
    sel[int(np.argmin(np.abs(f - f0)))] = True
    p_noise = sel.sum() * noise ** 2 * float(np.sum(w ** 2))
    starts = np.arange(0, x.size - nper + 1, max(nper // 2, 1))
    if not starts.size:
        return 0
    seg = x[starts[:, None] + np.arange(nper)]
    seg = seg - seg.mean(axis=1, keepdims=True)
    p = np.sum(np.abs(np.fft.rfft(seg * w, axis=1)[:, sel]) ** 2, axis=1)
    live = np.flatnonzero(p > 10 ** (ALIVE_DB / 10) * p_noise)
    return int(starts[live[-1]] + nper) if live.size else 0
