"""Line statistics: the exact law of a line over its floor, comb statistics and their Gamma tail,
p-values to posterior confidence."""

from __future__ import annotations

from functools import lru_cache
from math import gcd

import numpy as np

from .rules import PRIOR_ODDS, R_CAP, SHAFT_PRECISION, SLIP
from .spectra import _SES

# --- statistics ---------------------------------------------------------------------------------

def _log_gamma_sf(t: float, k: int) -> float:
    """log P(Gamma(k, 1) > t), without underflow far in the tail."""
    from scipy.special import gammaincc, gammaln
    q = float(gammaincc(k, t)) if t > 0 else 1.0
    if q > 1e-280:
        return float(np.log(q))
    # far tail: Q(k, t) ~ t^(k-1) e^-t / Gamma(k) (1 + (k-1)/t + ...)
    return float((k - 1) * np.log(t) - t - gammaln(k) + np.log1p((k - 1) / t))


def _log_odds(logp: np.ndarray) -> np.ndarray:
    """Posterior log odds of a family from its p-value: the Bayes-factor bound 1 / (-e p ln p) for
    p < 1/e (Sellke, Bayarri & Berger 2001) times the prior odds."""
    logp = np.minimum(np.asarray(logp, float), 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        log_bf = np.where(logp < -1.0, -(1.0 + np.log(np.maximum(-logp, 1e-300)) + logp), 0.0)
    return log_bf + np.log(PRIOR_ODDS)


def _log_p_to_conf(logp: np.ndarray) -> np.ndarray:
    """Posterior probability of each family (each against its absence) from its p-value."""
    return 1.0 / (1.0 + np.exp(-_log_odds(logp)))


def _positions(f0, harmonics, side, s):
    """Line positions (n_slip, n_terms) and the (harmonic, sideband) label of each term."""
    H, K, terms = _terms(tuple(harmonics), bool(side))
    pos = H * f0 * (1 + s[:, None])
    if side is not None:   # (without sidebands K is all 0: nothing to add)
        pos = pos + K * (side[0] * (1 + s[:, None] * side[1]))
    return pos, terms


@lru_cache(maxsize=256)
def _terms(harmonics: tuple, sidebands: bool):
    """The comb's terms: each harmonic alone or with its -1, 0, +1 sidebands; (harmonic array, sideband
    array, [(harmonic, sideband)]). Cached: a diagnosis asks for the same few shapes thousands of times."""
    terms = [(hh, k) for hh in np.asarray(harmonics, float) for k in ((-1, 0, 1) if sidebands else (0,))]
    H = np.array([t[0] for t in terms])
    K = np.array([t[1] for t in terms])
    H.flags.writeable = K.flags.writeable = False
    return H, K, tuple(terms)


@lru_cache(maxsize=256)
def _slip_grid(slip: float, n_s: int) -> np.ndarray:
    """The common slips a comb is tried at (read-only, cached like the terms)."""
    s = np.linspace(-slip, slip, n_s)
    s.flags.writeable = False
    return s


def _best(vals: np.ndarray, n_t: int, m_eff: int, shape: float):
    """The comb statistic of each candidate row of line values (ratios to the floor, each capped at
    R_CAP), the best row and its log p-value: n_t terms, each with 2 bins looked at, m_eff independent
    placements searched; ``shape``: channels averaged (Gamma(shape) per line under noise)."""
    T = np.minimum(vals, R_CAP).sum(axis=1) + 1e-9 * vals.sum(axis=1)  # ties: the stronger lines
    j = int(np.argmax(T))
    return T, j, _log_p(float(T[j]), n_t, m_eff, shape)


def _log_p(t: float, n_t: int, m_eff: int, shape: float) -> float:
    """log p-value of the best comb statistic t: Gamma tail, 2 bins per term, m_eff placements."""
    return np.log(m_eff) + n_t * np.log(2.0) + _log_gamma_sf(t * shape, n_t * shape)


def _comb_fit(ses: _SES, f0: float, harmonics, side=None, slip=SLIP):
    """The comb's fit over the common slips: (harmonics that fit the SES, slips, positions, terms,
    line values, statistics, best row, log p-value), or None when fewer than 2 terms fit."""
    df = ses.freq[1]
    top = (max(harmonics) * f0 + (side[0] if side else 0.0)) * (1 + slip)
    if top / df >= ses.n_valid - 2:
        harmonics = tuple(h for h in harmonics if (h * f0 + (side[0] if side else 0)) * (1 + slip) / df
                          < ses.n_valid - 2)
        if len(harmonics) < (1 if side else 2):
            return None
        top = (max(harmonics) * f0 + (side[0] if side else 0.0)) * (1 + slip)
    s = _slip_grid(slip, max(3, int(np.ceil(2 * slip * top / (0.5 * df))) + 1))
    pos, terms = _positions(f0, harmonics, side, s)
    i0 = np.clip(pos / df, 1, ses.n_valid - 2).astype(np.int64)
    vals = np.maximum(ses.r[i0], ses.r[i0 + 1])
    T, j, logp = _best(vals, len(terms), int(2 * slip * top / df) + 1, ses.shape)
    return harmonics, s, pos, terms, vals, T, j, logp


def _comb_logp(ses: _SES, f0: float, harmonics, side=None, slip=SLIP) -> float | None:
    """The comb's log p-value alone (``_comb(...)["logp"]``), for the many decoy combs that need no more."""
    fit = _comb_fit(ses, f0, harmonics, side, slip)
    return None if fit is None else float(min(fit[-1], 0.0))


def _comb_logps(ses: _SES, f0s, harmonics, side=None, slip=SLIP) -> list:
    """``_comb_logp`` of the same comb at many fundamentals (the decoys) in one array: every row's
    arithmetic as ``_comb_fit`` does it, so each value is the one comb's own. A comb that reaches the
    spectrum's end (its harmonics cut) is fitted alone."""
    df, nv = ses.freq[1], ses.n_valid
    off = side[0] if side else 0.0
    out, rows = [None] * len(f0s), []
    for i, f0 in enumerate(f0s):
        top = (max(harmonics) * f0 + off) * (1 + slip)
        if top / df >= nv - 2:
            out[i] = _comb_logp(ses, f0, harmonics, side, slip)
        else:
            rows.append((i, f0, _slip_grid(slip, max(3, int(np.ceil(2 * slip * top / (0.5 * df))) + 1)),
                         int(2 * slip * top / df) + 1))
    if not rows:
        return out
    H, K, terms = _terms(tuple(harmonics), bool(side))
    S = np.concatenate([s for _, _, s, _ in rows])[:, None]
    pos = H * np.concatenate([np.full(s.size, f0) for _, f0, s, _ in rows])[:, None] * (1 + S)
    if side is not None:
        pos = pos + K * (side[0] * (1 + S * side[1]))
    i0 = np.clip(pos / df, 1, nv - 2).astype(np.int64)
    vals = np.maximum(ses.r[i0], ses.r[i0 + 1])
    T = np.minimum(vals, R_CAP).sum(axis=1) + 1e-9 * vals.sum(axis=1)
    a = 0
    for i, _, s, m_eff in rows:
        j = a + int(np.argmax(T[a: a + s.size]))
        out[i] = float(min(_log_p(float(T[j]), len(terms), m_eff, ses.shape), 0.0))
        a += s.size
    return out


def _comb(ses: _SES, f0: float, harmonics, side=None, slip=SLIP) -> dict | None:
    """Best common slip for a comb and its log p-value; None when fewer than 2 terms fit the SES."""
    fit = _comb_fit(ses, f0, harmonics, side, slip)
    if fit is None:
        return None
    harmonics, s, pos, terms, vals, T, j, logp = fit
    n_s, df, r_line = s.size, ses.freq[1], ses.r_line
    best, at = vals[j].tolist(), pos[j].tolist()
    # one pass over the terms: the lines, and of those standing the counts and the step (``_step``)
    lines, main, n_lines, n_carriers, n_odd, g = [], [], 0, 0, 0, 0
    for (h, k), p, v in zip(terms, at, best):
        lines.append({"harmonic": float(h), "sideband": int(k), "hz": float(p), "r": v})
        if k == 0:
            main.append(v)
        if v >= r_line:
            n_lines += 1
            n_carriers += bool(k == 0 and h <= 3)
            n_odd += bool(h != int(h) or int(h) % 2)
            g = gcd(g, int(round(2 * h)))
    return {"logp": float(min(logp, 0.0)), "slip": float(s[j]), "stat": float(T[j]), "n_terms": len(terms),
            "edge": bool((slip - abs(s[j])) * max(at) < df and T[j] > T[n_s // 2]),
            "strength": float(np.sum(main)), "lines": lines, "n_lines": n_lines, "n_carriers": n_carriers,
            "n_odd": n_odd, "step": g / 2 if g else 1.0, "halves": _halves(ses, f0 * (1 + s[j]), harmonics)}


HALF_SHARE = 0.5   # a half-harmonic line counts from this share of the comb's own lines' median height


def _halves(ses: _SES, f0: float, harmonics, base: bool = False) -> int:
    """How many of the lines halfway below the comb's first three harmonics (0.5, 1.5, 2.5 x f0) stand
    as high as the comb's own (HALF_SHARE of the median of its standing harmonics 1-3): two or more make
    the comb the even harmonics of one at f0 / 2 (the true lines of a speed declared twice too fast, all
    of one height). Weaker half-lines are no such comb: CWRU IR021_3's inner race shows BPFI / 2 and
    1.5 x BPFI at a fifth of its own lines' height. 0 for a comb with half-harmonics of its own (the
    ball's BSF sub-model). ``base``: on the lines left after the shaft's and the cage's claims."""
    if any(h != int(h) for h in harmonics):
        return 0
    df = ses.freq[1]
    r = ses.r_base if base and ses.r_base is not None else ses.r

    def height(hz):
        i = int(hz / df)
        return float(max(r[i - 1: i + 3])) if 1 <= i < ses.n_valid - 2 else 0.0
    own = [v for v in (height(h * f0) for h in (1, 2, 3)) if v >= ses.r_line]
    if not own:
        return 0
    own.sort()   # their median, as np.median takes it, without its overhead on three values
    mid = len(own) // 2
    need = max(ses.r_line, HALF_SHARE * (own[mid] if len(own) % 2 else (own[mid - 1] + own[mid]) / 2))
    return sum(height((h - 0.5) * f0) >= need for h in (1, 2, 3) if (h - 0.5) * f0 / df >= 2)


DENSER_MAX = 12      # denser combs tried: f0 / 3 .. f0 / DENSER_MAX
DENSER_SHARE = 1 / 3   # of the in-between places that stand as high as the comb's own lines


def _denser(ses: _SES, f0: float, harmonics, own_sidebands=()) -> int:
    """The m (3 .. DENSER_MAX) for which the comb is every m-th line of a comb at f0 / m: at least
    DENSER_SHARE (and 3) of the places j f0 / m between its first three harmonics (j not a multiple of m)
    hold lines as high as the comb's own (HALF_SHARE of the median of its standing harmonics 1-3); 0
    when there is no such m. Places within 1.5 bins or 1 % of the comb's own modulation sidebands
    (harmonics 1-3 +- 1, 2 x each spacing in ``own_sidebands``) are not asked: the 6203's BPFO is
    3.05 X, so its +-1X sidebands stand at about j BPFO / 3. Another shaft's harmonics (a gearbox's
    second shaft, a belt's pulley) make such a comb: a 32/71 gearbox at 1800 rpm has its wheel's 8th,
    16th, 24th and 32nd orders 0.6 % off a 6205's BPFO and its harmonics, with lines between standing
    too. (m = 2 is ``_halves``.)"""
    if any(h != int(h) for h in harmonics):
        return 0
    df, r = ses.freq[1], ses.r
    top = ses.n_valid - 3

    def heights(hz):
        i = (np.asarray(hz) / df).astype(np.int64)
        ok = (i >= 1) & (i < top)
        i = np.where(ok, i, 1)
        return np.where(ok, np.max(np.stack([r[i - 1], r[i], r[i + 1], r[i + 2]]), axis=0), 0.0)
    own = heights(np.arange(1, 4) * f0)
    own = own[own >= ses.r_line]
    if not own.size:
        return 0
    need = max(ses.r_line, HALF_SHARE * float(np.median(own)))
    mods = np.array([h * f0 + k * sp for h in (1, 2, 3) for sp in own_sidebands for k in (-2, -1, 1, 2)])
    # every m's places at once (each value as j * f0 / m gives it), counted per m
    j, m = _DENSER_PLACES
    hz = j * f0 / m
    asked = hz / df >= 2
    if mods.size:
        asked &= np.all(np.abs(hz[:, None] - mods[None, :]) > np.maximum(1.5 * df, 0.01 * hz[:, None]), axis=1)
    n_asked = np.bincount(m[asked], minlength=DENSER_MAX + 1)
    n_high = np.bincount(m[asked & (heights(hz) >= need)], minlength=DENSER_MAX + 1)
    for mm in range(3, DENSER_MAX + 1):
        size = int(n_asked[mm])
        if size >= 3 and int(n_high[mm]) >= max(3, DENSER_SHARE * size):
            return mm
    return 0


def _places(m_max: int) -> tuple:
    """(j, m) of every place j / m x f0 (m = 3 .. m_max, j = 1 .. 3 m - 1, no multiple of m) that
    ``_denser`` asks, as two read-only integer arrays."""
    jm = np.array([(j, m) for m in range(3, m_max + 1) for j in range(1, 3 * m) if j % m]).T
    jm.flags.writeable = False
    return jm[0], jm[1]


_DENSER_PLACES = _places(DENSER_MAX)


def _step(harmonics) -> float:
    """The spacing, in multiples of the fundamental, of the comb the standing lines' harmonics make: the
    greatest common divisor of their half-harmonic indices 2h, over 2 (1.0 when no line stands). Up to 1
    the lines pin the family's fundamental: harmonic 1 alone, or 1 and 2, or 2 and 3 give 1; 2 and 4
    give 2; 3 alone gives 3. In the ball family's BSF sub-model (0.5, 1, 1.5 x 2 x BSF) 0.5 x 2 x BSF
    alone gives 0.5, 2 x BSF alone 1 (its own lines); 1.5 x 2 x BSF alone gives 1.5."""
    g = 0
    for h in harmonics:
        g = gcd(g, int(round(2 * h)))
    return g / 2 if g else 1.0


def _mask(ses: _SES, hz: float):
    """Claim the line at hz: its bins (and the leakage of a strong line) no longer count."""
    df = ses.freq[1]
    i = int(round(hz / df))
    if not 2 <= i < ses.n_valid - 2:
        return
    lo, hi = i - 1, i + 1
    while lo > i - 4 and ses.r[lo - 1] > 2.0:
        lo -= 1
    while hi < i + 4 and hi + 1 < ses.n_valid and ses.r[hi + 1] > 2.0:
        hi += 1
    ses.r[lo: hi + 1] = 0.0


def _line_present(ses: _SES, hz: float) -> bool:
    i = int(hz / ses.freq[1])
    return 1 <= i < ses.n_valid - 2 and max(ses.r[i - 1: i + 3]) >= ses.r_line


def _peak_at(ses: _SES, hz: float) -> float | None:
    """The frequency of a line standing at hz: a local maximum at least R_LINE high whose interpolated
    position lies within SHAFT_PRECISION x hz (at least 0.6 bin) of it; None when there is none, or
    what stands there is the flank or the peak of another line beside it. On a short record a bearing
    line a bin or two from a shaft harmonic (the 6209's BPFI is 5.977 X: 2.3 bins from 6X at 4 s)
    would otherwise pass for the shaft's."""
    df = ses.freq[1]
    tol = max(0.6 * df, SHAFT_PRECISION * hz)
    lo, hi = max(1, int(np.floor((hz - tol) / df))), min(ses.n_valid - 2, int(np.ceil((hz + tol) / df)))
    if hi < lo:
        return None
    j = lo + int(np.argmax(ses.r[lo: hi + 1]))
    a, b, c = ses.r[j - 1], ses.r[j], ses.r[j + 1]
    if b < ses.r_line or b < a or b < c:
        return None
    den = a - 2 * b + c
    f_peak = (j + (0.5 * (a - c) / den if den < 0 else 0.0)) * df
    return f_peak if abs(f_peak - hz) <= tol else None
