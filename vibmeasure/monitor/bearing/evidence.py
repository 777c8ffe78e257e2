"""Steps 4-5, test and decide over every spectrum of the record: ``bearing_evidence``."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...core._threads import each_in_threads
from ...core._validate import positive
from ...core.errors import ParameterError
from .cage import _cage_floor
from .decoys import _decoy_p, _speed_scan
from .families import HALVES, _accepted, _claim_artefact, _claim_shaft, _explain, _shaft_shows
from .grid import HUNT_TOL, HUNT_TOL_MAX, on_grid
from .lines import _log_p_to_conf
from .rules import ALPHA, FAMILIES, MIN_VOTES, R_LINE, SAME_DATA, SINGLE_VIEW_P, SLIP
from .smeared import _call_smeared, _smeared_ball
from .spectra import WHITENING, _fused, _spectra

# a race's fault makes a comb of sharp lines at a fixed frequency, far above combs of the same shape at
# other fundamentals (every race call on the development records beats all 120 decoys, p = 1/121); where
# more than this share of decoys score as well, the spectrum's own lines make such combs by chance (a
# gearbox's two gears repeat together every hunting-tooth period: lines every f1 x the teeth's common
# factor / the mating gear's teeth)
RACES = ("bearing_outer_race", "bearing_inner_race")
RACE_DECOY_P = 0.05


@dataclass(frozen=True)
class BearingEvidence:
    """What the bearing test found in one record.

    Attributes
    ----------
    families : dict
        Family name (``FAMILIES`` and ``"bearing_cage"``) -> summary: p_value, log10_p, confidence,
        slip, found_hz, lines, channel, preprocessing, band_hz, found (bool), votes, views, not_called.
    spectra : list
        Every squared-envelope spectrum searched (``spectra._SES``), the fused views last.
    kurtogram : Kurtogram or None
        The first channel's kurtogram.
    n_spectra : int
        How many spectra were searched (the p-values are corrected for them).
    measured_top_hz : dict
        Channel -> upper edge of the band it measures (below an anti-alias filter's edge).
    speed_scan : dict or None
        A comb that stands where another speed puts it and contradicts the declared speed.
    factor_rival : dict or None
        The best significant comb near 0.5 or 2 x the speed that does not contradict it, when it is
        not SPEED_SCAN_MARGIN weaker than the declared speed's best: {"factor", "family", "model",
        "p_value", "declared_p_value"} (``decoys._speed_scan``).
    """

    families: dict
    spectra: list
    kurtogram: object
    n_spectra: int
    measured_top_hz: dict
    speed_scan: dict | None
    factor_rival: dict | None = None


def bearing_evidence(signals: dict, fs: float, f1: float, freqs: dict, n_balls: int, *, band=None,
                     shaft_hz: float | None = None, f1_known: bool = True, whitening=("cepstral",),
                     artefact_hz=(), speed_search: float | None = None, speed_confirmed: bool | None = None,
                     smeared_ball: bool = True, other_shafts_hz=(), shaft_combs_hz=(),
                     hunting_hz: float | None = None, time_base_doubted: bool = False) -> BearingEvidence:
    """Evidence per bearing family over every channel of a record, as a statistical test.

    Parameters
    ----------
    signals : dict
        Channel name -> acceleration samples (1-D arrays of one length).
    fs : float
        Sampling rate in Hz.
    f1 : float
        Shaft speed in Hz.
    freqs : dict
        The bearing's frequencies at f1 (``Bearing.frequencies``: BPFO, BPFI, BSF, 2xBSF, FTF).
    n_balls : int
        Number of rolling elements.
    band : tuple of float, optional
        A demodulation band (Hz) of the user's, searched beside the record's own bands (the whole
        band, the kurtogram's and the infogram's): one view among them.
    shaft_hz : float, optional
        The shaft frequency whose harmonics are claimed first (default f1).
    f1_known : bool
        Whether a 1X line measured f1.
    whitening : tuple of str
        Pre-processings searched: "cepstral" and/or "ar".
    artefact_hz : tuple of float
        Fundamentals of combs the recording chain made (spikes every P samples: fs / P), claimed first.
    speed_search : float, optional
        How far (share of f1) the caller looked for the 1X; given, the bearing's lines are also
        searched at other speeds (``decoys._speed_scan``: from 0.5 to 2 x f1, or near 0.5 and 2 x
        alone where ``speed_confirmed``).
    speed_confirmed : bool, optional
        Whether the speed is confirmed (default ``f1_known``).
    smeared_ball : bool
        Ask for the ball's smeared comb where no family passes; off where the speed varies unfollowed.
    other_shafts_hz : tuple of float
        Speeds (Hz) of the machine's other shafts (a gearbox's mating shaft): their harmonics are claimed
        like this shaft's, so that a second shaft's comb is not taken for a bearing's.
    shaft_combs_hz : tuple of float
        Fundamentals (Hz) of shaft combs the caller saw in the direct spectrum where the speed is in
        doubt (a comb at 2, 3 or 4 x a declared speed no 1X confirms): every harmonic is claimed, even
        where a bearing line could stand, since whichever speed is true they are a shaft's lines.
    hunting_hz : float, optional
        The spacing (Hz) of a gear pair's hunting-tooth comb (f1 x gcd(z1, z2) / z2): a family whose
        standing lines all lie on it is not found (``grid.grid_tolerance``).
    time_base_doubted : bool
        The speed step found the lines fit only at another fs (``shaft_hz`` then differs from f1), or a
        shaft comb standing at another speed (``shaft_combs_hz``): the scan of other speeds leaves out
        4 x f1 (``decoys.UNCONFIRMED_WINDOWS``); that doubt names the speed and the test runs there too.

    Returns
    -------
    BearingEvidence

    Raises
    ------
    ParameterError
        When ``whitening`` selects no pre-processing, or a speed in ``other_shafts_hz`` or
        ``shaft_combs_hz`` is not a positive finite number.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> from vibmeasure.monitor.bearing import bearing_evidence
    >>> rec = vm.synth.machine(fault="bearing_outer_race", rpm=1797, fs=12000.0, duration=4.0, seed=1)
    >>> b = vm.BEARINGS["6205-2RS"]
    >>> ev = bearing_evidence({"a": rec.data[0]}, 12000.0, 1797 / 60, b.frequencies(1797 / 60), b.n_balls)
    >>> bool(ev.families["bearing_outer_race"]["found"])
    True
    """
    other_shafts_hz = tuple(positive(hz, "other_shafts_hz") for hz in other_shafts_hz)
    shaft_combs_hz = tuple(positive(hz, "shaft_combs_hz") for hz in shaft_combs_hz)
    spectra, measured = _explained_spectra(signals, fs, f1, freqs, n_balls, band, whitening, artefact_hz,
                                           shaft_hz or f1, f1_known, other_shafts_hz, shaft_combs_hz)
    hunting_hz = None if hunting_hz is None else positive(hunting_hz, "hunting_hz")
    fams, votes = _family_summaries(spectra, freqs, hunting_hz)
    smeared = _smeared_if_none(fams, spectra, freqs, f1) if smeared_ball else None
    _confidences(fams, votes, smeared, len(spectra), _views(spectra))
    confirmed = f1_known if speed_confirmed is None else speed_confirmed
    other, rival = (None, None) if speed_search is None else _speed_scan(spectra, freqs, f1, speed_search, confirmed,
                                                                           hunting_hz, not time_base_doubted)
    kurtogram = next((s.kurtogram for s in spectra if s.kurtogram is not None), None)
    return BearingEvidence(fams, spectra, kurtogram, len(spectra), measured, other, rival)


def _explained_spectra(signals, fs, f1, freqs, n_balls, band, whitening, artefact_hz, shaft_hz, f1_known,
                       other_shafts_hz=(), shaft_combs_hz=()):
    """Every channel's SES (cage floor divided out before the channels are fused), the fused views,
    and on each the lines explained by the shaft, artefacts, the cage and the families."""
    spectra, measured = [], {}
    each = each_in_threads(lambda item: _spectra(item[1], fs, item[0], f1, freqs, band, whitening), signals.items())
    for name, (sp, measured[name]) in zip(signals, each):
        for s in sp:   # before the channels are fused, so that a mean carries each channel's floor
            _cage_floor(s, freqs, f1, n_balls)
        spectra.extend(sp)
    # the shaft claims the harmonics a bearing line could also be (``_contested``) only when one of the
    # spectra (any channel: one shaft turns under every sensor) shows it on its own, at a harmonic no
    # bearing line explains: a bearing whose fault line falls on a shaft harmonic (the 6203's 2 x BSF
    # is 3.987 X, one bin from 4X on a 4 s record) then keeps that line and its multiples
    shaft = any(_shaft_shows(s, shaft_hz, f1_known, freqs) for s in spectra)
    # another shaft (its speed known from the gear ratio) claims its harmonics by the same rule
    others = [(hz, any(_shaft_shows(s, hz, True, freqs, f1) for s in spectra)) for hz in other_shafts_hz]
    others += [(hz, True) for hz in shaft_combs_hz]
    spectra += _fused(spectra)
    for s in spectra:
        for g in artefact_hz:
            _claim_artefact(s, g)
        for hz, shows in others:
            _claim_shaft(s, hz, True, freqs, contested=shows, own_f1=f1)
        _explain(s, freqs, f1, shaft_hz, f1_known, n_balls, shaft=shaft)
    if not spectra:
        raise ParameterError(f"whitening={whitening!r} selects no pre-processing; choose from {WHITENING}")
    return spectra, measured


def _family_summaries(spectra, freqs, hunting_hz=None) -> tuple[dict, dict]:
    """Each family's evidence (where it claimed first; else where it is strongest), its decoy p, votes
    and views; a family that claims first nowhere, or in one view only, is not found."""
    n_sp = len(spectra)
    votes = {name: [s for s in spectra if s.primary == name] for name in FAMILIES}
    n_views = _views(spectra)   # how many distinct views the record offers (one with a user's band= and channel)
    fams = {}
    for name in list(FAMILIES) + ["bearing_cage"]:
        key = "FTF" if name == "bearing_cage" else FAMILIES[name][0]
        pool = votes.get(name) or spectra
        best, where = None, None
        for s in pool:
            res = s.results.get(name)
            if res is not None and (best is None or res["logp"] < best["logp"]):
                best, where = res, s
        fams[name] = _summary(name, key, best, where, freqs, n_sp)
        if name in FAMILIES and best is not None and "spec" in best:
            fams[name]["decoy_p"] = _decoy_p(where, best, freqs[key], freqs)
        fams[name]["votes"] = len(votes.get(name, ()))
        # a user's band adds no view of its own (``spectra._candidates``): it may confirm what the record's
        # bands show, and alone it is one view
        own = [s for s in votes.get(name, ()) if not s.given]
        fams[name]["views"] = max(_views(own), 1 if len(own) < len(votes.get(name, ())) else 0)
        fams[name]["band_given_only"] = bool(votes.get(name)) and not own
        # the family's strength in the record's own spectra: what may stand in the way of another finding
        own_p = [s.results[name]["logp"] for s in (own or [s for s in pool if not s.given])
                 if s.results.get(name) is not None]
        fams[name]["log_p_own"] = min(0.0, min(own_p, default=0.0) + np.log(n_sp))   # corrected as _summary's
        if name in FAMILIES and not votes[name]:
            fams[name]["found"] = False   # only ever significant on lines another family explains better
        elif name in FAMILIES and _one_view(fams[name], fams[name]["views"], n_views):
            fams[name]["found"] = False
        elif name in RACES and fams[name]["found"] and fams[name].get("decoy_p", 0.0) > RACE_DECOY_P:
            fams[name]["found"] = False
            fams[name]["chance_comb"] = True
        elif name in FAMILIES and fams[name]["found"] and _on_hunting_grid(where, fams[name], hunting_hz):
            fams[name]["found"] = False
            fams[name]["hunting_comb"] = hunting_hz
    # a family only the user's band claims is no call against one the record's own bands call: a band
    # that misses the bearing's resonance demodulates clutter (CWRU fan-end OR007@3_1, outer race at 1.00
    # in its own bands, read as ball in 300-900 Hz and inner race in 4.2-5.4 kHz)
    own = [n for n in FAMILIES if fams[n]["found"] and not fams[n]["band_given_only"]]
    for name in FAMILIES:
        if own and fams[name]["found"] and fams[name]["band_given_only"]:
            fams[name]["found"] = False
            fams[name]["against_own"] = own
    return fams, votes


def _on_hunting_grid(ses, fam: dict, spacing: float | None) -> bool:
    """Whether every standing line of a family's comb (two or more) lies on the hunting-tooth grid
    (``grid.on_grid``)."""
    return on_grid(ses, [ln["hz"] for ln in fam["lines"] if ln["r"] >= ses.r_line], spacing)


def _smeared_if_none(fams, spectra, freqs, f1):
    """No family's lines pass and no race's are significant: is the ball's comb there, smeared?"""
    # a comb that only a user's band shows (``band_given_only``, or significant in none of the record's
    # own spectra: ``log_p_own``) does not stand in the way
    if any(fams[n]["found"] and not fams[n].get("band_given_only") for n in FAMILIES) or any(
            fams[n].get("log_p_own", fams[n]["log_p"]) < np.log(ALPHA) and not fams[n].get("band_given_only")
            for n in FAMILIES if n != "bearing_ball"):
        return None
    smeared = _smeared_ball(spectra, freqs, f1)
    if smeared is not None:
        fams["bearing_ball"]["smeared"] = smeared
        if smeared["found"]:
            _call_smeared(fams["bearing_ball"], smeared, freqs)
    return smeared


def _confidences(fams, votes, smeared, n_sp, n_views):
    """Each family's confidence: the posterior from its p-value, times its share of the spectra's votes
    (each spectrum votes with the weight of its evidence, -log p, for the family that claimed first),
    times the share of decoy combs it beats on its own spectrum; and why a comb was not called."""
    weight = {n: sum(-s.results[n]["logp"] for s in votes[n]) for n in FAMILIES}
    # a family only the user's band shows, refused against the record's own (``_family_summaries``),
    # casts no votes against them
    total = sum(w for n, w in weight.items() if not fams[n].get("against_own"))
    names = list(FAMILIES)
    conf = _log_p_to_conf(np.array([fams[n]["log_p"] if fams[n]["found"] else 0.0 for n in names]))
    for n, c in zip(names, conf):
        share = weight[n] / total if total > 0 else 0.0
        if n == "bearing_ball" and smeared is not None and smeared["found"]:
            share = 1.0   # no family's lines pass: the line spectra's votes speak for no other family
        fams[n]["agreement"] = share
        fams[n]["confidence"] = float(c * share * (1.0 - fams[n].get("decoy_p", 1.0)))
    fams["bearing_cage"]["confidence"] = 0.0
    for n in names:
        fams[n]["not_called"] = _not_called(n, fams[n], n_sp, n_views)


def _views(spectra) -> int:
    """How many distinct views of the record the spectra are: spectra of other channels (or channel
    sets) are distinct; two of one channel are distinct when their bands share at most SAME_DATA of
    their union. (Low-passed at 0.6 x Nyquist, B021_3's fan-end channel has its whole band at 1.4-4.0
    kHz and its kurtogram band at 2.0-4.0 kHz, 77 % shared: one view, whose false BPFO comb both
    showed. The two-spectrum calls on the development-record variants that were right shared 2-44 %.)

    A fused view (the mean of several channels' spectra, each in its band: ``_SES.sources``) is the
    view of one of its channels again where that channel's own spectrum, in a band sharing more than
    SAME_DATA with the band it has in the fusion, is among ``spectra``: a comb one channel holds alone
    stands in the mean too, diluted. (With a 0.05 s burst, B021_3's fan-end infogram band at 2-4 kHz
    showed a BPFO comb, p = 3e-9 per spectrum, and the drive-end and fan-end channels fused, each in its
    infogram band, showed it again: two views, and the ball fault was called outer race at 1.00.) Fused
    views of other channel sets stay distinct: where no channel shows a comb alone, each fusion adds up
    other channels' weak evidence (B014_3's ball comb, per spectrum: p = 4e-11 with the three channels
    fused, 1e-6 with two fused in 3-6 kHz, at best 3e-3 in one channel)."""
    kept = []
    for s in spectra:
        if not any(_same_data(s, k) for k in kept):
            kept.append(s)
    return len(kept)


def _shared(a: tuple, b: tuple) -> bool:
    """Whether bands a and b share more than SAME_DATA of their union."""
    return max(0.0, min(a[1], b[1]) - max(a[0], b[0])) > SAME_DATA * (max(a[1], b[1]) - min(a[0], b[0]))


def _same_data(a, b) -> bool:
    """Whether spectra a and b are one view (``_views``)."""
    if len(a.sources) > 1 and len(b.sources) > 1:
        return a.channel == b.channel and _shared(a.band, b.band)
    return any(ca == cb and _shared(ba, bb) for ca, ba in a.sources for cb, bb in b.sources)


def _one_view(fam: dict, views: int, n_views: int) -> bool:
    """Is a family's evidence too thin for a call because one view of the record alone holds it (views:
    how many distinct views claim it first, ``_views``; n_views: how many the record offers)? A view is one channel (or the channels fused) in one band; a
    fault shows in two, for instance in the whole band and in the band the kurtogram picks, or in two
    channels. The p-value assumes the SES floor is noise, but real recordings carry structured clutter
    (other machine parts, electrical lines), and a band picked out of the kurtogram's tree finds it.
    Measured on the variants of the development records (benchmarks/diagnosis_robustness.py: cut,
    low-passed, with a tone, with noise), calls resting on one spectrum were right 5 times and wrong 7
    times, with p from 6e-7 to 3e-4 for the wrong ones; calls in two spectra or more were right 398
    times and wrong once (two spectra of one channel whose bands were 77 % the same, ``_views``). So one
    view is enough only with overwhelming evidence, SINGLE_VIEW_P: a fault in a narrow resonance band
    of a single-channel record at 0 dB (synthetic, 4 s at 64 kHz) reaches p = 1e-35 to 1e-60 there and
    next to nothing in the whole band.

    A record that offers one view only (one channel whose measured band is too narrow for a kurtogram
    band of its own) gets no waiver: its evidence cannot be checked in another view either. A healthy
    19/61 gearbox whose mesh filled the spectrum to 1.8 kHz read as band-limited, and the wheel's 15th
    and 30th orders (93.4, 186.8 Hz, where a 6205's 2 x BSF and its double fall) were called ball at 1.00
    with p = 1e-8 in that one view (benchmarks/gearbox.py). ``n_views`` names the views in the reason."""
    return views < MIN_VOTES and fam["log_p"] >= np.log(SINGLE_VIEW_P)


def _not_called(name: str, fam: dict, n_sp: int, n_views: int) -> str | None:
    """Why a family with a comb was not called, in the terms of the decision rule (None when it was
    called or has no comb at all)."""
    if fam["found"] or fam["n_terms"] == 0:
        return None
    why = []
    if fam["p_value"] >= 0.1:
        why.append(f"no comb stands above the floor (p = {fam['p_value']:.2g})")
    elif fam["log_p"] >= np.log(ALPHA):
        why.append(f"p = {fam['p_value']:.3g} is not below {ALPHA:g} (corrected for the {n_sp} spectra, the slips "
                   "and the sub-models searched)")
    if fam["n_lines"] < 2:
        why.append(f"{fam['n_lines']} line(s) stand {10 * np.log10(R_LINE):.1f} dB above the floor, 2 needed")
    elif fam.get("n_carriers", 1) < 1:
        why.append("no line at one of the first three harmonics of its own fundamental")
    elif fam.get("step", 1.0) == 2.0:
        why.append(f"its lines stand at even harmonics only: they make a comb at twice its fundamental "
                   f"({2 * fam['found_hz']:.1f} Hz), which is no frequency of this bearing")
    elif fam.get("step", 1.0) > 1.0:
        why.append(f"its lines stand only at multiples of its harmonic {fam['step']:g}: they make a comb at "
                   f"{fam['step']:g} x its fundamental ({fam['step'] * fam['found_hz']:.1f} Hz), which is no "
                   "frequency of this bearing")
    if fam.get("halves", 0) >= HALVES:
        why.append(f"lines stand also halfway between its harmonics: with them it is the even part of a comb at "
                   f"half its fundamental ({fam['found_hz'] / 2:.1f} Hz), no frequency of this bearing at the "
                   f"declared speed; at half that speed it is this family's own (check the speed for a factor 2: "
                   f"rpm for Hz, pulses per revolution)")
    if fam.get("denser"):
        why.append(f"its lines are one in every {fam['denser']} of a denser comb at "
                   f"{fam['found_hz'] / fam['denser']:.2f} Hz whose lines between stand as high: another shaft's "
                   "harmonics (a gearbox's other shaft, a belt's pulley), no frequency of this bearing; declare "
                   "a gearbox's other shaft (gear=vm.Gear(teeth, mating_shaft_ratio=...)) to have its harmonics "
                   "claimed")
    if fam.get("edge"):
        why.append(f"its comb fits best at the edge of the +-{100 * SLIP:g} % slip range, so it would fit better "
                   "further off: the lines are not where this bearing puts them (a shaft-order comb, another "
                   "family's sidebands)")
    if fam.get("modulation_sidebands") == 0:
        why.append("no +-1X sidebands (an inner-race defect turns through the load zone)"
                   if name == "bearing_inner_race" else
                   "no +-FTF sidebands (a ball defect travels with the cage)")
    if fam.get("chance_comb"):
        why.append(f"its spectrum makes such combs by chance: {100 * fam['decoy_p']:.0f} % of decoy combs at "
                   f"fundamentals that are no bearing frequency score as well (a race's comb needs at most "
                   f"{100 * RACE_DECOY_P:g} %): a dense line spectrum (two gears' hunting-tooth rate, a belt)")
    if fam.get("hunting_comb"):
        why.append(f"every line of its comb stands on the gears' hunting-tooth comb (a line every "
                   f"{fam['hunting_comb']:.3f} Hz: the two gears' tooth errors repeat together), within "
                   f"{HUNT_TOL:g}-{HUNT_TOL_MAX:g} of the spectrum's line spacing: the gearbox's lines, not the bearing's")
    if fam.get("against_own"):
        why.append(f"only the band given shows it, while the record's own bands show {', '.join(fam['against_own'])}")
    if not why and not fam["votes"]:
        why.append("its lines are explained first by another family, the shaft harmonics or the cage comb")
    elif not why and _one_view(fam, fam["views"], n_views):
        why.append(f"it shows in one view of the record only ({fam['votes']} of the {n_sp} spectra: "
                   f"{fam['preprocessing']} in {fam['channel']!r}); a call needs {MIN_VOTES} views (other "
                   f"channels, or bands that share at most half; channels fused are the view of one that shows it "
                   f"alone), or p below {SINGLE_VIEW_P:g} in one")
    return "; ".join(why) or None


def _summary(name, key, res, ses, freqs, n_sp) -> dict:
    expected = freqs[key]
    if res is None:
        return {"fault": name, "expected_hz": expected, "found": False, "log_p": 0.0, "p_value": 1.0,
                "statistic": 0.0, "n_terms": 0,
                "log10_p": 0.0, "slip": np.nan, "found_hz": None, "lines": [], "n_lines": 0, "channel": None,
                "preprocessing": None, "band_hz": None, "model": None, "amplitude": None, "evidence_db": 0.0,
                "modulation_sidebands": None}
    logp = min(0.0, res["logp"] + np.log(n_sp))
    df = ses.freq[1]
    f0 = expected * (1 + res["slip"])
    i = int(round(f0 / df))
    lines = [dict(ln, db=float(10 * np.log10(max(ln["r"], 1e-12)))) for ln in res["lines"]]
    main = [ln for ln in lines if ln["sideband"] == 0]
    ev_db = float(np.mean([ln["db"] for ln in main])) if main else 0.0
    found = bool(logp < np.log(ALPHA) and _accepted(res))
    # the cage comb's level where it carries the family's lines (``_cage_floor``: BPFO's harmonics, and
    # the harmonics it shares with BPFI or the ball family) within the slip searched around them
    under = [v[2] for ln in main for v in ses.cage_floor.values()
             if v[0] <= ln["harmonic"] * expected * (1 + SLIP) and v[1] >= ln["harmonic"] * expected * (1 - SLIP)]
    return {"fault": name, "expected_hz": expected, "found": found, "log_p": logp, "p_value": float(np.exp(logp)),
            "statistic": res["stat"], "n_terms": res["n_terms"],
            "log10_p": float(logp / np.log(10)), "slip": res["slip"], "found_hz": float(f0),
            "lines": lines, "n_lines": res["n_lines"], "n_carriers": res["n_carriers"], "edge": res.get("edge", False),
            "n_odd": res.get("n_odd", 1), "step": res.get("step", 1.0), "halves": res.get("halves", 0),
            "denser": res.get("denser", 0),
            "channel": ses.channel,
            "preprocessing": ses.prep,
            "band_hz": ses.band, "model": res.get("model"), "modulation_sidebands": res.get("modulation"),
            "amplitude": float(ses.amp[i]) if i < ses.amp.size else None, "evidence_db": ev_db,
            "cage_floor_db": float(10 * np.log10(max(under))) if under else None}
