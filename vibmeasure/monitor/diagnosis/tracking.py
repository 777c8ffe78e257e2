"""Speed that varies: the speed measured by a tachometer or a profile, or followed along a drifting 1X,
and the record resampled at equal steps of shaft angle (order tracking)."""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from ...core.errors import ParameterError
from ...signal.spectral import fast_len_below
from .lines import LINE_DB, _refine

if TYPE_CHECKING:   # for annotations only
    from .job import Job


def _speed_from_1x(rec, job: Job, speed: dict, band):
    """When the 1X drifts along a curve: that curve as the speed profile, the job order-tracked with
    it, and the speed dict updated (source "1X line"); None when the curve is not a usable profile
    (it leaves the range the 1X was seen in by more than half, or a band in Hz was fixed)."""
    coef = speed.pop("_curve", None)
    if coef is None or band is not None:
        return None
    t = np.arange(job.a.size) / job.fs
    prof = 60.0 * np.polyval(coef, t)
    lo, hi = speed["drift_hz"]
    if not (prof.min() > 30.0 * lo and prof.max() < 90.0 * hi):
        return None
    est = _measured_speed(rec, None, prof, 1)
    est["source"] = "1X line"
    tracked, _ = _order_tracked_job(job, est, None)
    if "order_tracked" not in tracked.flags:
        return None
    note = (f"the 1X line moves between {lo:.2f} and {hi:.2f} Hz over the record: the speed was estimated from "
            f"it (a quadratic in time, {est['min_rpm']:.0f}-{est['max_rpm']:.0f} rpm) and the shaft orders and "
            f"bearing lines analysed after angular resampling; frequencies are orders x the mean speed "
            f"{est['mean_rpm'] / 60:.2f} Hz. A tachometer (tach=) measures the speed instead of estimating it")
    speed.update(estimated_rpm=est["mean_rpm"], min_rpm=est["min_rpm"], max_rpm=est["max_rpm"], source="1X line",
                 note=note)
    return tracked


SPEED_DRIFT = 0.02   # the 1X line may wander this much (share of its mean) before the speed is said to vary
DRIFT_P = 1e-3       # ... along a curve that a constant speed would follow by chance less often than this
# Measured with _speed_drift: on the 146 channels of the 57 development records (constant speed) where
# the 1X stands in enough parts, the curve spans at most 0.72 % and none is flagged (the 8 MFPT
# channels' 1X is too weak to track; Normal_0's wrong declared fs is flagged before this is looked
# at). On 284 constant-speed synthetic machines (benchmarks/diagnosis.py, SNR -10 to 10 dB) none is
# flagged: the widest curve, 2.32 %, has p = 0.29. The spread of the parts alone flagged 3 of them.
# Over 892 channel pieces of the development set (whole records, their first 4 s, their quarters),
# the curve and its test pass on 2 (the first 4 s of two fan-end records, where sidebands beside the
# 1X pull the parts' estimates); the whole record's 1X is sharp there, and _smeared rejects both.


def _speed_drift(a, fs, f1, n_seg=8):
    """(lowest, highest, spread, p, curve) of the 1X line's frequency over n_seg parts of the record, from
    the parts where it stands LINE_DB above its floor (at least 6 of them; else None). lowest and
    highest are those of a quadratic in time fitted to the parts' 1X (a run-up, a run-down, or both),
    spread their difference over the mean; p is the F-test's probability that a constant speed
    scatters as far from a constant as it does from the curve: a marginal 1X wanders from part to part
    by noise alone, a speed that changes follows the curve. curve: the quadratic's coefficients for
    the 1X in Hz against time in seconds (np.polyval)."""
    n_seg = min(n_seg, int(a.size / fs * f1 / 8))     # each part spans 8 revolutions or more
    if n_seg < 4:
        return None
    L = a.size // n_seg
    w = np.hanning(L)
    f = np.fft.rfftfreq(L, 1 / fs)
    sel = np.flatnonzero((f > 0.75 * f1) & (f < 1.25 * f1))
    if sel.size < 3 or sel[0] < 1:
        return None
    A = np.abs(np.fft.rfft(a[: n_seg * L].reshape(n_seg, L) * w, axis=1))
    found, when = [], []
    for j, row in enumerate(A):   # when: the part's middle, in parts
        k = sel[np.argmax(row[sel])]
        ring = (np.abs(f - f[k]) < max(0.25 * f1, 12 * f[1])) & (np.abs(f - f[k]) > 3 * f[1])
        if ring.sum() < 5 or 20 * np.log10(row[k] / max(np.median(row[ring]), 1e-300)) < LINE_DB:
            continue
        found.append(_refine(f, row, f[k]))
        when.append(j + 0.5)
    if len(found) < 6:
        return None
    from scipy.special import fdtrc
    found, when = np.asarray(found), np.asarray(when)
    coef = np.polyfit(when, found, 2)
    curve = np.polyval(coef, np.linspace(when[0], when[-1], 50))
    mean = float(found.mean())
    rss2 = float(np.sum((found - np.polyval(coef, when)) ** 2))
    rss0 = float(np.sum((found - mean) ** 2))
    dof = found.size - 3
    F = (rss0 - rss2) / 2 / max(rss2 / dof, 1e-30 * mean ** 2)
    # the same curve with time in seconds (a part lasts L / fs)
    coef_s = coef * np.array([(fs / L) ** 2, fs / L, 1.0])
    return (float(curve.min()), float(curve.max()), float(curve.max() - curve.min()) / mean, float(fdtrc(2, dof, F)),
            coef_s)


VARYING_SPEED = 0.002   # above this spread of the mean speeds of the record's parts, the analysis runs in orders


def _measured_speed(rec, tach, rpm_profile, pulses_per_rev) -> dict:
    """Shaft angle (revolutions) per sample from a tachometer or an rpm profile, and the speed's range
    over whole revolutions."""
    from ...signal.demod import shaft_angle
    if isinstance(pulses_per_rev, bool) or not isinstance(pulses_per_rev, (int, np.integer)) or pulses_per_rev < 1:
        raise ParameterError(f"pulses_per_rev={pulses_per_rev!r} must be a whole number >= 1")
    if tach is not None and rpm_profile is not None:
        raise ParameterError("give tach or rpm_profile, not both")
    if tach is not None and not isinstance(tach, (str, int, np.integer)):
        tach = np.asarray(tach, float)
        if tach.ndim != 1 or not np.isfinite(tach).all():
            raise ParameterError("tach must be a channel name or index, or one finite sample per record sample")
    ang = shaft_angle(rec, tach=tach, rpm_profile=rpm_profile, pulses_per_rev=pulses_per_rev)
    ok = np.flatnonzero(np.isfinite(ang))
    t = np.arange(rec.n_samples) / rec.fs
    revs = np.arange(np.ceil(ang[ok[0]]), np.floor(ang[ok[-1]]) + 1)
    if revs.size < 21:
        raise ParameterError(f"the speed information covers {max(revs.size - 1, 0)} whole revolutions; at least 20 "
                             "are needed")
    t_rev = np.interp(revs, ang[ok], t[ok])
    # per revolution, averaged over 5: a square pulse is timed to +-half a sample, +-0.25 % of a
    # revolution of 400 samples, and that jitter is no change of speed
    per_rev = np.convolve(60.0 / np.diff(t_rev), np.ones(5) / 5, mode="valid")
    # whether the speed varies: mean speed over up to 8 parts of 8 or more revolutions each
    n_p = int(min(8, (revs.size - 1) // 8))
    edges = np.linspace(0, revs.size - 1, n_p + 1).round().astype(int)
    parts = 60.0 * np.diff(revs[edges]) / np.diff(t_rev[edges])
    mean = 60.0 * float((ang[ok[-1]] - ang[ok[0]]) / (t[ok[-1]] - t[ok[0]]))
    return {"angle": ang, "mean_rpm": mean,
            "min_rpm": float(per_rev.min()), "max_rpm": float(per_rev.max()),
            "spread": float(parts.max() - parts.min()) / mean,
            "source": "tachometer" if tach is not None else "rpm profile"}


def _order_tracked_job(job: Job, tracked: dict, band):
    """The job with every channel resampled at equal steps of shaft angle when the speed varies: its
    'fs' is the angular rate at the mean speed (samples per revolution x mean revolutions per second),
    so every Hz below is an order x the mean speed. A constant speed keeps the record as measured."""
    f_mean = tracked["mean_rpm"] / 60.0
    if tracked["spread"] <= VARYING_SPEED:
        return replace(job, rpm=tracked["mean_rpm"]), ""
    if band is not None:
        raise ParameterError("band= is in Hz, but this record's speed varies and the bands are searched in orders "
                             "after angular resampling: leave band unset")
    from ...signal.demod import angle_grid, at_times
    spr = job.fs / (tracked["min_rpm"] / 60.0)          # the slowest speed's whole band is kept
    _, t_grid = angle_grid(tracked["angle"], job.fs, spr)
    t_grid = t_grid[:fast_len_below(t_grid.size)]   # a length with small prime factors: the FFTs stay fast
    signals = {k: at_times(x, job.fs, t_grid) for k, x in job.signals.items()}
    note = (f"speed {tracked['min_rpm']:.0f}-{tracked['max_rpm']:.0f} rpm (from the {tracked['source']}): shaft "
            f"orders and bearing lines analysed after angular resampling; frequencies are orders x the mean "
            f"speed {f_mean:.2f} Hz")
    out = replace(job, fs=spr * f_mean, rpm=tracked["mean_rpm"], signals=signals, a=signals[job.primary],
                  flags=job.flags + ["order_tracked"])
    return out, note
