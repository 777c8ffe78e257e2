"""Step: the gear, as a statistical test like the bearings'. The null is a healthy gearbox: a line at
teeth x 1X with its harmonics, modest sidebands at +-1 x either shaft's speed (eccentricity, runout and
the load's variation make them on every working gearbox), and each gear's random tooth-to-tooth errors,
which modulate the mesh at every order of its shaft. A local tooth fault (a crack, a broken or chipped
tooth) strikes once a turn of its shaft: it modulates the mesh with a short pulse, whose spectrum
spreads sidebands at +-2, 3, ... x that shaft's speed around every mesh harmonic, in phase. The test
counts those wider sidebands of each shaft against decoy spacings that are no shaft's speed, on the
same spectrum, and asks the shaft's synchronous residual to be more impulsive than residuals of the
same sideband spectrum with random timing (``gear_rows``)."""

from __future__ import annotations

import numpy as np

from .lines import LINE_DB, _line, _refine, _row

MESH_HARMONICS = (1, 2, 3)
WIDE_SIDEBANDS = (2, 3, 4, 5, 6)   # +-1 belongs to the healthy mesh; a tooth's pulse spreads to these
# of the 30 places (3 harmonics x 5 orders x 2 sides), beyond those halfway between: a local tooth fault
# at 0 dB fills 10-14 (synth.machine), a healthy machine with shaft-rate impacts (a rub) up to 5
MIN_SIDEBANDS = 6
N_DECOYS = 60
DECOY_P = 0.05          # the shaft's count must beat this share of decoy spacings (1/61 at best)
# FM4 (Stewart 1977): kurtosis of the time-synchronous average with the regular mesh removed (orders
# 0-2, each mesh harmonic and its +-1 sidebands). Identical teeth leave near-Gaussian residue (2.7-4.0 on
# synthetic healthy gearboxes); a local tooth fault's once-a-turn pulse makes it impulsive (6-10 on
# synthetic ones); random tooth errors of 2-10 % read 4-8 (a modulated carrier is no Gaussian), hence
# the surrogate test below. Sidebands that stand without both are a distributed modulation (tooth
# errors, run-out with harmonics, an off-centre gear) or a speed that wanders.
FM4_FAULT = 4.0
MIN_REVOLUTIONS = 10    # revolutions the synchronous average needs
# FM4 must also beat residuals of the same sideband spectrum with random timing (``impulsiveness``).
# A confident call needs p <= IMPULSE_P: a diagnosis tests both shafts and a fleet diagnoses many
# gearboxes, so a level of 0.005 calls a healthy gear at full confidence about once in a hundred
# diagnoses (on 90 synthetic healthy gearboxes with 2-10 % random tooth errors the smallest p read
# 0.0049: a 23-tooth pinion with one tooth 3.05 sigma off). Local tooth faults at 0 and 10 dB read
# p <= 0.001 on 31 of 60 gearboxes, <= 0.002 on 36 (7,999 surrogates): 0.002 is the level taken.
# N_SURROGATES resolves p well below it.
N_SURROGATES = 1999
SURROGATE_CHUNK = 250   # surrogates a pass: bounds memory at 4096 samples a turn
# the draw stops once this many surrogates reach FM4: p is then above 50 / 2,000 = 0.025, far from
# IMPULSE_P, and known to about 15 % (a sequential Monte Carlo test, after Besag & Clifford 1991)
SURROGATES_ENOUGH = 50
IMPULSE_P = 0.002
TOOTH_ERRORS_P = 0.05   # above it, the residual is as random tooth errors make it: wide sidebands are no fault
SURROGATE_SEED = 20261129


def _phase_bins(n: int, fs: float, f_shaft: float, per_rev: int) -> np.ndarray:
    """Each sample's bin of shaft phase (per_rev bins a turn) at the constant speed f_shaft."""
    return np.minimum(((np.arange(n) * (f_shaft / fs)) % 1.0 * per_rev).astype(np.int64), per_rev - 1)


def _synchronous_average(x: np.ndarray, j: np.ndarray, per_rev: int) -> np.ndarray:
    return np.bincount(j, weights=x, minlength=per_rev) / np.maximum(np.bincount(j, minlength=per_rev), 1)


def _residual(x: np.ndarray, fs: float, f_shaft: float, mesh_order: float, others=()) -> tuple | None:
    """(order spectrum, samples a turn) of x's synchronous residual at f_shaft (``residual_moments``)."""
    # the mesh harmonics a turn's samples hold (with +-3 orders): a mesh above a third of Nyquist has its
    # third harmonic folded or filtered away, and the average is taken on the harmonics below (a 40-tooth
    # gear at 3600 rpm, 12 kHz: 200 samples a turn hold harmonics 1 and 2; asking for the third left every
    # such gearbox without FM4, its sidebands alone holding the gear at 0.45)
    held = [m for m in MESH_HARMONICS if 2 * (m * mesh_order + 3) <= 2 * int(fs / f_shaft / 2)]
    if not held or x.size * f_shaft / fs < MIN_REVOLUTIONS:
        return None
    need = 2 * (max(held) * mesh_order + 3)
    # a power of two a turn where it holds them, else every sample a turn offers
    per_rev = int(min(4096, 2 ** int(np.floor(np.log2(max(fs / f_shaft, 1.0))))))
    if per_rev < need:
        per_rev = 2 * int(fs / f_shaft / 2)
    x = x - x.mean()
    # the other shafts' parts averaged on a fine grid (about 16 samples a bin, gathered from many turns):
    # a coarse one, read back at each sample's bin, leaves a tenth of a strong pattern's high orders
    n_fine = int(min(8192, max(per_rev, 2 ** int(np.floor(np.log2(max(x.size / 16, 1.0)))))))
    for f_other in others:
        j_other = _phase_bins(x.size, fs, f_other, n_fine)
        x = x - _synchronous_average(x, j_other, n_fine)[j_other]
    A = np.fft.rfft(_synchronous_average(x, _phase_bins(x.size, fs, f_shaft, per_rev), per_rev))
    k = np.arange(A.size)
    regular = k <= 2
    for m in MESH_HARMONICS:
        regular |= np.abs(k - m * mesh_order) <= 1.5
    A[regular] = 0
    return A, per_rev


def _kurtosis(A: np.ndarray, n: int) -> np.ndarray:
    """Kurtosis of the waveform(s) whose half spectrum is A (last axis), a turn of n samples."""
    d = np.fft.irfft(A, n, axis=-1)
    power = np.sum(d ** 2, axis=-1)
    return n * np.sum(d ** 4, axis=-1) / np.where(power > 0, power, np.inf) ** 2


def residual_moments(x: np.ndarray, fs: float, f_shaft: float, mesh_order: float, others=()) -> tuple | None:
    """(variance, FM4) of x's synchronous residual at the shaft speed f_shaft whose mesh is
    ``mesh_order`` x that speed: the samples binned by shaft phase and averaged over every revolution
    (a time-synchronous average without a tachometer, at the constant speed the analysis found), the
    regular orders taken out; FM4 is the kurtosis of what is left, the variance (the signal's unit
    squared) what NA4 normalises by over a healthy history (``vm.trend``). The synchronous part of each
    shaft in ``others`` (their speeds) is taken out of x first: over a few dozen turns its orders near
    whole orders of this shaft do not average away, and its gear's growth would read as this one's.
    None when the record holds too few revolutions or too few samples per revolution for the mesh's
    third harmonic."""
    res = _residual(x, fs, f_shaft, mesh_order, others)
    if res is None:
        return None
    A, per_rev = res
    power = float(np.sum(np.fft.irfft(A, per_rev) ** 2))
    return (power / per_rev, float(_kurtosis(A, per_rev))) if power > 0 else None


def impulsiveness(x: np.ndarray, fs: float, f_shaft: float, mesh_order: float) -> tuple | None:
    """(FM4, p): the synchronous residual's kurtosis and how unusual it is among N_SURROGATES residuals
    with the same sideband spectrum and random timing. Every real gear's teeth differ a little (pitch,
    profile, stiffness): that modulates the mesh at every order of the shaft, and a modulated carrier is
    not Gaussian (a carrier times a Gaussian modulation has kurtosis 4.5), so FM4 alone reads 4-14 on
    synthetic gears with random tooth errors of 2-10 %. A local fault differs in timing, not in spectrum:
    its sidebands are in phase (one pulse a turn). Each surrogate keeps every order's magnitude and
    delays the modulation's order k at random, the same delay for the pair (mesh harmonic h x teeth +- k)
    and for every h, so that an amplitude or phase modulation stays one, with its kurtosis. Orders below
    half the mesh are delayed as their order too (harmonic 0): a gear's tooth errors are one value a
    tooth, a sequence of ``teeth`` values whose spectrum repeats every ``teeth`` orders, so the mesh's
    lower sideband at order teeth - (teeth - k) = k carries the same errors as the sidebands at
    h x teeth +- k. Random phases there would make the surrogates less impulsive than random tooth
    errors are: on 120 synthetic healthy two-gear gearboxes, p <= 0.05 on 15 % of the shaft tests and
    p <= 0.005 on 2 gearboxes with them, against 8 % and none delayed as their order, while local tooth
    faults at 0 dB are found as often (``docs/methods/diagnosis.md``). p = (1 + surrogates at or above FM4) /
    (1 + surrogates drawn), drawn SURROGATE_CHUNK at a time until N_SURROGATES, or until
    SURROGATES_ENOUGH reach FM4."""
    res = _residual(x, fs, f_shaft, mesh_order)
    if res is None:
        return None
    A, n = res
    o = np.arange(A.size)
    h = np.rint(o / mesh_order).astype(int)
    k = o - np.rint(h * mesh_order).astype(int)
    rng = np.random.default_rng(SURROGATE_SEED)
    observed = float(_kurtosis(A, n))
    above = drawn = 0
    while drawn < N_SURROGATES and above < SURROGATES_ENOUGH:
        m = min(SURROGATE_CHUNK, N_SURROGATES - drawn)
        delay = rng.uniform(0, 2 * np.pi, (m, int(np.abs(k).max()) + 1))
        phase = np.sign(k)[None, :] * delay[:, np.abs(k)]
        if n % 2 == 0:
            phase[:, -1] = 0.0   # the Nyquist order of an even turn stays real
        above += int(np.sum(_kurtosis(A[None, :] * np.exp(1j * phase), n) >= observed))
        drawn += m
    return observed, float((1 + above) / (1 + drawn))


def _heights(A: np.ndarray, df: float, hz: np.ndarray, tol: int, ring: int) -> np.ndarray:
    """Height in dB of the strongest bin within +-tol bins of each frequency over the median of the
    bins within +-ring (the line's own bins left out); -inf outside the spectrum."""
    out = np.full(hz.size, -np.inf)
    i = np.rint(np.asarray(hz, float) / df).astype(int)
    inside = (i - ring >= 1) & (i + ring < A.size)
    if not inside.any():
        return out
    i = i[inside, None]
    peak = A[i + np.arange(-tol, tol + 1)].max(axis=1)
    floor = np.median(A[i + np.r_[np.arange(-ring, -tol - 1), np.arange(tol + 2, ring + 1)]], axis=1)
    out[inside] = 20 * np.log10(peak / np.maximum(floor, 1e-300))
    return out


def _places(fm: float, spacing: float, top: float, shift: float = 0.0) -> np.ndarray:
    """The wide sidebands' frequencies around the mesh harmonics (or, ``shift`` = -0.5, around the points
    halfway below them) below ``top``."""
    hz = np.array([(k + shift) * fm + s * n * spacing for k in MESH_HARMONICS for n in WIDE_SIDEBANDS
                   for s in (-1, 1)])
    return hz[(hz > 0) & (hz < top)]


def _count(A, df, fm, spacing, top, tol, ring, avoid=()) -> int:
    """Places around the mesh harmonics where a sideband stands (LINE_DB over its floor) and the same
    place around the point halfway below the harmonic either holds none or one LINE_DB lower, less the
    places where it is the other way round. A local tooth fault's
    pulse, a few teeth long, spreads sidebands a few orders wide: high near the mesh, low halfway. A
    shaft's own comb (impacts once a turn, a rub, looseness) and random tooth-to-tooth errors fill every
    order alike, near the mesh and halfway. Places on a harmonic of a shaft in ``avoid`` are not asked
    (the decoys avoid every shaft): the mesh is a whole order of every shaft it joins, so each shaft's
    sidebands around it are simply that shaft's harmonics, and a 71-tooth wheel's random tooth errors
    stand at most of them (decoy spacings counted up to 23 places, and a pinion's local fault with 8
    did not beat them)."""
    offsets = np.array([s * n * spacing for k in MESH_HARMONICS for n in WIDE_SIDEBANDS for s in (-1, 1)])
    near = np.repeat(np.asarray(MESH_HARMONICS, float) * fm, 2 * len(WIDE_SIDEBANDS)) + offsets
    half = near - 0.5 * fm
    keep = (near > 0) & (near < top) & (half > 0) & (half < top)
    for s in avoid:
        for hz in (near, half):
            keep &= np.abs(hz - np.rint(hz / s) * s) > (tol + 0.5) * df
    h_near = _heights(A, df, near[keep], tol, ring)
    h_half = _heights(A, df, half[keep], tol, ring)
    near_only = (h_near >= LINE_DB) & ((h_half < LINE_DB) | (h_near - h_half >= LINE_DB))
    half_only = (h_half >= LINE_DB) & ((h_near < LINE_DB) | (h_half - h_near >= LINE_DB))
    return max(0, int(np.sum(near_only)) - int(np.sum(half_only)))


def _half_width(A: np.ndarray, i: int) -> int:
    """Bins on either side of the peak at i down to half its amplitude (the wider side)."""
    peak, lo, hi = A[i], i, i
    while lo > 0 and A[lo - 1] > peak / 2:
        lo -= 1
    while hi < A.size - 1 and A[hi + 1] > peak / 2:
        hi += 1
    return max(i - lo, hi - i)


def _decoys(f1: float, shafts: list) -> np.ndarray:
    """Spacings that are no shaft's speed: 0.6-1.7 x f1, 5 % or more from every shaft's speed, its
    half and its double (a mesh's sidebands at a multiple of the spacing would count)."""
    u = np.geomspace(0.6, 1.7, 4 * N_DECOYS) * f1
    bad = np.array([q * s for s in shafts for q in (0.5, 1.0, 1.5, 2.0)])
    keep = np.all(np.abs(u[:, None] / bad[None, :] - 1) > 0.05, axis=1)
    u = u[keep]
    return u[:: max(1, u.size // N_DECOYS)][:N_DECOYS]


def _winner(run, shafts: list, counts: dict, decoy: np.ndarray, fm: float):
    """(shaft, its count, decoy p, whether its sidebands stand, (FM4, p) of its residual). A shaft whose
    wide sidebands stand against the decoys and whose synchronous residual is impulsive (FM4 >= FM4_FAULT
    and p <= IMPULSE_P) is the faulty gear's; else the shaft with more sidebands, standing only when it
    has more than the other. Both residuals are tested: the gear with more sidebands is not always the
    faulty one (a 71-tooth wheel's random tooth errors spread more sidebands than a pinion's broken
    tooth)."""
    tests = {}
    for name, s in shafts:
        c = counts[name]
        p = float((1 + np.sum(decoy >= c)) / (1 + decoy.size))
        tests[name] = (c, p, c >= MIN_SIDEBANDS and p <= DECOY_P,
                       impulsiveness(run.job.a, run.job.fs, s, fm / s) or (None, None))
    local = [n for n, (c, p, ok, (k, kp)) in tests.items() if ok and k is not None and k >= FM4_FAULT
             and kp <= IMPULSE_P]
    if local:
        name = max(local, key=lambda n: tests[n][3][0])
        c, p, _, fm4 = tests[name]
        return name, c, p, True, fm4
    name = max(tests, key=lambda n: tests[n][0])
    c, p, ok, fm4 = tests[name]
    return name, c, p, ok and all(c > counts[n] for n in counts if n != name), fm4


def gear_rows(run) -> list:
    """The gear row where a gear is given: the mesh line, and a fault where one shaft's wide sidebands
    (+-2..6 x its speed around mesh harmonics 1-3, less those standing halfway between the harmonics)
    stand in at least MIN_SIDEBANDS places, more often than at all but DECOY_P of the decoy spacings,
    and its synchronous residual is impulsive (``_winner``: FM4 and its surrogates).
    Reason: the test asked only for a mesh line with one +-1X sideband, which every working gearbox has:
    on real healthy gearboxes it called gear_mesh at up to 1.00."""
    gear = run.job.gear
    if gear is None:
        return []
    f, A, f1 = run.f, run.A, run.f1
    df = f[1]
    fm = gear.teeth * f1
    mesh_f, mesh_amp, mesh_db = _line(f, A, fm, max(2.5 * df, 0.005 * fm), max(2 * f1, 10 * df))
    shafts = [("this shaft", f1)]
    if gear.mating_shaft_ratio is not None:
        shafts.append(("the mating shaft", f1 * gear.mating_shaft_ratio))
    if mesh_db < LINE_DB:   # the answer then says the gear was not checked (``doubts.gear_unseen``)
        run.job.flags.append("gear_not_seen")
        return [_row("gear_mesh", fm, mesh_f, mesh_amp, mesh_db, 0.0,
                     f"no mesh line at {gear.teeth} x 1X ({fm:.1f} Hz): the gear is not seen")]
    # the mesh line measures the speed: the places are set from it, as wide as the line itself is (a
    # steady speed: a window's main lobe; a wandering one smears the line and its sidebands alike)
    hz = _refine(f, A, mesh_f)
    shafts = [(name, s * hz / fm) for name, s in shafts]
    spacing_min = min(s for _, s in shafts)
    tol = max(2, min(int(round(0.002 * fm / df)), _half_width(A, int(round(mesh_f / df))) + 1))
    expected, fm = fm, hz
    ring = max(tol + 6, int(0.35 * 0.6 * spacing_min / df))   # inside the gap to the nearest decoy sideband
    top = f[-1] - ring * df
    # a shaft's own comb (impacts once a turn, a rub, looseness) stands at every order, around the mesh
    # and between its harmonics alike: only what stands around the mesh beyond what stands halfway
    # between is the mesh's modulation (``_count``; without it, a healthy machine with a rub was called
    # gear_mesh on 18 of 30 synthetic records)
    speeds = [s for _, s in shafts]
    counts = {name: _count(A, df, fm, s, top, tol, ring) for name, s in shafts}
    decoy = np.array([_count(A, df, fm, u, top, tol, ring, speeds) for u in _decoys(f1, speeds)])
    # the average needs the shaft's speed to a small part of a turn over the record: the mesh line, many
    # orders up and refined between bins, measures it better than the 1X (0.1 % off smears a pulse over a
    # fifth of a turn in 180; a bin's width, 1/T, drifts order k by k / fm turns over the record)
    name, c, p, stands, (fm4, fm4_p) = _winner(run, shafts, counts, decoy, fm)
    spacing = dict(shafts)[name]
    score = (1 - p) * min(1.0, c / (MIN_SIDEBANDS + 2)) if stands else 0.0
    places = len(_places(fm, spacing, top))
    # for NA4 (``vm.trend``), each gear's residual on its own shaft, whichever won: this shaft's gear has
    # ``teeth``, the mating one teeth / ratio; the other shaft's synchronous part is taken out first
    per_shaft = {}
    for key, (n, s) in zip(("shaft", "mating"), shafts):
        var_k, fm4_k = residual_moments(run.job.a, run.job.fs, s, fm / s,
                                        [o for m, o in shafts if m != n]) or (None, None)
        per_shaft.update({f"{key}_fm4": fm4_k, f"{key}_residual_var": var_k})
    note = (f"mesh {gear.teeth} x 1X at {mesh_db:.0f} dB; wide sidebands (+-2..6 x {name}'s {spacing:.2f} Hz) stand "
            f"in {c} of {places} places more than halfway between the mesh harmonics, decoy spacings p = {p:.2g}"
            + "".join(f"; {n}: {counts[n]}" for n, _ in shafts if n != name)
            + (f"; FM4 {fm4:.2f} ({name}'s synchronous average, regular mesh removed; p = {fm4_p:.2g} among "
               "residuals of its sideband spectrum with random timing)" if fm4 is not None else "")
            + ("" if stands else "; a healthy mesh (only its +-1 sidebands and a few others)"))
    if stands and fm4 is not None and fm4_p > TOOTH_ERRORS_P:
        score = 0.0
        note += ("; not a fault: the synchronous residual is no more impulsive than random tooth-to-tooth errors "
                 f"of the same sideband spectrum make it (p > {TOOTH_ERRORS_P:g}), as on a healthy gear")
        run.job.flags.append("gear_not_impulsive")
    elif stands and (fm4 is None or fm4 < FM4_FAULT or fm4_p > IMPULSE_P):
        score = min(score, 0.45)
        why = ("no synchronous average: too few turns, or too few samples a turn for the mesh line"
               if fm4 is None else f"FM4 < {FM4_FAULT:g}" if fm4 < FM4_FAULT else
               f"p > {IMPULSE_P:g} among residuals with random timing")
        note += (f"; held at 0.45: the synchronous residual is not clearly impulsive ({why}), as a local tooth "
                 "fault makes it: random tooth errors, a distributed modulation (an eccentric or off-centre gear, "
                 "load changes) or a wandering speed")
        run.job.flags.append("gear_not_impulsive")
    return [_row("gear_mesh", expected, mesh_f, mesh_amp, mesh_db, score, note, sidebands=c, decoy_p=p, fm4=fm4,
                 fm4_p=fm4_p, **per_shaft)]
