"""Step 2, the running speed: the 1X line near the declared speed, its consistency with fs, a shaft
comb or the bearing's own lines that contradict the declared speed, a speed that drifts; the whole
step is ``running_speed``, which hands a frozen ``Run`` to the steps after it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import fft as _sfft

from ...signal.spectral import symmetric_window
from .job import Job
from .lines import LINE_DB, _harmonic_support, _line, _lines_standing, _refine, _spectrum
from .mains import _at_mains
from .tracking import DRIFT_P, SPEED_DRIFT, _order_tracked_job, _speed_drift, _speed_from_1x

# The 1X line is looked for within SPEED_SEARCH of the declared speed: an induction motor under load
# runs up to about 5 % below its synchronous speed, a declared speed is often the nameplate's, and a
# drive's set point may be further off (CWRU OR014@3_0 declared 4-5 % fast has its 1X, 52 dB, outside a
# +-3 % window, and a 17.5 dB line inside it). Within the window the 1X is the line with the most
# harmonics 2X-6X (``_harmonic_support``), then the strongest: a stronger line without harmonics
# (another machine, a structure) is not the shaft's. Measured on the 57 development records declared
# 0.90-1.12 x their speed: the 1X of all 57 is found from 0.92 to 1.12 x (56 at 0.90 x, where IR007_1's
# 1X lies 13.8 % away); the strongest line within +-6 % alone finds all 57 only from 0.97 to 1.03 x.
SPEED_SEARCH = 0.12
SPEED_NOTED = 0.01   # a 1X this far from the declared speed is said so in the answer
# a 0.5X line (with 1.5X standing too) this many dB or more over the 1X makes the 1X a 2X: the 53 development
# records at their true fs read 0.5X at 10 dB or more under the 1X, at half their fs up to 25.6 dB over it
# (the true 1X over the true 2X; 21 of them 6 dB or more); a loose machine's sub-harmonic reads -2.9 to
# +0.4 dB (synth.machine): below this, the two cannot be told apart by the lines
HALF_OVER_1X_DB = 6.0
# Between HALF_AMBIGUOUS_DB under the 1X and HALF_OVER_1X_DB over it, a 0.5X line (1.5X standing too) is
# either a loose machine's sub-harmonic or the true 1X of a record read at half its rate (or at a speed
# declared twice too high): the answer stands, flagged ``half_order_ambiguous`` with that advice. The
# development records at their own rate read 10 dB or more under it; CWRU B007_1 at half its rate -0.4 dB
HALF_AMBIGUOUS_DB = -6.0
# A 1X candidate more than SPEED_NOTED from the declared speed confirms the speed it shows only with at
# least ONE_X_CONFIRMS of its harmonics 2X-6X; with fewer, neither it nor the declared speed is confirmed
# and the bearing's own lines are searched at other speeds, as when no 1X is found. Reason: MFPT's
# inner-race record declared 20 % fast shows a 12 dB line with one harmonic at 1919 rpm (+28 % from the
# true speed); taken for the 1X it leads to a ball call (p = 3e-15) on the inner race's lines, while the
# scan finds the inner race's comb with +-1X sidebands at 1488 rpm (true 1486), p = 2e-58. At their
# declared speed the MFPT records' 1X shows 1-3 harmonics within 1.2 % of it. A speed measured by a
# tachometer or a profile is confirmed as it is.
ONE_X_CONFIRMS = 2


# A gear's mesh (teeth x the shaft's speed) is the strongest line of a gearbox's spectrum and measures the
# speed teeth times finer than the 1X; with a gear declared, the 1X is the candidate whose tooth-order
# harmonic is that mesh line (the strongest line within MESH_SEARCH of the declared mesh, standing
# MESH_DB above its floor). The agreement of two lines confirms the speed where the 1X alone cannot: a
# shaft at 3000 or 3600 rpm turns at the line frequency, whose lines are not taken for a 1X (``mains``),
# and the mating shaft's 2X, 3.6 % under the true 1X of a 40/83 gearbox at 3600 rpm with its comb of
# harmonics, was taken for it. On the 192 healthy records of benchmarks/gearbox.py the speed is found
# within 1 % on 189 with the gear and its ratio declared, on 136 by the 1X search alone. Where no 1X
# stands at the mesh's speed (a wrong tooth count, no mesh) the search goes on as without a gear.
# The mesh is looked for within MESH_SEARCH of the declared speed's, wider than the 1X (SPEED_SEARCH):
# two lines that agree (the strongest near the mesh, a 1X at its speed over the teeth) stand for a
# speed further off than one line can (a speed declared 0.8 x the true one, a drive's set point for
# its output: the gearbox benchmark's tooth faults were lost at 0.8 and 1.2 x, the mesh 25 % away).
MESH_DB = 20.0
MESH_SEARCH = 0.3
MESH_FACTORS = (2.0, 0.5, 4.0, 0.25)   # where else a declared gear's mesh is looked for (``doubts.mesh_speed``)


def _mesh_one_x(job: Job, f, A, f1):
    """(speed from the mesh, 1X height in dB, harmonics, mesh Hz) where a declared gear's mesh line and
    a 1X line agree (MESH_DB), else None."""
    if job.gear is None:
        return None
    df, z = f[1], job.gear.teeth
    # the window, where it reaches Nyquist, ends a floor's ring short of it
    k = np.flatnonzero((np.abs(f - z * f1) <= MESH_SEARCH * z * f1) & (f < f[-1] - 5 * df))
    if k.size == 0:
        return None
    i = int(k[np.argmax(A[k])])   # the strongest line there: a local peak standing MESH_DB
    if not (1 <= i < A.size - 1 and A[i] >= A[i - 1] and A[i] > A[i + 1]):
        return None
    if _line(f, A, f[i], 0.6 * df, f[i] + 5 * df)[2] < MESH_DB:
        return None
    mesh_hz = _refine(f, A, f[i])
    fc = mesh_hz / z
    one_x = _line(f, A, fc, max(1.5 * df, 0.002 * fc), fc + 5 * df)[2]
    if one_x < LINE_DB:
        return None
    return fc, one_x, _harmonic_support(f, A, fc), mesh_hz


def _speed(job: Job, f, A):
    """Running speed from the 1X line near the declared rpm (where a gear is declared, the one its mesh
    line confirms); a 1X that only fits another fs is flagged."""
    df = f[1]
    f1 = job.rpm / 60.0
    meshed = _mesh_one_x(job, f, A, f1)
    found = meshed[:3] if meshed else _one_x(f, A, f1, job.mains)
    # no mesh at the declared speed, but one at 2, 0.5, 4 or 0.25 x it (a speed in Hz for rpm, pulses per
    # revolution, a sampling rate declared 2 or 4 x off), with its 1X: the speed may be off by that
    # factor (``doubts.mesh_speed``); a mesh cannot move, where a 2X ten times the 1X is also misalignment.
    # A mesh at the declared speed is no proof where one stands at half it too: the declared speed's is
    # then its second harmonic (a gear makes no line at half its mesh)
    elsewhere = None if job.gear is None else next(
        ((q, m[3]) for q in ((0.5,) if meshed else MESH_FACTORS) if (m := _mesh_one_x(job, f, A, q * f1)) is not None),
        None)
    snr1 = found[1] if found else _line(f, A, f1, max(SPEED_SEARCH * f1, 2 * df), f1 + 5 * df)[2]
    speed = {"declared_rpm": job.rpm, "estimated_rpm": None, "one_x_db": snr1, "consistent": True, "note": "",
             "fs_ratio": 1}
    if elsewhere is not None:   # mesh_hz: the mesh line found, the declared speed's where it confirms it
        speed["mesh_factor"], speed["mesh_factor_hz"] = elsewhere
        speed["mesh_hz"] = elsewhere[1]
    if found:
        f1 = found[0]
        speed["estimated_rpm"] = 60 * f1
        speed["one_x_harmonics"] = found[2]
        if meshed:
            speed["mesh_hz"] = meshed[3]
        off = f1 / (job.rpm / 60.0) - 1
        if abs(off) > SPEED_NOTED:
            speed["note"] = (f"the 1X line is at {60 * f1:.0f} rpm, {100 * off:+.1f} % from the declared {job.rpm:g} "
                             "rpm: the measured speed is used")
            job.flags.append("speed_corrected")
    _sub_orders(job, f, A, f1, snr1, speed)
    if speed["consistent"] and not found:   # the declared speed is used as given: said, not held
        speed["note"] = (f"no 1X line within {100 * SPEED_SEARCH:g} % of the declared {job.rpm:g} rpm: the speed "
                         "is used as declared, unchecked")
        job.flags.append("speed_unchecked")
    # a speed the mesh and the 1X both measure is not contradicted by another shaft's comb (the mating
    # shaft's, which every gearbox has)
    other = _contradiction(job, f, A, found, snr1) if speed["consistent"] and not meshed else None
    if other is not None:
        _contradicted(job, speed, other, found)
    if speed["consistent"]:
        drift = _speed_drift(job.a, job.fs, f1)
        if drift is not None and drift[2] > SPEED_DRIFT and drift[3] < DRIFT_P and _smeared(f, A, drift[0], drift[1]):
            lo, hi, spread, _, coef = drift
            speed.update(drift_hz=(lo, hi), _curve=coef, note=(
                f"the 1X line moves between {lo:.2f} and {hi:.2f} Hz over the record ({100 * spread:.1f} %): the "
                "speed varies and the bearing lines smear; give tach= or rpm_profile= for an analysis in orders"))
            job.flags.append("speed_varies")   # the bearing side then says little (pipeline._bearing_weak)
    return speed, f1


def _sub_orders(job: Job, f, A, f1: float, snr1: float, speed: dict) -> None:
    """Lines at quarter and half orders of the 1X (``speed`` updated, flags set): a time base that fits
    only at 2 or 4 x fs (``speed_inconsistent``), a loose machine's sub-harmonics or a factor 2
    (``half_order_ambiguous``), a 0.5X line alone far over the 1X (``speed["half_line"]``)."""
    df = f[1]
    for r in (4, 2):
        # a mains line is no sub-harmonic (a 60 Hz line stood for 7/4 X of a 2100 rpm looseness machine)
        lines = [_line(f, A, k * f1 / r, max(2 * df, 0.01 * k * f1 / r), 0.5 * f1 / r) for k in range(1, 2 * r)
                 if k % r]
        hits = [db >= LINE_DB and not _at_mains(fk, df, job.mains) for fk, _, db in lines]
        # at half the true fs the true 1X reads 0.5X and the true 2X stands where the 1X is looked for:
        # a 0.5X line about as high as the "1X" says so (HALF_OVER_1X_DB)
        if r == 4 and sum(hits) >= 3 or r == 2 and all(hits) and (snr1 < LINE_DB or
                                                                    lines[0][2] >= snr1 + HALF_OVER_1X_DB):
            speed.update(consistent=False, fs_ratio=r, note=(
                f"lines at {1 / r:g}X, ... fit a shaft speed of {job.rpm:g} rpm only if fs is {r}x the declared "
                f"{job.fs:g} Hz ({r * job.fs:g} Hz): check the sampling rate"))
            job.flags.append("speed_inconsistent")
            return
        # a 0.5X line alone as far over the 1X (its 1.5X weak, or on a supply line): the shaft's 1X may be
        # that line all the same (``doubts.half_line``); a gearbox's tooth errors leave its 3X weak
        if r == 2 and hits[0] and not hits[1] and (snr1 < LINE_DB or lines[0][2] >= snr1 + HALF_OVER_1X_DB):
            speed["half_line"] = (lines[0][0], lines[0][2])
        if (r == 2 and all(hits) and snr1 >= LINE_DB and lines[0][2] >= snr1 + HALF_AMBIGUOUS_DB
                and "half_order_ambiguous" not in job.flags):
            job.flags.append("half_order_ambiguous")
            speed["note"] = " ".join(x for x in (speed["note"], (
                f"the 0.5X and 1.5X lines stand within {-HALF_AMBIGUOUS_DB:g} dB of the 1X ({lines[0][2]:.1f} against "
                f"{snr1:.1f} dB): a loose machine's sub-harmonics, or the true 1X of a record whose fs is 2x the "
                f"declared {job.fs:g} Hz (or whose speed is half the declared {job.rpm:g} rpm): check both")) if x)


def _contradicted(job: Job, speed: dict, other: tuple, found) -> None:
    """The speed dict and flags where another shaft's comb (``_contradiction``: frequency, harmonics,
    height, channel) contradicts the declared speed."""
    fc, h, db, where = other
    near = (f"no line stands out within {100 * SPEED_SEARCH:g} % of the declared speed" if not found else
            f"the best 1X candidate within {100 * SPEED_SEARCH:g} % of the declared speed ({60 * found[0]:.0f} "
            f"rpm) stands only {found[1]:.0f} dB with {found[2]} of its harmonics")
    speed.update(consistent=False, estimated_rpm=None, contradicting_rpm=60 * fc, note=(
        f"the declared {job.rpm:g} rpm is contradicted by the spectrum of {where!r}: a shaft comb stands at "
        f"{60 * fc:.0f} rpm "
        f"({100 * (fc / (job.rpm / 60.0) - 1):+.1f} %; its line {db:.0f} dB above the floor with {h} of its "
        f"harmonics 2X-6X), and {near}. Shaft-order and bearing "
        "faults are not looked for at a speed the record contradicts: give the measured speed (rpm=, or "
        "tach= / rpm_profile=)"))
    speed.pop("one_x_harmonics", None)
    if "speed_corrected" in job.flags:
        job.flags.remove("speed_corrected")
    job.flags.append("speed_contradicted")


# A declared speed further off than SPEED_SEARCH finds no 1X, or a wrong line, and puts the bearing
# lines at wrong orders (the 53 development records declared at 0.88 x their speed: 16 wrong calls
# without this check). The record contradicts such a speed when a shaft comb stands elsewhere
# (OTHER_SHAFT x the declared speed): a line at least OTHER_SHAFT_DB above the window's 1X (or the level
# there when none stands out) with at least OTHER_SHAFT_HARMONICS of its harmonics 2X-6X, more than
# that 1X has, and no harmonic or sub-harmonic of it. Measured (benchmarks/diagnosis_robustness.py):
# at the declared speed no development record and no 1 s or 2 s piece of one is flagged (Normal_0's
# wrong declared fs is caught before); at 0.85 x and 1.2 x, 90 % of the 1 s pieces are.
OTHER_SHAFT = (0.5, 2.0)
OTHER_SHAFT_DB = 10.0
OTHER_SHAFT_HARMONICS = 4


def _contradiction(job: Job, f, A, found, snr1):
    """(frequency, harmonics, height in dB, channel) of a shaft comb that contradicts the declared speed in
    the primary channel's spectrum (f, A; its 1X candidate ``found`` and level ``snr1``) or in another
    channel's: one shaft turns under every sensor, and a sensor across the machine may show its comb
    where the primary channel shows a spurious one (CWRU IR014_1 declared 20 % fast: in the fan-end
    channel a 21 dB line at the declared speed has lines at 2X-6X of its own in a dense spectrum; the
    drive-end channel shows the true 1X, 51 dB with its comb)."""
    f1 = job.rpm / 60.0
    hit = _other_shaft(f, A, f1, found, snr1, job.mains)
    if hit is not None:
        return (*hit, job.primary)
    for name, x in job.signals.items():
        if name == job.primary or x.size != job.a.size:
            continue
        win = symmetric_window("hann", x.size)
        Ax = np.abs(_sfft.rfft((x - x.mean()) * win)) * 2 / win.sum()
        found_x = _one_x(f, Ax, f1, job.mains)
        snr_x = found_x[1] if found_x else _line(f, Ax, f1, max(SPEED_SEARCH * f1, 2 * f[1]), f1 + 5 * f[1])[2]
        # the comb must also stand 10 dB above the primary channel's 1X candidate: a channel whose 1X is
        # weak (a remote sensor) cannot overrule one that shows it
        hit = _other_shaft(f, Ax, f1, found_x, max(snr_x, snr1), job.mains)
        if hit is not None:
            return (*hit, name)
    return None


def _other_shaft(f, A, f1, found, snr1, mains=()):
    """(frequency, harmonics, height in dB) of a shaft comb that contradicts the declared speed f1, or
    None: see OTHER_SHAFT. Lines at 2, 3, 4, 1/2, 1/3, 1/4, 3/2 or 2/3 x the window's 1X (when one was
    found; else at 2 or 1/2 x a speed within the window) are its harmonics, not another shaft."""
    df = f[1]
    m = min(f.size, int(13 * OTHER_SHAFT[1] * f1 / df) + 10)
    f, A = f[:m], A[:m]
    k = np.flatnonzero((f >= OTHER_SHAFT[0] * f1) & (f <= OTHER_SHAFT[1] * f1) & (np.abs(f - f1) > SPEED_SEARCH * f1))
    need = max(LINE_DB, snr1 + OTHER_SHAFT_DB)
    # the exact test (``_line``: over the median of 0-2 x the line's frequency) runs on the lines within
    # 20 dB of the need over the median of 0-4 x f1: on the development records and their 1 s pieces,
    # every channel, declared at 0.7-1.3 x, it found the same combs as on every line (10 dB missed 6 of
    # 9948)
    floor = np.median(A[1: max(3, int(4 * f1 / df))])
    k = k[A[k] >= floor * 10 ** ((need - 20) / 20)]
    best = None
    for fc, db in _lines_standing(f, A, k, need):
        if _at_mains(fc, df, mains):
            continue
        if found is not None:
            if any(abs(fc / (found[0] * q) - 1) < 0.01 for q in (2, 3, 4, 1 / 2, 1 / 3, 1 / 4, 3 / 2, 2 / 3)):
                continue
        elif any(abs(fc / (f1 * q) - 1) <= SPEED_SEARCH for q in (2, 1 / 2)):
            continue
        h = _harmonic_support(f, A, fc)
        if h >= OTHER_SHAFT_HARMONICS and (found is None or h > found[2]) and (best is None or (h, db) > best[1:]):
            best = (fc, h, db)
    return best


def _one_x(f, A, f1, mains=()):
    """(frequency, height in dB, harmonics) of the 1X line within SPEED_SEARCH of the declared f1: of the
    local maxima standing LINE_DB above their floor there, the one with the most harmonics
    (``_harmonic_support``), then the strongest; None when no line stands out. A shaft shows its
    harmonics; an electrical, structural or other machine's line near 1X rarely shows the same comb."""
    df = f[1]
    m = min(f.size, int(13 * (1 + SPEED_SEARCH) * f1 / df) + 10)   # every floor ring below reaches 12 x fc
    f, A = f[:m], A[:m]
    k = np.flatnonzero(np.abs(f - f1) <= max(SPEED_SEARCH * f1, 2 * df))
    best = None
    for fc, snr in _lines_standing(f, A, k, LINE_DB):
        if _at_mains(fc, df, mains):
            continue
        cand = (fc, snr, _harmonic_support(f, A, fc))
        if best is None or (cand[2], cand[1]) > (best[2], best[1]):
            best = cand
    return best


def _smeared(f, A, lo, hi) -> bool:
    """Whether the whole record's 1X is as broad as the drift says: the lines within 6 dB of its peak
    reach beyond the Hann main lobe (two lines) by at least a quarter of lo..hi (a linear run-up under
    the record's Hann window reads 6 dB down at half its range: the window weighs its ends less).
    A constant speed keeps a
    sharp 1X however its short parts scatter: sidebands beside a 1X pull a short part's estimate
    (measured on the first 4 s of CWRU fan-end records: 5.7 % and 3.3 % of scatter along a 'curve'
    beside a 1X two lines wide)."""
    df = f[1]
    sel = np.flatnonzero((f >= lo - 2 * df) & (f <= hi + 2 * df))
    if sel.size < 2:
        return False
    strong = sel[A[sel] >= 0.5 * A[sel].max()]
    return (strong[-1] - strong[0] - 1) * df >= 0.25 * (hi - lo)


def _tach_speed(job: Job, f, A, tracked: dict, declared, note: str):
    """The speed as the tachometer (or profile) gives it; the declared rpm is compared with it."""
    f1 = tracked["mean_rpm"] / 60.0
    _, _, snr1 = _line(f, A, f1, max(0.03 * f1, 2 * f[1]), f1 + 5 * f[1])
    speed = {"declared_rpm": declared, "estimated_rpm": tracked["mean_rpm"], "one_x_db": snr1, "consistent": True,
             "note": note, "fs_ratio": 1, "source": tracked["source"], "min_rpm": tracked["min_rpm"],
             "max_rpm": tracked["max_rpm"]}
    if declared is not None and abs(declared / tracked["mean_rpm"] - 1) > 0.03:
        speed["note"] = (note + "; " if note else "") + (
            f"the declared {declared:g} rpm is not the {tracked['source']}'s mean {tracked['mean_rpm']:.0f} rpm: "
            "the measured speed is used")
        job.flags.append("speed_inconsistent")
    return speed, f1


def _confirmed(speed: dict) -> bool:
    """Whether the speed the bearing analysis uses is confirmed: measured (a tachometer, a speed profile,
    the 1X's own curve: ``speed["source"]``), or a 1X line near the declared speed or with its harmonics
    (see ONE_X_CONFIRMS). When it is not, the bearing's own lines are searched at other speeds
    (``bearing.decoys._speed_scan``)."""
    if speed["estimated_rpm"] is None:
        return False
    if speed.get("source") is not None or not speed.get("declared_rpm"):
        return True
    off = abs(speed["estimated_rpm"] / speed["declared_rpm"] - 1)
    return off <= SPEED_NOTED or speed.get("one_x_harmonics", 0) >= ONE_X_CONFIRMS


def _bearing_contradiction(job: Job, speed: dict, f1: float, other: dict):
    """No 1X confirmed the speed (none found, or one off the declared speed without its harmonics:
    ONE_X_CONFIRMS), and the bearing's lines stand where another speed puts them
    (``bearing.decoys._speed_scan``): the speed is contradicted, as by another shaft's comb."""
    lines = ", ".join(f"{hz:.1f} Hz {db:.0f} dB" for hz, db in other["lines"][:5])
    rpm = 60 * f1 * other["factor"]
    if speed["estimated_rpm"] is None:
        why = "no 1X line confirms it"
    elif speed.get("source") is not None:
        why = (f"the {speed['source']} gives {speed['estimated_rpm']:.0f} rpm (check its pulses per revolution)")
    elif _confirmed(speed):   # a factor of 2 (decoys.FACTOR_WINDOWS): a 1X found says little
        why = (f"a 1X line stands at {speed['estimated_rpm']:.0f} rpm, but a shaft's 2X stands at twice a speed "
               "declared half the true one, and a line at half the true speed takes its harmonics for its own")
    else:   # a 1X candidate off the declared speed without its harmonics (ONE_X_CONFIRMS)
        why = (f"the 1X candidate, at {speed['estimated_rpm']:.0f} rpm, shows "
               f"{speed.get('one_x_harmonics', 0)} of its harmonics 2X-6X ({ONE_X_CONFIRMS} confirm a speed)")
    if "speed_corrected" in job.flags:
        job.flags.remove("speed_corrected")
    speed.pop("one_x_harmonics", None)
    speed.update(consistent=False, estimated_rpm=None, contradicting_rpm=rpm,
                 contradicted_by="bearing lines", bearing_comb=other, note=(
                     f"the declared {job.rpm:g} rpm is contradicted by the bearing's lines: {why}, and a "
                     f"{other['family']} comb ({other['model']}: {lines}) stands where about "
                     f"{rpm:.0f} rpm ({100 * (rpm / job.rpm - 1):+.1f} %) puts it, "
                     f"p = {other['p_value']:.2g} in {other['channel']!r} against p = "
                     f"{other['declared_p_value']:.2g} for the best comb at the declared speed"
                     + "".join(f"; another family's comb fits them nearly as well at {60 * f1 * u:.0f} rpm"
                               for u in other.get("other_factors", ())[:2])
                     + " (or the bearing declared is not the one that shows). Shaft-order and bearing faults "
                     "are not looked for at a speed the record contradicts: give the measured speed (rpm=, or "
                     "tach= / rpm_profile=)" + _whole_factor(rpm / job.rpm)))
    job.flags.append("speed_contradicted")


def _whole_factor(u: float) -> str:
    """Advice where the contradicting speed is a whole factor (2, 4 or their inverses) of the declared
    one: every frequency off by that factor is as likely a sampling rate off by it."""
    for k in (2, 4):
        for v, word in ((k, "high"), (1 / k, "low")):
            if abs(u / v - 1) <= 0.06:   # decoys.FACTOR_WINDOW
                return f", or check fs: a sampling rate declared {k} x too {word} reads every line {k} x too {word}"
    return ""



@dataclass(frozen=True)
class Run:
    """The record at its analysed time base (order-tracked where the speed varies), its primary
    channel's amplitude spectrum (f, A) and the speed the analysis uses (``speed``, f1 in Hz)."""
    job: Job
    f: np.ndarray
    A: np.ndarray
    speed: dict
    f1: float


def running_speed(rec, job: Job, tracked: dict | None, rpm, band) -> Run:
    """The speed from a tachometer or profile (``tracked``: the record order-tracked with it where it
    varies) or from the 1X line; a 1X that drifts along a curve is followed the same way."""
    note = ""
    if tracked is not None:
        job, note = _order_tracked_job(job, tracked, band)
    f, A, _ = _spectrum(job)
    speed, f1 = _speed(job, f, A) if tracked is None else _tach_speed(job, f, A, tracked, rpm, note)
    if "speed_varies" in job.flags:   # no speed information, but the 1X drifts along a curve: follow it
        tracked_1x = _speed_from_1x(rec, job, speed, band)
        if tracked_1x is not None:
            job = tracked_1x
            f, A, _ = _spectrum(job)
            f1 = speed["estimated_rpm"] / 60.0
    speed.pop("_curve", None)
    return Run(job, f, A, speed, f1)
