"""Decoy combs (how unusual a family's comb is on its own spectrum) and the speed scan (a comb that
stands where another speed puts it contradicts the declared speed)."""

from __future__ import annotations

import numpy as np

from .families import _family
from .families import HALVES
from .grid import on_grid
from .lines import _best, _comb_logps, _halves, _positions, _step
from .rules import ALPHA, FAMILIES, SLIP
from .spectra import _SES

N_DECOYS = 120


def _decoy_p(ses: _SES, res: dict, f0: float, freqs: dict) -> float:
    """Empirical false-alarm probability of a family's comb on this spectrum: the share of decoy
    combs of the same shape, at fundamentals that are no bearing frequency (0.55-1.8 x f0, away from
    every family's harmonics and sub-harmonics), that score as well. It measures how easily this
    spectrum's own lines (other machine parts, electrical, structure) make a comb by chance, which
    the Gaussian-noise p-value cannot know."""
    harmonics, sp, _ = res["spec"]
    u = np.geomspace(0.55, 1.8, 4 * N_DECOYS)
    fund = [freqs[k] for k in ("BPFO", "BPFI", "2xBSF", "BSF", "FTF")]
    ratios = np.array([h * F / m / f0 for F in fund for h in (1, 2, 3) for m in (1, 2, 3)])
    keep = np.all(np.abs(u[:, None] / ratios[None, :] - 1) > 0.05, axis=1)
    u = u[keep][:: max(1, keep.sum() // N_DECOYS)][:N_DECOYS]
    saved, ses.r = ses.r, ses.r_base if ses.r_base is not None else ses.r
    try:
        scores = [c for c in _comb_logps(ses, [f0 * ui for ui in u], harmonics, sp) if c is not None]
    finally:
        ses.r = saved
    raw = res["logp"] - np.log(res["spec"][2])  # the family's own score before the sub-model correction
    return float((1 + sum(sc <= raw for sc in scores)) / (1 + len(scores)))


# --- the speed the bearing's lines imply ------------------------------------------------------------

# Where no 1X line confirms the declared speed, the bearing's own lines are the speedometer: every
# defect frequency and sideband spacing is a fixed multiple of the shaft speed, so a fault's comb shows
# where the true speed puts it. The families are searched again over SPEED_SCAN x the declared speed
# (every line and sideband spacing scaled together) beyond the 1X search (+-12 %: within it a comb
# only says the speed is somewhat off, as a 1X found there would). A comb there contradicts the
# declared speed when it is significant (p below ALPHA, corrected for the whole range searched like
# any comb), shows at least two lines with one at a first-three harmonic, fits inside the range (not
# at its edge), and stands SPEED_SCAN_MARGIN below the best comb of the declared speed: the families
# at their +-SLIP and, scaled alike, anywhere within the 1X search. Not counted: a comb whose lines
# are all harmonics of a speed within the 1X search (that shaft's own modulation, ``_shaft_like``),
# and one whose carriers all stand where the declared speed puts a bearing line (``_declared``: the
# 2 x BSF of MFPT's bearing at 0.632 x its speed is its BPFO). A real fault at the right speed is not
# outdone by its aliases: a comb at another speed that hits the same lines misses its sidebands or
# pays for the wider search. Measured (benchmarks/diagnosis_robustness.py): the MFPT records, whose
# 1X is too weak to contradict a wrong speed, declared 15 % slow, 20 % fast or 30 % slow give 8 wrong
# calls without the scan (BPFI - 2X and its multiples taken for BPFO at 15 % slow, p down to 1e-19); the inner race's
# own comb with its sidebands stands where the true speed puts it, p = 1e-38. Every development record
# at its declared speed with its 1X taken as not found (a scratch run forcing the scan): one is
# contradicted, B007_1, a "none" record whose base channel carries a BPFI comb with +-1X sidebands of
# a shaft 13.9 % faster (166.6 Hz +- 33.7 Hz). The two exclusions and the 1X-search range on the
# declared side are needed: without them, noise at the records' RMS (which hides the 1X) turns 3 right
# calls into "contradicted" (an inner race at +2.2 % read through BPFO's alias at 1.655 x, shaft
# harmonics read as BSF x 0.5, 1, 1.5 at 0.501 x).
SPEED_SCAN = (0.5, 2.0)
SPEED_SCAN_MARGIN = 1e-3
# A speed off by a factor 2 (rpm read as Hz x 30, two pulses per revolution, a gearbox's other shaft) is
# the commonest mistake, and a 1X found near it confirms nothing: the true shaft's 2X stands at twice a
# speed declared half the true one, with its own harmonics, and a line near half the true speed takes
# the true 1X and its harmonics for its even harmonics. So the bearing's lines are searched within
# FACTOR_WINDOW of 0.5 and 2 x the declared speed even when a 1X confirms it, by the same rule as the
# scan (a significant comb SPEED_SCAN_MARGIN below the declared speed's best); the full scan's range
# ends there and would miss a factor of exactly 2 (a comb at its edge "would fit better outside").
FACTOR_WINDOW = 0.06
# Not 1/4: at a quarter of the speed the bearing's lines fall among the shaft's first harmonics, where
# two lines of 12 dB made an inner-race comb that "contradicted" CWRU B014_2's speed.
FACTOR_WINDOWS = tuple((u * (1 - FACTOR_WINDOW), u * (1 + FACTOR_WINDOW)) for u in (0.5, 2.0))
# Where no 1X confirms the speed, 4 x it is searched too (fs declared 4 x the true rate, 48 kHz for
# 12): a bearing fault under a mesh at 3000 rpm, whose 1X is the supply's line, read at 4 x fs was
# answered "none" at 0.57 or "undetermined", unflagged. Every development record with its 1X taken as
# not found (the scan forced): no contradiction added (B007_1's, above, stays the only one). Not where
# the speed step already doubts the speed by a shaft comb or the time base: the test runs at the speed
# that doubt names, and a contradiction would drop it (CWRU fan-end records read at 4 x fs lost 5
# faults named that way).
UNCONFIRMED_WINDOWS = ((4.0 * (1 - FACTOR_WINDOW), 4.0 * (1 + FACTOR_WINDOW)),)


def _scan_comb(ses: _SES, f0: float, harmonics, side, lo: float, hi: float, excluded: float = 0.0, pair_max=None):
    """Best comb of f0's harmonics (and sidebands at spacing side[0]) when every line scales with the
    speed, over 1 + lo to 1 + hi times the declared speed, outside +-excluded around it: (log p
    corrected for the range searched, speed factor, term values, labels), or None. ``pair_max``: the
    larger of each bin and the next of the spectrum scanned (``_pair_max``), when the caller has it."""
    df = ses.freq[1]
    r = ses.r_base if ses.r_base is not None else ses.r
    if pair_max is None:
        pair_max = _pair_max(r)
    off = side[0] if side else 0.0
    harmonics = tuple(h for h in harmonics if (h * f0 + off) * (1 + lo) / df < ses.n_valid - 2)
    if len(harmonics) < (1 if side else 2):
        return None
    top = max(harmonics) * f0 + off
    s = np.linspace(lo, hi, int(np.ceil((hi - lo) * top / (0.5 * df))) + 1)
    s = s[np.abs(s) > excluded]
    pos, terms = _positions(f0, harmonics, None if side is None else (side[0], 1.0), s)
    b = pos / df
    i0 = np.clip(b, 1, ses.n_valid - 2).astype(np.int64)
    # a line the spectrum does not reach at that speed counts as absent (the comb keeps its shape)
    vals = np.where(b < ses.n_valid - 2, pair_max[i0], 0.0)
    T, j, logp = _best(vals, len(terms), int((hi - lo) * top / df) + 1, ses.shape)
    if j in (0, s.size - 1):   # it would fit better outside the range
        return None
    return float(logp), float(1 + s[j]), vals[j], terms


def _on_base(ses: _SES, name: str, freqs: dict, f1: float) -> dict | None:
    """The family's comb on the lines the shaft and the cage left (``r_base``): as the family test's
    first pass found it (``base_results``), else fitted there."""
    if ses.base_results is not None and name in ses.base_results:
        return ses.base_results[name]
    saved, ses.r = ses.r, ses.r_base if ses.r_base is not None else ses.r
    try:
        return _family(ses, name, freqs, f1)
    finally:
        ses.r = saved


def _pair_max(r: np.ndarray) -> np.ndarray:
    """max(r[i], r[i + 1]) for every i: a line is read from the two bins around its position, and the
    speed scan reads a million positions of the same spectrum per record."""
    return np.maximum(r[:-1], r[1:])


def _shaft_like(hz: list, f1: float, search: float, df: float) -> bool:
    """Do the lines ``hz`` all stand at whole multiples of one frequency within +-search of f1 (a shaft
    comb: the 1X modulation of an envelope, at a speed the 1X search covers)?"""
    lo = min(hz)
    for k in range(1, 5):
        g = lo / k
        if abs(g / f1 - 1) <= search and all(abs(h - round(h / g) * g) <= max(1.5 * df, 0.005 * h) for h in hz):
            return True
    return False


def _declared(hz: list, freqs: dict, df: float) -> bool:
    """Do the lines ``hz`` all stand where the declared speed puts a bearing line (a harmonic 1-5 of
    BPFO, BPFI, BSF or 2 x BSF, within SLIP: the harmonics the families test)? Such lines cannot
    contradict that speed."""
    return bool(hz) and all(any(abs(h - round(h / f) * f) <= max(SLIP * h, 1.5 * df) and 1 <= round(h / f) <= 5
                                for f in (freqs["BPFO"], freqs["BPFI"], freqs["BSF"], freqs["2xBSF"])) for h in hz)


def _speed_scan(spectra: list, freqs: dict, f1: float, speed_search: float, confirmed: bool = False,
                hunting_hz: float | None = None, four: bool = True) -> tuple:
    """(contradiction, rival). The contradiction: the bearing comb that contradicts the declared speed
    (see SPEED_SCAN; where a 1X ``confirmed`` the speed, only within FACTOR_WINDOWS), or None. The
    rival: the best significant comb within FACTOR_WINDOWS when it does not contradict the speed yet is
    not SPEED_SCAN_MARGIN weaker than the declared speed's best (both may saturate: a line counts up to
    R_CAP), or None: {"factor", "family", "model", "p_value", "declared_p_value"}. A contradiction: {"factor": true
    over declared speed, "family", "model", "p_value", "declared_p_value", "lines": [(Hz, dB)], "channel",
    "preprocessing", "other_factors"}. Both sides are judged on the same lines: every spectrum after the
    shaft's and the cage's claims (``r_base``), every family at the declared speed (its +-SLIP, and
    scaled anywhere within ``speed_search``) against every family elsewhere. A comb elsewhere whose lines are all harmonics of a speed within
    ``speed_search`` of the declared one is that shaft's modulation (a 1X too weak to be found), not a
    bearing's."""
    n_sp = max(1, len(spectra))
    # ``four``: 4 x the speed is searched too where nothing confirmed it (UNCONFIRMED_WINDOWS), unless the
    # time base is in doubt already (the speed step named its factor and the test runs at that speed too)
    ranges = FACTOR_WINDOWS if confirmed else (SPEED_SCAN,) + FACTOR_WINDOWS + (UNCONFIRMED_WINDOWS if four else ())
    found = [c for ses in spectra for c in _elsewhere(ses, freqs, f1, speed_search, ranges, n_sp, hunting_hz)]
    # the declared speed's best comb only weighs a significant comb found elsewhere: without one there is
    # neither a contradiction nor a rival, whatever it is
    if not found or min(c[0] for c in found) >= np.log(ALPHA):
        return None, None
    declared = min([0.0] + [_declared_best(ses, freqs, f1, speed_search, n_sp) for ses in spectra])
    found.sort(key=lambda c: c[0])
    logp, best = found[0]
    if logp >= np.log(ALPHA) or logp >= declared + np.log(SPEED_SCAN_MARGIN):
        return None, _rival(found, declared)
    best["declared_p_value"] = float(np.exp(declared))
    # another family's comb at another speed may fit the same lines nearly as well (a 6205's BPFO x 1-3
    # is its BSF x 1-3 at 1.52 x the speed): those speeds are named too
    others = []
    for lp, c in found[1:]:
        if lp < logp - np.log(SPEED_SCAN_MARGIN) and all(abs(c["factor"] / u - 1) > 2 * SLIP
                                                           for u in [best["factor"]] + others):
            others.append(c["factor"])
    best["other_factors"] = others
    return best, None


def _elsewhere(ses: _SES, freqs: dict, f1: float, speed_search: float, ranges: tuple, n_sp: int,
               hunting_hz: float | None) -> list:
    """The combs one spectrum shows at other speeds (``ranges``, outside the 1X search): (log p, comb) in the
    order families, sub-models and ranges are tried (``_speed_scan``)."""
    found = []
    pair_max = _pair_max(ses.r_base if ses.r_base is not None else ses.r)   # the scans below only read it
    for name, (key, models) in FAMILIES.items():
        for harmonics, side in models:
            sp = None if side is None else (f1 if side == "1X" else freqs["FTF"],)
            for lo, hi in ranges:
                res = _scan_comb(ses, freqs[key], harmonics, sp, lo - 1.0, hi - 1.0, max(SLIP, speed_search),
                                 pair_max=pair_max)
                if res is None:
                    continue
                c = _scanned(res, ses, freqs, key, harmonics, side, sp, f1, speed_search,
                             np.log(len(models)) + np.log(n_sp), (lo, hi) != SPEED_SCAN)
                if c is not None and not on_grid(ses, [hz for hz, _ in c[1]["lines"]], hunting_hz):
                    found.append((c[0], dict(c[1], family=name, factor_window=(lo, hi) in FACTOR_WINDOWS)))
    return found


def _declared_best(ses: _SES, freqs: dict, f1: float, speed_search: float, n_sp: int) -> float:
    """The best log p (at most 0) one spectrum gives the declared speed: every family at its +-SLIP and,
    every line scaled alike, anywhere within the 1X search (``_speed_scan``)."""
    declared = 0.0
    for name in FAMILIES:
        res = _on_base(ses, name, freqs, f1)
        # a comb with lines halfway between its harmonics speaks for half the speed, not this one
        if res is not None and res.get("halves", 0) < HALVES:
            declared = min(declared, res["logp"] + np.log(n_sp))
    pair_max = _pair_max(ses.r_base if ses.r_base is not None else ses.r)
    for name, (key, models) in FAMILIES.items():
        for harmonics, side in models:
            sp = None if side is None else (f1 if side == "1X" else freqs["FTF"],)
            # within the 1X search a comb only says the speed is somewhat off (the declared speed
            # stands, as with a 1X found there): it counts for the declared speed
            near = _scan_comb(ses, freqs[key], harmonics, sp, -speed_search, speed_search, pair_max=pair_max)
            if near is not None and _halves(ses, freqs[key] * near[1], harmonics, base=True) < HALVES:
                declared = min(declared, near[0] + np.log(len(models)) + np.log(n_sp))
    return declared


def _rival(found: list, declared: float) -> dict | None:
    """The best comb of ``found`` (sorted (log p, comb)) within FACTOR_WINDOWS, significant and not
    SPEED_SCAN_MARGIN weaker than the declared speed's best (log p ``declared``), or None."""
    for lp, c in found:
        if c["factor_window"]:
            if lp < np.log(ALPHA) and lp < declared - np.log(SPEED_SCAN_MARGIN):
                return {"factor": c["factor"], "family": c["family"], "model": c["model"],
                        "p_value": float(np.exp(lp)), "declared_p_value": float(np.exp(declared))}
            return None
    return None


def _scanned(res, ses, freqs, key, harmonics, side, sp, f1, speed_search, penalty, factor_window=False):
    """(log p, comb) of a scanned comb ``res`` (``_scan_comb``) that may contradict the declared speed:
    at least two lines standing, one a carrier at a first-three harmonic, no gap over one harmonic; not
    a shaft's comb within the 1X search (``_shaft_like``) nor, outside the ``factor_window`` of 0.5 or 2,
    carriers all at the declared speed's bearing lines (``_declared``). Near a factor of 2 every line of
    a comb is a harmonic of a line of the same family at the other speed, so that exclusion would take
    every comb: there the margin over the declared speed's best comb alone decides (the comb with all its
    harmonics beats the one that sees every second of them). None otherwise. ``penalty``: log of the
    models and spectra tried."""
    logp, u, vals, terms = res
    logp += penalty
    standing = [(h, k) for (h, k), v in zip(terms, vals) if v >= ses.r_line]
    if (len(standing) < 2 or not any(k == 0 and h <= 3 for h, k in standing)
            or _step(h for h, k in standing) > 1.0 or _halves(ses, freqs[key] * u, harmonics, base=True) >= HALVES):
        return None
    spacing = 0.0 if side is None else sp[0] * u
    lines = [(round(float(h * freqs[key] * u + k * spacing), 2), round(float(10 * np.log10(v)), 1))
             for (h, k), v in zip(terms, vals) if v >= ses.r_line]
    carriers = [h * freqs[key] * u for h, k in standing if k == 0]
    if _shaft_like([hz for hz, _ in lines], f1, speed_search, ses.freq[1]) or (
            not factor_window and _declared(carriers, freqs, ses.freq[1])):
        return None
    return logp, dict(factor=u, model=f"{key} x {','.join(f'{h:g}' for h in harmonics)}" + (f" +-{side}" if side else ""),
                      p_value=float(np.exp(logp)), lines=lines, channel=ses.channel, preprocessing=ses.prep)
