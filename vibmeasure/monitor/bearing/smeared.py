"""Step 6, smeared ball: a ball whose spin wanders spreads its lines into humps at 2 x BSF x 1-3; a
band-energy test against its Gamma law and decoy combs."""

from __future__ import annotations

import numpy as np

from .lines import _log_gamma_sf
from .rules import ALPHA, MIN_VOTES, SINGLE_VIEW_P, SLIP
from .spectra import _SES

# --- a ball's smeared comb ---------------------------------------------------------------------------
# A ball's spin wanders (its axis tilts, it skids in and out of the load zone), so the lines of a ball
# defect may spread over a few per cent where a race defect's, locked to the cage and the shaft, stay
# sharp: the line test (2 bins a line) then sees nothing, and the envelope holds a hump at 2 x BSF and its
# harmonics instead. The band-energy test below looks for that comb of humps; it is asked only where no
# family's lines pass and no race family is significant (``_smeared_ball``). Measured on the channels'
# mean (benchmarks/ball_smear.py, log10 p uncorrected): with the races' lines and sidebands left out, the
# CWRU fan-end ball records B007_1, B014_1 and B007_2, which show no line comb, stand at -48, -35 and -21
# (best decoy -14, -1.7, -3.6); every race record, real or synthetic, at -7.2 or above (MFPT's inner race
# at load 3, whose BPFI is found first), healthy ones at -1.5 or above. Without leaving the races out,
# race records reach -143 (IR021_0): on the 6203, BPFO + 1X and BPFI - 1X lie 1.6 % and 1.0 % from 2 x BSF.
SMEAR_WIDTH = 0.015    # each hump: +-1.5 % of its centre
SMEAR_EXCL = 0.01      # bins within 1 % of a race line (BPFO, BPFI x 1-12, with +-1X and +-2X) are left out
SMEAR_FLOOR_HZ = 40.0  # the floor: a running median over +-40 Hz, wider than a hump
SMEAR_MARGIN = 5.0     # decades: the comb's p-value stands this far below the best decoy comb's
SMEAR_SLIPS = 9        # common slips searched within +-SLIP
# a smear spreads its energy over a hump's bins; a sharp line inside a hump (another shaft's harmonic)
# fills it from one place. So a hump stands only where its sum, its loudest bin and SMEAR_LINE_BINS either
# side (a Hann line's main lobe and first sidelobe) left out, is still at p below SMEAR_HUMP_P against
# its own Gamma law, and a comb needs SMEAR_HUMPS such humps. A healthy 61/19 gearbox's pinion (96.3 Hz)
# puts its third harmonic, 75 x the floor, in the second hump of a 6205's 2 x BSF comb at +1 % slip:
# that hump read p = 2e-14 and the comb was called ball at 0.95; without its line the hump reads 0.04.
# The CWRU fan-end ball records called from their humps keep a hump without its loudest line at 1e-4
# (B007_2's fan-end channel) to 1e-18 (B007_1's drive end); on the base channel alone B014_0 and B014_1
# show one hump each, 6e-4 and 2e-7 without it.
SMEAR_LINE_BINS = 2
SMEAR_HUMPS = 1
SMEAR_HUMP_P = 0.01
# a sum of Hann-windowed periodogram bins varies this much more than one of independent bins: the power
# correlation of neighbours is (0.25 / 0.375)^2, of next neighbours (0.0625 / 0.375)^2
HANN_VAR = 1.0 + 2.0 * ((0.25 / 0.375) ** 2 + (0.0625 / 0.375) ** 2)


def _wide_ratio(ses: _SES, freqs: dict, f1: float, races: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """The SES power over a wide floor (running median of +-SMEAR_FLOOR_HZ, taken on blocks of about
    2 Hz), scaled to mean 1 over the bins kept; and which bins are kept: not within 2 bins of a shaft
    harmonic, 1 bin of a cage harmonic, nor (``races``) SMEAR_EXCL of a race line or its +-1X and +-2X
    sidebands."""
    from scipy.ndimage import median_filter
    n = ses.n_valid
    P = ses.amp[:n].astype(float) ** 2
    df = float(ses.freq[1])
    blk = max(1, int(round(2.0 / df)))
    nb = n // blk
    if nb < 3:   # too short a spectrum for a floor of blocks: no bin is kept, no comb is found
        return np.ones(n), np.zeros(n, bool)
    med = np.median(P[: nb * blk].reshape(nb, blk), axis=1)
    med = median_filter(med, size=2 * max(1, int(round(SMEAR_FLOOR_HZ / (blk * df)))) + 1, mode="nearest")
    floor = np.interp(np.arange(n), (np.arange(nb) + 0.5) * blk, med)
    r = P / np.maximum(floor, 1e-300)
    keep = np.ones(n, bool)
    keep[: max(3, int(5.0 / df))] = False
    for hz, half in ((f1, 2), (freqs["FTF"], 1)):
        for k in range(1, int(n * df / hz) + 1):
            i = int(round(k * hz / df))
            keep[max(0, i - half): i + half + 1] = False
    for key in ("BPFO", "BPFI") if races else ():
        for h in range(1, 13):
            for sb in (-2, -1, 0, 1, 2):
                c = h * freqs[key] + sb * f1
                if c > 0:
                    keep[max(0, int(c * (1 - SMEAR_EXCL) / df)): max(0, int(c * (1 + SMEAR_EXCL) / df) + 1)] = False
    scale = float(r[keep].mean()) if keep.any() else 1.0
    return r / max(scale, 1e-300), keep


def _broad_log_p(r: np.ndarray, sel: np.ndarray, shape: float) -> float:
    """log p of a hump's sum over its kept bins with its loudest bin and SMEAR_LINE_BINS either side
    left out (Gamma law as ``_smear_comb``'s): what stands of it without its sharpest line."""
    sel = sel.copy()
    if sel.any():
        top = int(np.argmax(np.where(sel, r, -np.inf)))
        sel[max(0, top - SMEAR_LINE_BINS): top + SMEAR_LINE_BINS + 1] = False
    total, m = float(r[sel].sum()), int(sel.sum())
    return _log_gamma_sf(total * shape / HANN_VAR, m * shape / HANN_VAR) if total > 0 and m else 0.0


def _smear_comb(r: np.ndarray, keep: np.ndarray, df: float, f0: float, shape: float) -> tuple[float, float, list]:
    """(log p, slip, [(centre Hz, mean ratio, the hump's ``_broad_log_p``)]) of the best comb of humps at f0
    x 1-3 over the common slips searched; under noise the sum over M kept bins of a mean of ``shape``
    spectra is about Gamma(M shape / HANN_VAR) x HANN_VAR / shape (moment-matched for the window's
    correlation)."""
    best = (0.0, 0.0, [])
    for s in np.linspace(-SLIP, SLIP, SMEAR_SLIPS):
        tot, m, bands = 0.0, 0, []
        for h in (1, 2, 3):
            c = h * f0 * (1 + s)
            lo, hi = int(c * (1 - SMEAR_WIDTH) / df), int(c * (1 + SMEAR_WIDTH) / df) + 1
            if hi >= r.size:
                break
            sel = keep[lo:hi]
            hump, mh = float(r[lo:hi][sel].sum()), int(sel.sum())
            tot += hump
            m += mh
            bands.append((c, hump / mh if mh else 0.0, (lo, hi)))
        if m < 10 or len(bands) < 2:
            continue
        k = m * shape / HANN_VAR
        logp = _log_gamma_sf(tot * shape / HANN_VAR, k) if tot > 0 else 0.0
        if logp < best[0]:
            best = (logp, float(s), bands)
    # each hump without its loudest line, at the best slip only (the decoys' many slips need none)
    return best[0], best[1], [(c, mean, _broad_log_p(r[lo:hi], keep[lo:hi], shape)) for c, mean, (lo, hi) in best[2]]


def _smear_decoys(freqs: dict, f1: float) -> np.ndarray:
    """Decoy fundamentals (0.55-1.8 x 2 x BSF, steps of 0.5 %) whose harmonics 1-3 stay 4 % from every
    bearing line: 16-19 for the CWRU bearings. Neighbours share most of their humps' bins, so the best of
    them is a strict null: with 7 decoys in 2 % steps, a hump comb of the 6205's 2 x BSF on fan-end
    B007_3 (136, 272, 408 Hz at +2.5 to +3 dB, p = 2.8e-9) passed; with these it does not."""
    lines = np.array([h * freqs[key] + sb * f1 for key in ("BPFO", "BPFI", "2xBSF", "BSF") for h in range(1, 12)
                      for sb in ((-1, 0, 1) if key == "BPFI" else (0,))])
    f0 = freqs["2xBSF"]
    u = np.linspace(0.55, 1.8, 240)
    return np.array([f0 * m for m in u
                     if all(np.min(np.abs(lines - h * f0 * m)) > 0.04 * h * f0 * m for h in (1, 2, 3))])


def _smeared_ball(spectra: list, freqs: dict, f1: float) -> dict | None:
    """The ball family's smeared comb, asked of the cepstral whole-band spectrum of each channel and of
    their mean: in each view its p-value (corrected for the slips and the views searched) and the best
    decoy's. Found where it passes (p below ALPHA and SMEAR_MARGIN decades under the best decoy) in
    MIN_VOTES views, or in the only one the record offers, or in one with p below SINGLE_VIEW_P."""
    views = [s for s in spectra if s.prep == "cepstral"]
    if not views:
        return None
    df = float(views[0].freq[1])
    decoys = _smear_decoys(freqs, f1)
    ratios = [_wide_ratio(s, freqs, f1) for s in views]
    entries = [(s.channel, s.prep, s.band, r, k, 1.0) for s, (r, k) in zip(views, ratios)]
    if len(views) > 1:
        n = min(r.size for r, _ in ratios)
        keep = np.all([k[:n] for _, k in ratios], axis=0)
        fused = [s for s in spectra if s.prep.startswith("cepstral (channels fused")]
        entries.append(("+".join(s.channel for s in views), fused[0].prep if fused else "cepstral (channels fused)",
                        fused[0].band if fused else views[0].band,
                        np.mean([r[:n] for r, _ in ratios], axis=0), keep, float(len(views))))
    out = []
    correction = np.log(SMEAR_SLIPS) + np.log(len(entries))
    for channel, prep, band, r, keep, shape in entries:
        logp, slip, bands = _smear_comb(r, keep, df, freqs["2xBSF"], shape)
        dec = [_smear_comb(r, keep, df, d, shape)[0] for d in decoys]
        best_decoy = min(dec, default=0.0)
        logp_c = min(0.0, logp + correction)
        humps = sum(lp < np.log(SMEAR_HUMP_P) for _, _, lp in bands)
        passes = bool(logp_c < np.log(ALPHA) and logp <= best_decoy - SMEAR_MARGIN * np.log(10)
                      and humps >= SMEAR_HUMPS)
        out.append({"channel": channel, "preprocessing": prep, "band_hz": band, "log_p": logp_c, "slip": slip,
                    "bands": bands, "humps": humps, "decoy_log_p": best_decoy, "passes": passes,
                    "decoy_p": float((1 + sum(d <= logp for d in dec)) / (1 + len(dec)))})
    best = min(out, key=lambda e: e["log_p"])
    n_pass = sum(e["passes"] for e in out)
    best["views"] = n_pass
    best["found"] = bool(best["passes"] and (n_pass >= min(MIN_VOTES, len(views))
                                             or best["log_p"] < np.log(SINGLE_VIEW_P)))
    return best


def _call_smeared(fam: dict, sm: dict, freqs: dict):
    """The ball family's summary where its smeared comb is found: p-value, slip, the humps (centre, mean
    ratio over its bins), the view and its decoys."""
    f0 = freqs["2xBSF"] * (1 + sm["slip"])
    fam.update(found=True, log_p=sm["log_p"], p_value=float(np.exp(sm["log_p"])),
               log10_p=float(sm["log_p"] / np.log(10)), slip=sm["slip"], found_hz=float(f0),
               model=f"2xBSF x 1,2,3 smeared (humps +-{100 * SMEAR_WIDTH:g} %)", channel=sm["channel"],
               preprocessing=sm["preprocessing"], band_hz=sm["band_hz"], decoy_p=sm["decoy_p"],
               lines=[{"harmonic": float(h), "sideband": 0, "hz": float(c), "r": float(m),
                       "db": float(10 * np.log10(max(m, 1e-12)))} for h, (c, m, _) in enumerate(sm["bands"], 1)],
               evidence_db=float(np.mean([10 * np.log10(max(m, 1e-12)) for _, m, _ in sm["bands"]])),
               n_lines=0, votes=sm["views"], views=sm["views"])
