"""Damage a recording chain leaves in the samples: isolated spikes, flat runs (dropouts), clipping, and
transients (bursts, settling) that are no steady running.

A converter's buffer boundary, a loose connector or a switching transient can put single samples far
from their neighbours. No accelerometer behind an anti-alias filter makes such a sample: a structure's
response and the sensor's rings over several samples, so a real impact moves its neighbours too. The
envelope analysis cannot tell them apart: a spike is broadband, the kurtogram picks it as the most
impulsive band, and spikes at a fixed interval make a comb in the envelope spectrum (every 1024
samples at 12 kHz is 11.72 Hz, within 2 % of the 6205's cage frequency, whose 9th harmonic is BPFO).
Measured on the 53 development fault records (``benchmarks/diagnosis_robustness.py``): 30 x the RMS
every 1024 samples give 7 wrong calls unrepaired, five random ones a second leave 5 of 39 right answers.

``isolated_spikes`` finds them: a sample whose departure from the running median of 7 (the residual)
is ``SPIKE_SIGMA`` times the residual's robust spread (MAD), ``SPIKE_LEVEL`` times the record's own,
``SPIKE_ISOLATION`` times either neighbour's and the largest residual of the ``SPIKE_CONTEXT`` samples
on each side (other comparable far-out samples there excepted, unless there are two or more: a burst).
Two adjacent ones whose flanks are both that much lower are a two-sample glitch. Once any is found,
an AR model of the record looks again (``_ar_spikes``) for the ones a fault's impact hides from the
median's residual. Spikes on one grid of a fixed interval (``spike_grid``) are completed along it. On
every channel of the 57 development recordings (CWRU 12 kHz, MFPT 48.8 kHz, faulty bearings' impacts
included) none is found even at 8 sigma and 3 x (a first false find at 6 sigma and 3 x). Of 500 random
spikes of 30 x the RMS (alternating sign) in every 10 s of every channel of the 53 fault records, 27 of
69,351 are missed, 191 without the AR model's second look.

``fill`` replaces lost samples by their least-squares AR interpolation (``despike`` and ``vm.diagnose``
fill the spikes found, ``vm.diagnose`` the dropouts too): a neighbours' mean misses these records'
samples by more than their RMS, and whitening lifts 500 such repairs in 10 s over the bearing's band
(the spikes' true places given, 16 of 39 right answers stay right with it, 39 with the AR fill).
``flat_runs`` (dropouts) and ``clipped_share`` (saturation) measure; saturation is flagged, not filled
(a fill made CWRU B021_3 clipped at 3 x the RMS a wrong call).
"""

from __future__ import annotations

import numpy as np

from ..core._validate import as_record
from ..core.errors import ParameterError, warn_quality
from ..core.record import Record
from .whiten import _whitened_or, whitened

__all__ = ["despike", "isolated_spikes", "fill", "flat_runs", "clipped_share", "transients", "isolated_events",
           "gate", "spike_grid", "whitened"]

SPIKE_SIGMA = 10.0      # residual of a spike over the residual's robust spread (1.4826 MAD)
SPIKE_ISOLATION = 4.0   # ... and over every other residual within SPIKE_CONTEXT samples
SPIKE_CONTEXT = 16
SPIKE_LEVEL = 3.0       # ... and this many times the record's own robust spread (1.4826 MAD of the samples)
SPIKE_PASSES = 3        # passes, each on the record with the spikes found before repaired
GRID_MIN = 5            # spikes on one grid of a fixed interval: at least this many ...
GRID_SHARE = 0.8        # ... with this share of the intervals between them whole multiples of it
GRID_SIGMA = 3.0        # on such a grid, a residual this far out (robust sigmas) is a spike too
CLIP_MIN = 5            # saturation: this many samples exactly at the record's maximum or minimum
FLAT_RUN = 8            # a dropout: this many equal samples or more in a row (and at least 0.5 ms) ...
FLAT_SECONDS = 5e-4


def _samples(x, name: str = "x") -> np.ndarray:
    """One channel's samples as float64: a 1-D, finite array, else a ParameterError naming ``name``."""
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be an array of numbers (one channel's samples)") from None
    if a.ndim != 1:
        raise ParameterError(f"{name} must be one channel's samples (1-D), got shape {a.shape}")
    if not np.isfinite(a).all():
        i = int(np.argmax(~np.isfinite(a)))
        raise ParameterError(f"{name} has NaN/inf samples (first at index {i}); the rule is finite data")
    return a


def _thresholds(sigma, isolation) -> None:
    for name, v, least in (("sigma", sigma, 3.0), ("isolation", isolation, 1.5)):
        if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)) \
                or not np.isfinite(v) or v < least:
            raise ParameterError(f"{name}={v!r} must be a number >= {least:g}: lower, ordinary samples of a "
                                 "vibration record would be taken for spikes")


def _residual(x: np.ndarray) -> tuple[np.ndarray, float]:
    from scipy.ndimage import median_filter
    r = x - median_filter(x, size=7, mode="reflect")
    s = 1.4826 * float(np.median(np.abs(r)))   # the residual's median is 0 by construction (to a sample)
    # over half the residuals 0 (a flat or coarsely quantised record): their mean size instead
    return r, s if s > 0.0 else (float(np.mean(np.abs(r))) or 1.0)


def isolated_spikes(x, *, sigma: float = SPIKE_SIGMA, isolation: float = SPIKE_ISOLATION) -> np.ndarray:
    """Indices of the single samples that stand far from both neighbours and from every sample near
    them (see the module's docstring); an empty array when there are none, or when the record is
    shorter than 2 x SPIKE_CONTEXT + 1 samples (too little around a sample to judge it)."""
    x = _samples(x)
    _thresholds(sigma, isolation)
    if x.size < 2 * SPIKE_CONTEXT + 1:
        return np.zeros(0, np.int64)
    # a spike among others near it can stand out only once they are repaired: 500 random spikes of
    # 30 x the RMS in 10 s on the 135 channels of the CWRU fan-end records, 98.3 % found in one pass,
    # 98.5 % in three
    found = np.zeros(0, np.int64)
    for _ in range(SPIKE_PASSES):
        new = _spikes_once(_repair(x, found) if found.size else x, sigma, isolation)
        new = np.setdiff1d(new, found)
        if not new.size:
            break
        found = np.union1d(found, new)
    if found.size and x.size >= 8 * FILL_ORDER:
        # the chain is seen to glitch: look again where the vibration hides a spike from the median's
        # residual (on a fault's impact ringing at 3 kHz of 12), with the AR model of the record
        found = np.union1d(found, _ar_spikes(fill(x, found), sigma))
    grid = spike_grid(found)
    if grid is None:
        return found
    # glitches at a fixed interval (a converter's buffer): every position of the grid whose residual
    # stands out at all (GRID_SIGMA) is one, also where the vibration around it hides it from the test
    n0, P = grid
    r, s = _residual(x)
    pos = np.arange(n0 % P, x.size, P)
    return np.union1d(found, pos[np.abs(r[pos]) > GRID_SIGMA * s]).astype(np.int64)


def _spikes_once(x: np.ndarray, sigma: float, isolation: float) -> np.ndarray:
    r, s = _residual(x)
    a = np.abs(r)
    # far out against the residual's spread, and against the record itself: on a smooth, oversampled
    # record (a slow ring-down) the residual's spread is tiny and a wiggle of 0.3 % of the RMS is no spike
    cand = np.flatnonzero(a > sigma * s)
    if cand.size:
        cand = cand[a[cand] > SPIKE_LEVEL * 1.4826 * float(np.median(np.abs(x - np.median(x))))]
    if cand.size == 0:
        return np.zeros(0, np.int64)
    # a candidate is a single sample when both its neighbours stand ``isolation`` times lower (on a
    # fault's impact a spike still does: 60-90 robust sigmas beside 15-25; requiring instead that no
    # neighbour be a candidate at all misses 1.7 % of random spikes on the CWRU fan-end channels, up to
    # 49 of 500 on one, all of them on impacts). Two single ones within SPIKE_CONTEXT samples do not hide each
    # other (two spikes close together), but three or more comparable ones (each within ``isolation``
    # of the sample judged) are a burst: an impact ringing near Nyquist, every other sample far out
    pad = np.concatenate(([0.0], a, [0.0]))
    single = cand[np.maximum(pad[cand], pad[cand + 2]) * isolation < a[cand]]
    # two adjacent ones (a glitch over two samples, a buffer's seam): both flanks lower as well
    j = cand[:-1][np.diff(cand) == 1]
    pair = j[np.maximum(pad[j], pad[j + 3]) * isolation < np.minimum(a[j], a[j + 1])]
    single = np.union1d(single, np.concatenate((pair, pair + 1)))
    if single.size == 0:
        return np.zeros(0, np.int64)
    is_single = np.zeros(x.size, bool)
    is_single[single] = True
    k = np.arange(1, SPIKE_CONTEXT + 1)
    near = np.clip(single[:, None] + np.concatenate((-k, k))[None, :], 0, x.size - 1)
    A, S = a[near], is_single[near]
    around = np.where(S, 0.0, A).max(axis=1)
    others = (S & (A * isolation >= a[single][:, None])).sum(axis=1)
    return single[(a[single] > isolation * around) & (others <= 1)].astype(np.int64)


def _prediction_filter(y: np.ndarray) -> np.ndarray | None:
    """The prediction-error filter [1, -a1, ..., -ap] of an AR(FILL_ORDER) model of y, or None when y
    does not vary (a constant record, zeros with a spike: the model is undetermined)."""
    from scipy.linalg import LinAlgError
    from .whiten import _ar_coefficients
    if not np.ptp(y) > 0:
        return None
    try:
        a = _ar_coefficients(y, FILL_ORDER)
    except (LinAlgError, ValueError):
        return None
    return np.concatenate(([1.0], -a)) if np.isfinite(a).all() else None


AR_SHARE = 0.9   # a spike explains this share of the AR prediction error over the FILL_ORDER + 1 samples it enters


def _ar_spikes(y: np.ndarray, sigma: float) -> np.ndarray:
    """Single samples of ``y`` (spikes found so far filled in) that an AR(FILL_ORDER) model of the
    record takes for a spike: the least-squares size of a one-sample error at n (the prediction
    errors e[n..n+p] weighted by the prediction-error filter c) stands ``sigma`` times its own spread
    under the model and SPIKE_LEVEL times the record's robust spread, and explains AR_SHARE of the
    error energy of those p + 1 samples. A vibration's impact is one large prediction error followed
    by its predictable ringing: a one-sample error explains 1 / sum(c^2) of it (sum(c^2) is 1.5-5 on
    the CWRU and MFPT channels). On every channel of the 57 development recordings no sample reaches 0.78 with
    sigma 8; the random spikes of 30 x the RMS the median's residual misses on impacts reach 0.98-1.0
    (two in adjacent samples do not: 0.3-0.8, and stay)."""
    from scipy.signal import oaconvolve
    p = FILL_ORDER
    c = _prediction_filter(y)
    if c is None:
        return np.zeros(0, np.int64)
    r0 = float(c @ c)
    e = oaconvolve(y - y.mean(), c)[: y.size]
    e[:p] = 0.0                                            # the filter's start-up
    g = oaconvolve(e, c[::-1])[p: p + y.size]              # sum_k c_k e[n + k]
    energy = oaconvolve(e ** 2, np.ones(p + 1))[p: p + y.size]
    spread = 1.4826 * float(np.median(np.abs(e))) or float(np.mean(np.abs(e))) or 1.0
    size = np.abs(g) / r0                                  # the one-sample error's size at n
    level = SPIKE_LEVEL * 1.4826 * float(np.median(np.abs(y - np.median(y))))
    hit = (np.abs(g) > sigma * spread * np.sqrt(r0)) & (size > level) \
        & (g ** 2 > AR_SHARE * r0 * np.maximum(energy, 1e-300))
    hit[:p] = hit[-p:] = False
    return np.flatnonzero(hit).astype(np.int64)


def spike_grid(found: np.ndarray):
    """(offset, period) when the spikes found sit on one grid of a fixed period (at least GRID_MIN of
    them and GRID_SHARE of the intervals between them whole multiples of the period); else None."""
    if found.size < GRID_MIN:
        return None
    d = np.diff(found)
    vals, counts = np.unique(d, return_counts=True)
    mode = int(vals[np.argmax(counts)])
    # the most common interval may skip spikes the test missed: the period is the divisor of it that
    # the most intervals are whole multiples of (of equals, the longest: half the period fits as well)
    best, share = None, 0.0
    for m in range(1, 9):
        P = mode // m
        if mode % m or P <= SPIKE_CONTEXT:
            continue
        on = float(np.mean(d % P == 0))
        if on >= GRID_SHARE and on > share + 1e-9:
            best, share = P, on
    if best is None:
        return None
    n0 = int(np.bincount(found % best).argmax())
    return (n0, best) if np.sum(found % best == n0) >= GRID_MIN else None


def _repair(x: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """x with the samples at idx replaced by the mean of their two neighbours (at an end, by its one)."""
    y = x.copy()
    left = np.where(idx > 0, idx - 1, idx + 1)
    right = np.where(idx < x.size - 1, idx + 1, idx - 1)
    y[idx] = 0.5 * (x[left] + x[right])
    return y


FILL_ORDER = 32         # AR model order for filling repaired samples in (``fill``)


def fill(x, idx) -> np.ndarray:
    """x with the samples at ``idx`` replaced by their least-squares AR interpolation (Janssen, Veldhuis
    and Vries, 1986, for one missing sample at a time): the values that make the prediction error of an
    AR(FILL_ORDER) model of the record smallest over every error they enter, found jointly for samples
    within FILL_ORDER of each other. The mean of the two neighbours misses a sample of a vibration
    record by more than its RMS (1.3-1.8 x on the CWRU fan-end records, whose energy lies at 2-4 kHz
    of 6 kHz): 500 such repairs in 10 s spread broadband noise that whitening lifts over the bearing's
    resonance band. The AR fill misses by 0.15-0.29 x the RMS there. Samples within FILL_ORDER of the
    record's ends keep the neighbours' mean; a record shorter than 8 x FILL_ORDER is filled that way."""
    from scipy.signal import oaconvolve
    from scipy.sparse import coo_matrix
    from scipy.sparse.linalg import spsolve
    x = _samples(x)
    raw = np.asarray(idx)
    if raw.size and raw.dtype.kind not in "iu":
        raise ParameterError(f"idx must be sample indices of x (integers), got {raw.dtype} values")
    if raw.size and (raw.min() < 0 or raw.max() >= x.size):
        raise ParameterError(f"idx must be sample indices of x (from 0 to {x.size - 1}; x has {x.size} "
                             f"samples), got values from {int(raw.min())} to {int(raw.max())}")
    idx = np.unique(raw.astype(np.int64).ravel())
    y = _repair(x, idx)
    p = FILL_ORDER
    inner = idx[(idx >= p) & (idx < x.size - p)]
    if inner.size == 0 or x.size < 8 * p:
        return y
    c = _prediction_filter(y)
    if c is None:       # a record without variation (constant around the lost samples): nothing to model
        return y
    m = float(y.mean())
    e = oaconvolve(y - m, c)[: x.size]                    # prediction error with the first repair
    g = oaconvolve(e, c[::-1])[p: p + x.size][inner]      # its gradient at each filled sample: sum_k c_k e[n + k]
    R = np.correlate(c, c, "full")[p:]                    # the Hessian's band: R[l] = sum_t c_t c_(t+l)
    rows, cols, vals = [np.arange(inner.size)], [np.arange(inner.size)], [np.full(inner.size, R[0])]
    for d in range(1, inner.size):
        lag = inner[d:] - inner[:-d]
        near = np.flatnonzero(lag <= p)
        if not near.size:
            break
        for a, b in ((near, near + d), (near + d, near)):
            rows.append(a)
            cols.append(b)
            vals.append(R[lag[near]])
    H = coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                   shape=(inner.size, inner.size)).tocsc()
    y[inner] -= np.atleast_1d(spsolve(H, g))
    return y


def flat_runs(x, fs: float) -> list[tuple[int, int]]:
    """(start, stop) of the runs of equal samples at least FLAT_RUN long and FLAT_SECONDS: a dropout (a
    converter or a link that held or zeroed its output). Clipping (runs at the record's extremes) is
    left to ``clipped_share``."""
    from ..core._validate import positive
    x = _samples(x)
    fs = positive(fs, "fs")
    if x.size < 2:
        return []
    same = np.concatenate(([False], x[1:] == x[:-1]))
    d = np.diff(np.concatenate(([0], same.view(np.int8), [0])))
    starts, ends = np.flatnonzero(d == 1) - 1, np.flatnonzero(d == -1)
    need = max(FLAT_RUN, int(np.ceil(FLAT_SECONDS * fs)))
    hi, lo = x.max(), x.min()
    return [(int(s), int(e)) for s, e in zip(starts, ends)
            if e - s >= need and x[s] != hi and x[s] != lo]


def clipped_share(x) -> float:
    """Share of the samples that sit exactly at the record's maximum or minimum, counted for an
    extreme that at least CLIP_MIN samples reach, more than twice as many as the next value inside it,
    and that lies far from the median (at least half the largest excursion): the sensor or the
    converter saturated. (A recorded value at its extreme
    occurs once; at 12 kHz a clipped excursion often lasts one or two samples, so runs are not asked.)"""
    x = _samples(x)
    if x.size == 0:
        return 0.0
    hi, lo = float(x.max()), float(x.min())
    at = {e: int(np.count_nonzero(x == e)) for e in (hi, lo)}
    if max(at.values()) < CLIP_MIN:
        return 0.0
    med = float(np.median(x))
    reach = max(hi - med, med - lo)

    def piled(e):
        """More samples at the extreme than twice at the next value inside it (to within rounding): a
        rail. A noise-free periodic signal repeats its extreme once a period and the values beside it as
        often or more (a sine with a whole number of samples per period: twice as often; without this
        test every such test sine reads as saturated), and the next code of a quantised signal that
        does not reach its rail is commoner than its top code."""
        inside = x[x < e] if e == hi else x[x > e]
        if inside.size == 0:
            return False
        nxt = inside.max() if e == hi else inside.min()
        return at[e] > 2 * int(np.count_nonzero(np.abs(inside - nxt) <= 1e-9 * reach))

    n = sum(k for e, k in at.items() if k >= CLIP_MIN and reach > 0 and abs(e - med) >= 0.5 * reach and piled(e))
    return n / x.size


# Transients: stretches that are not the machine's steady running. A knock, a touched cable or a passing
# load is a burst above the record's level; an ICP sensor's bias settling, or a step, moves the mean. The
# squared envelope's spectrum floor grows as the square of a stretch's power (a window at 3 x the others'
# RMS adds 81 x its share; a 0.2 s burst at 10 x the RMS in 10 s lifts it 23 dB): every bearing line sinks
# (the 39 right answers of 53 fell to 0, and to 7 at 3 x the RMS). A settling's low frequencies lift the
# ISO velocity, letting shaft-order patterns through (4 wrong "looseness" on the same records).
# ``vm.diagnose`` judges windows of two shaft revolutions. On the 57 development records (154 channels) steady
# windows reach 4.8 x the median window's RMS (fan-end ball faults: six channels have one to three such
# stretches, 1.3-6.2 % of the record, gated by the 3 x level; no answer changes), a window's mean 0.87 x (B007_1).
#
# A burst can bury the envelope spectrum without standing out in the RMS: an accelerometer's signal is
# loud in its structure's resonances and quiet elsewhere, and a broadband knock fills the quiet bands,
# which whitening lifts to full height. A 0.2 s burst at 2 x the RMS (about sqrt(5) = 2.2 x the record's
# RMS, under the level) stands, whitened, 5-12 x above the median window (two revolutions) on the drive-
# and fan-end channels of the CWRU fan-end records and 8-25 x on their base channels, and took 39 right
# answers of 53 to 14 (the inner race of IR007_0, p = 1e-180 as recorded, had p = 1).
# ``transients(..., whiten=True)`` judges the whitened signal by the RMS rule in windows of two cage
# turns: a rolling element's defect passes the load zone once a turn, and real ball-fault records are loud
# on that rhythm and slower (whitened two-revolution windows reach 4.7 x; gating them made fan-end
# OR007@12_1 a wrong inner-race call). In two-cage-turn windows only B007_1's drive- and fan-end channels
# pass 3 x (3.6, 3.1 x); no answer changes. ``vm.diagnose`` looks once the RMS rule's transients are gated
# (a loud burst's whitened tails would be taken too). Not found: a burst that fills every band (whitened,
# 0.3 x the RMS on a one-resonance signal with a 1 % floor), or one in a record whose structure rings in a
# broad band (MFPT: 2.6-3.4 x whitened at 2 x the RMS, a fifteenth of their 3 s).
TRANSIENT_LEVEL = 3.0    # a window's RMS (about its own mean) over the median window's
TRANSIENT_OFFSET = 2.0   # a window's mean off the median window mean, in median window RMS
TRANSIENT_SHARE = 0.25   # more than this share of the record beyond either is the machine's state, not a transient


def transients(x, block: int, *, whiten: bool = False, whitened_x: tuple | None = None) -> list[tuple[int, int]]:
    """(start, stop) of the stretches that are transients: a window of ``block`` samples (moved by half a
    block, so that a burst astride two blocks is seen whole) whose RMS about its own mean exceeds
    ``TRANSIENT_LEVEL`` x the median window's (a burst), or whose mean is off the median window mean by
    ``TRANSIENT_OFFSET`` x the median window's RMS (a settling, a step). Each stretch is widened by half
    a block on either side (a transient's own start and tail); samples after the last whole half block
    go with it. Empty when fewer than 8 blocks fit, when the median window has no variation, or when
    more than ``TRANSIENT_SHARE`` of the record would be marked: a level that changes that much is the
    record's own (a run-up, an intermittent machine), not a transient to remove.

    ``whiten=True`` judges the windows of the signal whitened (``whitened``: its spectrum flattened, as
    the envelope analysis sees it), on the RMS rule alone: a broadband burst fills every band the machine
    is quiet in, where whitening lifts it far above the rest (notes above ``TRANSIENT_LEVEL``); it is
    ``whitened_x`` where the caller has ``whitened(x)`` already."""
    x = _samples(x)
    if isinstance(block, bool) or not isinstance(block, (int, np.integer)) or block < 2:
        raise ParameterError(f"block={block!r} must be a whole number of samples, at least 2")
    if not isinstance(whiten, (bool, np.bool_)):
        raise ParameterError(f"whiten={whiten!r} must be True or False")
    if whiten:
        if x.size < 8 * block or not np.ptp(x) > 0:   # too short for _marked, or nothing to whiten
            return []
        xw, a = _whitened_or(x, whitened_x)
        inner = x.size - 2 * a
        # judged between the tapered ends; a run that reaches an end takes the tapered samples beyond it
        return [(0 if s == 0 else s + a, x.size if e == inner else e + a)
                for s, e in _marked(xw[a: x.size - a], int(block), offset=False)]
    return _marked(x, int(block), offset=True)


# A single impact (a knock on the machine, a tool set down) rings for milliseconds: over windows of two
# revolutions it hardly moves the RMS, yet whitened it stands as one impulse above everything else, and
# the envelope analysis takes its band (kurtogram) or its flat spectrum for the record's: a 2.5 kHz ring
# (Q 20) at 10 x the RMS a third of the way into the 53 development records took 42 right answers to 30
# (benchmarks/diagnosis_robustness.py; 39 with the impact gated). A bearing's impacts repeat: many windows stand
# about as high. An event is a window of ``block`` samples (moved by half a window) whose whitened RMS is
# EVENT_LEVEL x the median window's and whose excess over the median is EVENT_RATIO x that of the
# record's own loudest: the loudest window beyond the MAX_EVENTS loudest (each with its neighbours), so
# that a few knocks are found together and more, as loud, are the record's rhythm. In quarter-turn
# windows the knock reads 2.1-23 x the median (the ratio is what finds it on the MFPT outer-race
# records, whose whitened windows are even to 10 %: 2.1-2.5 x); it is found on 117 of the 143 channels,
# not where the record's own loud stretches stand as high (fan-end ball faults, MFPT's inner race). As
# recorded, the development channels' excess ratios run on to 10.9 (fan-end OR007@12_0), 6.9, 4.5, 3.7:
# real records have loud moments of their own, and gating one can turn a marginal record (at a ratio of
# 3, six channels have an event, and fan-end OR007@12_1 under a 20 dB tone becomes a wrong ball call).
# At 5, two channels (OR007@12_0, B007_3; 17 ms each) and no answer changes; the knock is found on 117
# channels (130 at 3).
EVENT_LEVEL = 2.0
EVENT_RATIO = 5.0
MAX_EVENTS = 3


def isolated_events(x, block: int, *, whitened_x: tuple | None = None) -> list[tuple[int, int]]:
    """(start, stop) of single impacts: stretches of about ``block`` samples whose whitened RMS stands
    EVENT_LEVEL x the median window's, with an excess over the median EVENT_RATIO x that of the record's
    own loudest (the loudest window beyond the MAX_EVENTS loudest and their neighbours); at most
    MAX_EVENTS, each widened by a window before and two after (its onset and ring). More impacts than
    that, as loud, are the record's own rhythm. Empty when fewer than 16 windows fit or the signal is
    constant. ``whitened_x``: ``whitened(x)`` where the caller has it already.

    Examples
    --------
    >>> import numpy as np
    >>> from vibmeasure.signal import quality
    >>> x = np.random.default_rng(0).normal(size=48000)
    >>> t = np.arange(1200) / 12000.0
    >>> x[20000:21200] += 40 * np.exp(-400 * t) * np.sin(2 * np.pi * 2500 * t)   # a knock
    >>> [(s <= 20000 < e) for s, e in quality.isolated_events(x, 100)]
    [True]
    """
    x = _samples(x)
    if isinstance(block, bool) or not isinstance(block, (int, np.integer)) or block < 2:
        raise ParameterError(f"block={block!r} must be a whole number of samples, at least 2")
    h = int(block) // 2
    if x.size < 16 * block or not np.ptp(x) > 0:
        return []
    xw, a = _whitened_or(x, whitened_x)
    inner = xw[a: x.size - a]
    nu = inner.size // h
    P = (inner[: nu * h].reshape(nu, h) ** 2).sum(axis=1)
    rms = np.sqrt((P[:-1] + P[1:]) / (2 * h))        # window k = half windows k and k + 1
    med = float(np.median(rms))
    if not med > 0:
        return []
    # the loudest windows, each beyond the others' neighbours; the one after the first MAX_EVENTS is the
    # record's own loudest, against which an event must stand
    peaks, taken = [], np.zeros(rms.size, bool)
    for _ in range(MAX_EVENTS + 1):
        if taken.all():
            break
        k = int(np.argmax(np.where(taken, -np.inf, rms)))
        peaks.append(k)
        taken |= np.abs(np.arange(rms.size) - k) <= 3
    if len(peaks) <= MAX_EVENTS:
        return []
    own = rms[peaks[-1]]
    runs = [(max(0, a + (k - 1) * h), min(x.size, a + (k + 3) * h)) for k in peaks[:MAX_EVENTS]
            if rms[k] >= EVENT_LEVEL * med and rms[k] - med >= EVENT_RATIO * (own - med)]
    return sorted(runs)


def _marked(x: np.ndarray, block: int, offset: bool) -> list[tuple[int, int]]:
    """``transients``' rule on x: the RMS rule, and with ``offset`` the mean's."""
    h = block // 2
    nu = x.size // h                       # half blocks
    if nu < 16:
        return []
    U = x[: nu * h].reshape(nu, h)
    s1, s2 = U.sum(axis=1), (U ** 2).sum(axis=1)
    mu = (s1[:-1] + s1[1:]) / (2 * h)      # window k = half blocks k and k + 1
    rms = np.sqrt(np.maximum((s2[:-1] + s2[1:]) / (2 * h) - mu ** 2, 0.0))
    level = float(np.median(rms))
    if not level > 0:
        return []
    win = rms > TRANSIENT_LEVEL * level
    if offset:
        win |= np.abs(mu - np.median(mu)) > TRANSIENT_OFFSET * level
    if not win.any():
        return []
    bad = np.zeros(nu, bool)
    bad[:-1] |= win
    bad[1:] |= win
    bad = bad | np.concatenate(([False], bad[:-1])) | np.concatenate((bad[1:], [False]))
    d = np.diff(np.concatenate(([0], bad.view(np.int8), [0])))
    runs = [(int(s) * h, int(e) * h if e < nu else x.size)
            for s, e in zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1))]
    if sum(e - s for s, e in runs) > TRANSIENT_SHARE * x.size:
        return []
    return runs


def gate(x, runs, ramp: int) -> np.ndarray:
    """x with the samples of ``runs`` ((start, stop) pairs) set to the mean of the rest, and ``ramp``
    samples on each side of each run brought to it along a half cosine (no step for the spectrum to
    spread)."""
    x = _samples(x)
    if isinstance(ramp, bool) or not isinstance(ramp, (int, np.integer)) or ramp < 0:
        raise ParameterError(f"ramp={ramp!r} must be a whole number of samples, 0 or more")
    w = np.ones(x.size)
    for run in runs:
        ok = np.ndim(run) == 1 and len(run) == 2 and all(
            isinstance(v, (int, np.integer)) and not isinstance(v, bool) for v in run)
        if not ok or not 0 <= run[0] < run[1] <= x.size:
            raise ParameterError(f"runs must be (start, stop) sample pairs within x (whole numbers, 0 <= start < "
                                 f"stop <= {x.size}), got {run!r}")
        w[run[0]:run[1]] = 0.0
    if w.all():
        return x.copy()
    keep = w > 0
    m = float(x[keep].mean()) if keep.any() else 0.0
    if ramp > 0:
        r = 0.5 - 0.5 * np.cos(np.pi * np.arange(1, ramp + 1) / (ramp + 1))   # rising, 0 < r < 1
        for s, e in runs:
            a, b = min(ramp, int(s)), min(ramp, x.size - int(e))
            w[s - a: s] = np.minimum(w[s - a: s], r[::-1][ramp - a:])   # falling into the run
            w[e: e + b] = np.minimum(w[e: e + b], r[:b])                 # rising out of it
    return m + (x - m) * w


def despike(rec, *, fs: float | None = None, sigma: float = SPIKE_SIGMA,
            isolation: float = SPIKE_ISOLATION) -> Record:
    """The record with every isolated spike replaced by its AR interpolation.

    A spike is a single sample (or a pair) far from both neighbours and from the running median
    (``isolated_spikes``); it is filled by least-squares AR interpolation (``fill``, Janssen et al.
    1986). A QualityWarning names each channel repaired and how many samples.

    Parameters
    ----------
    rec : Record or array_like
        The record.
    fs : float, optional
        Sampling rate for an array.
    sigma : float
        Departure from the running median, in robust standard deviations, that marks a spike.
    isolation : float
        How much further out than its neighbours a spike must stand.

    Returns
    -------
    Record

    Raises
    ------
    ParameterError
        For bad thresholds or data.

    Examples
    --------
    >>> import warnings
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> x = np.sin(np.arange(4000) / 7.0)
    >>> x[1000] = 50.0
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("ignore")
    ...     clean = vm.despike(vm.Record.from_array(x, fs=1000.0))
    >>> bool(abs(clean.data[0, 1000]) < 1.1)
    True
    """
    from .preprocess import _finite
    rec = as_record(rec, fs=fs)
    _thresholds(sigma, isolation)
    _finite(rec, "despike")
    data = np.array(rec.data, dtype=np.float64)
    found = {}
    for i, ch in enumerate(rec.channels):
        idx = isolated_spikes(data[i], sigma=sigma, isolation=isolation)
        if idx.size:
            data[i] = fill(data[i], idx)
            found[ch.name] = int(idx.size)
    if not found:
        return rec
    warn_quality("despike: " + "; ".join(f"channel {k!r}: {v} isolated spike{'s' * (v > 1)} replaced"
                                         for k, v in found.items()))
    return rec.replace(data=data, note=f"despike(sigma={sigma:g}, isolation={isolation:g}): {found}")
