"""Shared pieces of the free-decay methods: noise level, clipping, decay start, cycle peaks."""

from __future__ import annotations

import numpy as np
from scipy import signal as _sig
from scipy.ndimage import uniform_filter1d

from ..core.record import Record

CLIP_RUN = 3  # consecutive samples at the extreme that count as clipping


def clipped_mask(x: np.ndarray) -> np.ndarray:
    """True where a run of CLIP_RUN or more consecutive samples sits at the record's max or min."""
    mask = np.zeros(x.size, bool)
    tol = 1e-12 * max(np.ptp(x), np.finfo(float).tiny)
    med = np.median(x)
    reach = np.max(np.abs(x - med))
    for ext in (x.max(), x.min()):
        if abs(ext - med) < 0.5 * reach:  # a plateau near the resting value is not clipping
            continue
        at = np.abs(x - ext) <= tol
        if at.sum() < CLIP_RUN:
            continue
        d = np.diff(np.concatenate(([0], at.view(np.int8), [0])))
        starts, ends = np.flatnonzero(d == 1), np.flatnonzero(d == -1)
        for s, e in zip(starts, ends):
            if e - s >= CLIP_RUN:
                mask[s:e] = True
    return mask


def noise_std(x: np.ndarray, fs: float) -> float:
    """Broadband noise std from the median level of a Welch PSD (robust to sparse spectral lines)."""
    n = x.size
    nper = int(min(n, max(64, 2 ** int(np.log2(max(n // 16, 64))))))
    nper = min(nper, 4096)
    f, p = _sig.welch(x, fs=fs, nperseg=nper, detrend="linear")
    p = p[1:-1] if p.size > 4 else p
    segs = max(1, 2 * n // nper - 1)
    # median of an average of K chi^2_2 variables: mean * (1 - 2/(9K))^3 (Wilson-Hilferty)
    k = segs
    med_to_mean = (1 - 2 / (9 * k)) ** 3 if k > 1 else np.log(2)
    level = np.median(p) / med_to_mean
    welch_std = float(np.sqrt(level * fs / 2))
    # a record that has decayed ends in noise alone: its last tenth, detrended, is the noise
    tail = x[-max(16, n // 10):]
    k = np.arange(tail.size)
    tail_std = float(np.std(tail - np.polyval(np.polyfit(k, tail, 1), k)))
    return min(welch_std, tail_std)


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
    parabola over +-0.1 period.
    """
    per = fs / fd
    if not np.isfinite(per) or per > x.size / 3 or per < 2:
        return np.empty(0), np.empty(0)
    base = uniform_filter1d(x, size=max(3, int(round(per))), mode="nearest")
    y = x - base
    h = max(1, int(round(0.1 * per)))
    zc = np.flatnonzero(np.diff(np.sign(y)) != 0)
    if zc.size < 3:
        return np.empty(0), np.empty(0)
    keep = [zc[0]]
    for z in zc[1:]:
        if z - keep[-1] >= 0.3 * per:
            keep.append(z)
    zc = np.asarray(keep)
    u = np.arange(-h, h + 1, dtype=float)
    pinv = np.linalg.pinv(np.vstack([np.ones_like(u), u, u * u]).T)
    tk, vk = [], []
    for a, b in zip(zc[:-1], zc[1:]):
        seg = y[a + 1:b + 1]
        if seg.size == 0:
            continue
        i = a + 1 + int(np.argmax(np.abs(seg)))
        if i - h < 0 or i + h >= y.size:
            continue
        c0, c1, c2 = pinv @ x[i - h:i + h + 1]
        if c2 == 0:
            continue
        du = -c1 / (2 * c2)
        if abs(du) > h:
            continue
        tk.append((i + du) / fs)
        vk.append(c0 - c1 * c1 / (4 * c2))
    return np.asarray(tk), np.asarray(vk)


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
    the first part of the record.
    """
    n = x.size
    nfft = int(2 ** np.ceil(np.log2(max(4 * n, 1024))))
    k = np.arange(n)
    X = np.abs(np.fft.rfft(x - np.polyval(np.polyfit(k, x, 1), k), nfft))  # offset and drift out
    f = np.fft.rfftfreq(nfft, 1 / fs)
    sel = np.ones_like(f, bool) if band is None else (f >= band[0]) & (f <= band[1])
    sel &= f >= 2 * fs / n  # at least two cycles in the record
    if not sel.any():
        sel = f > 0
    k = np.flatnonzero(sel)[np.argmax(X[sel])]
    if 0 < k < X.size - 1:
        a, b, c = np.log(X[k - 1:k + 2] + 1e-300)
        d = 0.5 * (a - c) / (a - 2 * b + c) if (a - 2 * b + c) != 0 else 0.0
        return float((k + d) * fs / nfft)
    return float(f[k])
