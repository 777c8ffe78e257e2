"""The cage (FTF) comb: claimed as an explanation, never called; its level divides the lines it
shares with the other families (``_cage_floor``)."""

from __future__ import annotations

import numpy as np

from .lines import _comb, _line_present, _mask
from .rules import ALPHA, CONTESTED, SLIP
from .spectra import _SES


def _cage_shared(k_max: int, freqs: dict, f1: float, n_balls: int, df: float) -> set:
    """The cage harmonics (not multiples of n_balls: those are BPFO's) where an inner-race or ball line
    stands at its catalogue frequency too: within CONTESTED (plus 1.5 bins) of a harmonic 1-5 of BPFI or
    its +-1X sidebands, of BSF x 1-6 (2 x BSF x 0.5-3) or of the +-FTF sidebands of 2 x BSF x 1-3.

    Every defect frequency is a fixed multiple of the shaft speed, and for many bearings a harmonic of
    BPFI or 2 x BSF falls within a fraction of a per cent of a cage harmonic: BPFI is n (1 - FTF/fr) fr
    and FTF/fr is about 0.38-0.40, so BPFI/FTF = n fr/FTF - n lands near a whole number for whole
    families of bearings. Of the catalogue's 32 bearings, 30 have a harmonic 1-3 of BPFI or 2 x BSF
    within 1 % of one: the CWRU fan end's 6203 has BPFI at 12.96 x FTF (-0.3 %), the IMS rig's ZA-2115
    BPFI at 20.10 x and 2 x BSF at 18.94 x FTF. Claimed with the cage comb, those lines were lost to the
    family they belong to: CWRU IR021_3's fan-end channel alone lost every BPFI carrier (BPFI x 1-3 at
    13, 26 and 39 x FTF) and read "none" beside an inner-race sideband comb at p = 2.5e-33."""
    ftf = freqs["FTF"]
    lines = [h * freqs["BPFI"] + m * f1 for h in range(1, 6) for m in ((-1, 0, 1) if h <= 3 else (0,))]
    lines += [h * freqs["BSF"] for h in range(1, 7)]
    lines += [h * freqs["2xBSF"] + m * ftf for h in (1, 2, 3) for m in (-1, 1)]
    lines = np.asarray(lines)
    k = np.arange(1, k_max + 1)
    near = np.any(np.abs(k[:, None] * ftf - lines[None, :]) <= (CONTESTED * lines + 1.5 * df)[None, :], axis=1)
    return set(k[near & (k % n_balls != 0)].tolist())


def _claim_cage(ses: _SES, freqs: dict, f1: float, n_balls: int) -> dict | None:
    """The cage comb (FTF harmonics that are not BPFO's, which is n_balls x FTF): claimed when
    significant. Cage-rate modulation is common on healthy bearings; it is reported, not called. The
    harmonics an inner-race or ball line shares (``_cage_shared``) are left to those families: there the
    comb is their floor instead (``_cage_floor``)."""
    ftf = freqs["FTF"]
    k_max = int((ses.n_valid - 3) * ses.freq[1] / (ftf * (1 + SLIP)))
    shared = _cage_shared(k_max, freqs, f1, n_balls, ses.freq[1])
    res = _cage_comb(ses, ftf, n_balls, shared)
    if _cage_stands(res):
        for k in range(1, k_max + 1):
            hz = k * ftf * (1 + res["slip"])
            if k % n_balls and k not in shared and _line_present(ses, hz):
                _mask(ses, hz)
    return res


CAGE_NEIGHBOURS = 3   # a BPFO line is weighed against the cage comb's harmonics this many either side of it


def _cage_floor(ses: _SES, freqs: dict, f1: float, n_balls: int) -> dict | None:
    """Where the cage comb stands out, its level is the floor of the lines it shares with BPFO, and with
    BPFI and the ball family where their lines fall on its harmonics (``_cage_shared``).

    BPFO is n_balls x FTF exactly (both scale with 1 - d/D cos(contact angle)), so every BPFO harmonic
    is also a harmonic of the cage comb. ``_claim_cage`` leaves those lines to BPFO; but a comb that
    carries its harmonics on either side of one carries it too, and there the line is evidence for
    the outer race only by what it stands above the comb. So, in a spectrum whose cage comb is
    significant, the ratios within half a cage order of each multiple of n_balls x FTF are divided by
    the comb's level there: the median of its lines at the CAGE_NEIGHBOURS harmonics either side (the
    typical height of the comb's lines beside it); where that level is below the noise floor nothing
    changes. The median, not the mean, so that one shaft line or one sideband among the neighbours
    does not set it. Where the comb's fundamental is refined on its lines (``_cage_comb``), only the
    line's bins are divided (2 bins plus one per 12 harmonics either side of where the fit puts it);
    else the whole stretch, since the FTF searched on harmonics 1-6 does not pin the 18th to a bin
    (and a line of another family inside it is divided too: the 6205's 2 x BPFI lies 0.7 % from its
    3 x BPFO). The harmonics an inner-race or ball line shares are weighed the same way, against the
    nearest harmonics either side that are neither BPFO's nor shared: a healthy bearing's cage comb
    then gives those families nothing, a defect's line what it stands above the comb.

    A ball defect rides with the cage into and out of the load zone: the envelope carries the cage
    comb (CWRU drive-end B007_0: 18 of FTF x 1-21 at 5-15 dB), and its 9th and 18th harmonics, the 6205's
    BPFO x 1-2, were called outer race at p = 8e-18. An outer-race defect's own lines stand well
    above their cage sidebands.

    Returns the cage comb's test (``_comb``) when it is significant, else None."""
    ftf = freqs["FTF"]
    df = ses.freq[1]
    k_max = int((ses.n_valid - 3) * df / (ftf * (1 + SLIP)))
    shared = _cage_shared(k_max, freqs, f1, n_balls, df)
    res = _cage_comb(ses, ftf, n_balls, shared)
    if not _cage_stands(res):
        return None
    f = ftf * (1 + res["slip"])
    pre = ses.r.copy()
    m = min(CAGE_NEIGHBOURS, (n_balls - 1) // 2)   # neighbours that are no multiple of n_balls
    if m < 1:
        return res

    def weigh(k, nb):
        level = float(np.median([max(pre[i], pre[i + 1]) for i in (int(kk * f / df) for kk in nb)]))
        if level <= 1.0:
            return
        if res.get("refined") or k % n_balls:   # the line's bins
            half = 2 + k / 12 if res.get("refined") else 1.5 + k / 12
            lo, hi = int(np.ceil(k * f / df - half)), int(np.floor(k * f / df + half))
        else:   # BPFO's harmonic where the comb's fundamental is not refined: the whole stretch
            lo, hi = int(np.ceil((k - 0.5) * f / df)), int(np.floor((k + 0.5) * f / df))
        ses.r[lo: hi + 1] /= level
        ses.cage_floor[k] = (lo * df, hi * df, level)

    k = n_balls
    while (k + m) * f / df < ses.n_valid - 3:
        weigh(k, [kk for j in range(1, m + 1) for kk in (k - j, k + j)])
        k += n_balls
    free = [kk for kk in range(1, k_max + 1) if kk % n_balls and kk not in shared]
    for k in sorted(shared):
        below = [kk for kk in free if kk < k][-CAGE_NEIGHBOURS:]
        above = [kk for kk in free if kk > k][:CAGE_NEIGHBOURS]
        if below and above and (above[-1] + 1) * f / df < ses.n_valid - 3:
            weigh(k, below + above)
    return res


CAGE_REFINE = 24   # a cage comb that stands has its fundamental refined on its harmonics up to this one


def _cage_comb(ses: _SES, ftf: float, n_balls: int, shared=()) -> dict | None:
    """The cage comb's test (``_comb``) on its harmonics 1-6 that are neither BPFO's nor ``shared`` with
    another family (``_cage_shared``). Where it stands, its fundamental is refined on the lines it shows
    up to its CAGE_REFINE-th harmonic (``_refined``; the p-value stays that of harmonics 1-6)."""
    k_max = int((ses.n_valid - 3) * ses.freq[1] / (ftf * (1 + SLIP)))
    ks = tuple(k for k in range(1, min(k_max, 6) + 1) if k % n_balls and k not in shared)
    res = _comb(ses, ftf, ks) if len(ks) >= 2 else None
    if _cage_stands(res):
        fine = [k for k in range(1, min(k_max, CAGE_REFINE) + 1) if k % n_balls and k not in shared]
        f = _refined(ses, ftf * (1 + res["slip"]), fine)
        res["refined"] = f is not None
        if f is not None:
            res["slip"] = f / ftf - 1
    return res


def _refined(ses: _SES, f0: float, ks) -> float | None:
    """The fundamental of a comb from the lines it shows, refined harmonic by harmonic: the least-squares
    fit through the origin of the interpolated peak frequencies standing (R_LINE) within 2 bins of
    k x f0 on its harmonics ``ks`` up to the 6th, then within 1.5 bins of where that fit puts them up
    to the 12th, then up to the 24th (CAGE_REFINE). Each stage needs three lines (else the last fit
    stands); None when even the first has fewer. Windows that narrow keep other combs out: a ball
    defect's 2 x BSF +-FTF lines are a comb at FTF's spacing too, 0.17 FTF off the 6205's cage
    harmonics 11-13, and one wide window fit took them for the cage's.

    The slip searched on harmonics 1-6 pins the fundamental to half a bin over the 6th harmonic at
    best, and worse where their lines are so strong that every one is capped (R_CAP) over a range of
    slips: a healthy 6203 whose envelope pulses once per cage turn showed its 13th-27th harmonics 2-5
    bins from where that fit put them; the comb's level beside BPFO x 2-3 (``_cage_floor``) was then
    read off its lines, below the noise floor, and BPFO x 1-3 at its 8th, 16th and 24th harmonics was
    called outer race."""
    df = ses.freq[1]
    f, done = f0, False
    for top, half in ((6, 2.0), (12, 1.5), (CAGE_REFINE, 1.5)):
        num = den = 0.0
        n = 0
        for k in (k for k in ks if k <= top):
            lo = max(1, int(np.floor(k * f / df - half)))
            hi = min(ses.n_valid - 2, int(np.ceil(k * f / df + half)))
            if hi <= lo:
                continue
            j = lo + int(np.argmax(ses.r[lo: hi + 1]))
            a, b, c = ses.r[j - 1], ses.r[j], ses.r[j + 1]
            if b < ses.r_line or b < a or b < c:
                continue
            d = a - 2 * b + c
            fk = (j + (0.5 * (a - c) / d if d < 0 else 0.0)) * df
            if abs(fk - k * f) > half * df:
                continue
            num += k * fk
            den += k * k
            n += 1
        if n < 3:
            break
        f, done = num / den, True
    return f if done else None


def _cage_stands(res: dict | None) -> bool:
    """Does the cage comb stand out: significant, with two lines standing?"""
    return bool(res and res["logp"] < np.log(ALPHA) and res["n_lines"] >= 2)
