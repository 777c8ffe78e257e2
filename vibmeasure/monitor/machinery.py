"""Machine fault diagnosis from one accelerometer record: fault-frequency catalogue, running-speed
check, envelope analysis with a kurtosis-chosen band, evidence and confidence per fault family, and
ISO 10816-3 severity. Weak evidence gives top = "none" with the reason, never a confident guess.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core._validate import as_record, clean_signal, positive, response_channel
from ..core.errors import ParameterError
from ..core import units as _units
from ..models.bearing import BEARINGS, Bearing, Gear

__all__ = ["diagnose", "Diagnosis", "ISO_10816_3", "severity_zone"]

# ISO 10816-3:2009, Annex A (Tables A.1 and A.2): zone boundaries A/B, B/C, C/D in mm/s RMS,
# velocity 10-1000 Hz (2-1000 Hz below 600 rpm). Group 1: large machines, 300 kW - 50 MW;
# group 2: medium machines, 15 - 300 kW. Scope: 120 - 15 000 rpm.
ISO_10816_3 = {(1, "rigid"): (2.3, 4.5, 7.1), (1, "flexible"): (3.5, 7.1, 11.0),
               (2, "rigid"): (1.4, 2.8, 4.5), (2, "flexible"): (2.3, 4.5, 7.1)}
ISO_SCOPE_RPM = (120.0, 15000.0)
LINE_DB = 12.0     # a line counts as present this far above its local floor (noise maxima reach ~10 dB)
TOP_CONFIDENCE = 0.5
SLIP = 0.02        # bearing frequencies wander with slip and load: +-2 %


def severity_zone(v_rms_mm_s: float, *, group: int = 2, foundation: str = "rigid") -> str:
    """ISO 10816-3 zone A/B/C/D of an overall velocity RMS (mm/s) for a machine group and foundation."""
    key = (int(group), foundation)
    if key not in ISO_10816_3:
        raise ParameterError(f"machine_group={group!r}, foundation={foundation!r}: group 1 or 2, rigid or flexible")
    ab, bc, cd = ISO_10816_3[key]
    return "A" if v_rms_mm_s < ab else "B" if v_rms_mm_s < bc else "C" if v_rms_mm_s < cd else "D"


@dataclass(frozen=True)
class Diagnosis:
    """``top`` (none, unbalance, misalignment, looseness, bearing_outer_race, bearing_inner_race,
    bearing_ball, bearing_cage, gear_mesh, resonance, electrical), its ``confidence`` and ``reason``; ``faults`` (table per
    fault family), ``speed`` (estimated rpm and consistency), ``severity`` (ISO zone), ``flags``."""

    top: str
    confidence: float
    reason: str
    faults: object
    speed: dict
    severity: dict
    envelope_band_hz: tuple
    flags: tuple = ()
    extras: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        from ..core.results import _jsonable
        return _jsonable({"top": self.top, "confidence": self.confidence, "reason": self.reason,
                          "faults": self.faults.to_dict(orient="records"), "speed": self.speed,
                          "severity": self.severity, "envelope_band_hz": list(self.envelope_band_hz),
                          "flags": list(self.flags)})

    def __repr__(self) -> str:
        return f"Diagnosis(top={self.top!r}, confidence={self.confidence:.2f}: {self.reason})"


def _line(freq, values, f, tol, floor_halfwidth):
    """Strongest value within f +- tol and its height (dB) over the local median floor."""
    sel = np.abs(freq - f) <= tol
    if not sel.any():
        return None, 0.0, -np.inf
    k = np.flatnonzero(sel)[np.argmax(values[sel])]
    ring = (np.abs(freq - f) <= floor_halfwidth) & ~sel
    floor = np.median(values[ring]) if ring.sum() >= 5 else np.median(values)
    return float(freq[k]), float(values[k]), float(20 * np.log10(values[k] / max(floor, 1e-300)))


def _kurtogram_band(x, fs, f_lo):
    """The band (among 1/1 and 1/3-octave-wide bands above f_lo) whose envelope is most impulsive."""
    from scipy import signal as sg
    best, best_k = None, -np.inf
    nyq = fs / 2
    for width in (0.7, 0.35):  # relative bandwidths
        fc = f_lo * 1.3
        while fc * (1 + width / 2) < 0.95 * nyq:
            lo, hi = fc * (1 - width / 2), fc * (1 + width / 2)
            sos = sg.butter(4, (lo, hi), btype="bandpass", fs=fs, output="sos")
            env = np.abs(sg.hilbert(sg.sosfiltfilt(sos, x)))
            e = env - env.mean()
            k = float(np.mean(e ** 4) / np.mean(e ** 2) ** 2 - 2)  # kurtosis of a complex envelope: 0 for noise
            if k > best_k:
                best, best_k = (lo, hi), k
            fc *= 1 + width / 2
    return best, best_k


def diagnose(rec, *, rpm: float | None = None, bearing=None, gear=None, machine_group: int | None = None,
             foundation: str | None = None, channel=None, band=None, line_frequency: float | None = None,
             fs: float | None = None):
    """Diagnose a rotating machine from an acceleration record.

    ``rpm`` is the declared shaft speed (default: the record's meta["rpm"]); ``bearing`` a
    vm.Bearing or a catalogue name ("6205-2RS", "6203-2RS"); ``gear`` a tooth count or vm.Gear;
    ``machine_group`` (1 or 2) and ``foundation`` ("rigid", "flexible") select the ISO 10816-3
    zones (default group 2, rigid). ``band`` fixes the envelope band (default: most impulsive band).
    ``line_frequency`` (50 or 60 Hz) adds the electrical check at twice the line frequency.
    """
    rec = as_record(rec, fs=fs)
    idx = response_channel(rec, channel)
    x = clean_signal(rec, idx, min_samples=256)
    ch = rec.channels[idx]
    if rpm is None:
        rpm = rec.meta.get("rpm")
        if rpm is None:
            raise ParameterError("rpm is required (the declared shaft speed), e.g. diagnose(rec, rpm=1797)")
    rpm = positive(rpm, "rpm")
    f1 = rpm / 60.0
    fsr = rec.fs
    T = x.size / fsr
    if T * f1 < 20:
        raise ParameterError(f"the record spans {T * f1:.1f} shaft revolutions ({T:.3g} s at {rpm:g} rpm); at least "
                             f"20 are needed for the order resolution (record {20 / f1:.3g} s or more)")
    if isinstance(bearing, str):
        if bearing not in BEARINGS:
            raise ParameterError(f"bearing={bearing!r} is not in the catalogue {sorted(BEARINGS)}; give a vm.Bearing")
        bearing = BEARINGS[bearing]
    if bearing is not None and not isinstance(bearing, Bearing):
        raise ParameterError(f"bearing must be a vm.Bearing or a catalogue name, got {type(bearing).__name__}")
    if gear is not None and not isinstance(gear, Gear):
        gear = Gear(int(gear))
    group = 2 if machine_group is None else machine_group
    found = "rigid" if foundation is None else foundation
    if (group, found) not in ISO_10816_3:
        raise ParameterError(f"machine_group={machine_group!r}, foundation={foundation!r}: group 1 or 2, "
                             "foundation 'rigid' or 'flexible'")
    bf = bearing.frequencies(f1) if bearing is not None else {}
    for name, f in bf.items():
        if name != "FTF" and 3 * f >= fsr / 2:
            raise ParameterError(f"fs={fsr:g} Hz is too low for the bearing lines: the third harmonic of {name} "
                                 f"({3 * f:.1f} Hz) lies above the Nyquist frequency {fsr / 2:g} Hz")
    if gear is not None and (gear.teeth + 2) * f1 >= fsr / 2:
        raise ParameterError(f"fs={fsr:g} Hz is too low for the gear mesh ({gear.teeth * f1:.1f} Hz) and its sidebands")
    # acceleration in m/s^2 when the unit is known
    a = _units.convert(x, ch.unit, "m/s^2") if ch.unit and ch.quantity == "acceleration" else x
    flags = []
    if not (ch.unit and ch.quantity == "acceleration"):
        flags.append("unit_unknown")

    # --- spectra ------------------------------------------------------------------------------
    n = x.size
    win = np.hanning(n)
    A = np.abs(np.fft.rfft((a - a.mean()) * win)) * 2 / win.sum()
    f = np.fft.rfftfreq(n, 1 / fsr)
    df = f[1]
    with np.errstate(divide="ignore"):
        V = np.where(f > 0, A / (2 * np.pi * np.maximum(f, 1e-12)), 0.0)  # velocity amplitude, m/s
    tol1 = max(2.5 * df, 0.01 * f1)

    # --- running speed and its consistency with fs --------------------------------------------
    f1_found, _, snr1 = _line(f, A, f1, max(0.03 * f1, 2 * df), 10 * f1 * 0.1 + 5 * df)
    speed = {"declared_rpm": rpm, "estimated_rpm": 60 * f1_found if snr1 >= LINE_DB else None,
             "one_x_db": snr1, "consistent": True, "note": ""}
    if snr1 >= LINE_DB:
        f1 = f1_found
    # a 1X that only fits if the real sampling rate is r times the declared one shows at f1 / r
    for r in (4, 2):
        hits = [_line(f, A, k * f1 / r, max(2 * df, 0.01 * k * f1 / r), 0.5 * f1 / r)[2] >= LINE_DB
                for k in range(1, 2 * r) if k % r]
        if r == 4 and sum(hits) >= 3 or r == 2 and all(hits) and snr1 < LINE_DB:
            speed.update(consistent=False, note=(
                f"lines at {1 / r:g}X, ... fit a shaft speed of {rpm:g} rpm only if fs is {r}x the declared "
                f"{fsr:g} Hz ({r * fsr:g} Hz): check the sampling rate"))
            flags.append("speed_inconsistent")
            break
    if bearing is not None:
        bf = bearing.frequencies(f1)  # at the estimated running speed
    if speed["consistent"] and snr1 < LINE_DB:
        speed["note"] = f"no 1X line within 3 % of the declared {rpm:g} rpm"

    # --- severity (ISO 10816-3) -----------------------------------------------------------------
    lo = 2.0 if rpm < 600 else 10.0
    sel = (f >= lo) & (f <= 1000.0)
    v_rms = float(np.sqrt(np.sum(np.abs(np.fft.rfft(a - a.mean())[sel] / (2 * np.pi * f[sel])) ** 2) * 2) / n) \
        * 1e3 if sel.any() else np.nan
    in_scope = ISO_SCOPE_RPM[0] <= rpm <= ISO_SCOPE_RPM[1]
    severity = {"velocity_rms_mm_s": v_rms if "unit_unknown" not in flags else None, "band_hz": [lo, 1000.0],
                "group": group, "foundation": found,
                "zone": severity_zone(v_rms, group=group, foundation=found) if "unit_unknown" not in flags else None,
                "in_scope": in_scope,
                "note": "" if in_scope else f"{rpm:g} rpm is outside ISO 10816-3's 120-15000 rpm: zone is indicative"}
    ab = ISO_10816_3[(group, found)][0]
    # shaft-order faults must matter: nothing below half the zone A/B boundary, full weight from it on
    level = float(np.clip((v_rms - 0.5 * ab) / (0.5 * ab), 0, 1)) if np.isfinite(v_rms) else 1.0

    rows = []

    def add(fault, expected, found_hz, amp, db, conf, note=""):
        rows.append({"fault": fault, "expected_hz": expected, "found_hz": found_hz, "amplitude": amp,
                     "evidence_db": db, "confidence": float(np.clip(conf, 0, 1)), "note": note})

    # --- shaft orders (velocity) -----------------------------------------------------------------
    order = {}
    for k in (0.5, 1, 1.5, 2, 2.5, 3, 4, 5, 6, 7, 8, 9, 10):
        fk = k * f1
        if fk < f[-1]:
            order[k] = _line(f, V, fk, max(tol1, 2 * df), max(0.4 * f1, 10 * df))
    v1 = order[1][1] if order.get(1) and order[1][1] is not None else 0.0
    v2 = order[2][1] if order.get(2) and order[2][1] is not None else 0.0
    v1_rms_mm = v1 / np.sqrt(2) * 1e3
    frac1 = (v1_rms_mm / v_rms) ** 2 if v_rms > 0 else 0.0
    add("unbalance", f1, order[1][0], v1, order[1][2],
        level * np.clip((frac1 - 0.5) / 0.3, 0, 1) * (v2 < 0.5 * v1) * (order[1][2] >= LINE_DB),
        f"1X carries {frac1 * 100:.0f} % of the velocity power")
    ratio = v2 / v1 if v1 > 0 else np.inf
    add("misalignment", 2 * f1, order[2][0], v2, order[2][2],
        level * np.clip((ratio - 0.5) / 0.5, 0, 1) * (order[2][2] >= LINE_DB), f"2X/1X = {ratio:.2f}")
    harmonics = [k for k in (3, 4, 5, 6, 7, 8, 9, 10) if k in order and order[k][2] >= LINE_DB
                 and order[k][1] > 0.1 * max(v1, 1e-300)]
    subs = [k for k in (0.5, 1.5, 2.5) if k in order and order[k][2] >= LINE_DB]
    loose = np.clip((len(harmonics) - 2) / 4 + 0.35 * len(subs), 0, 1) * level
    if "speed_inconsistent" in flags:
        loose *= 0.3  # the sub-harmonics are explained by the sampling-rate contradiction
    add("looseness", f1, None, None, float(len(harmonics)), loose,
        f"{len(harmonics)} harmonics above 2X, sub-harmonics at {subs or 'none'}")

    # --- resonance: the noise floor raised into a hump around a shaft order ---------------------------
    res_conf, res_f, res_db = 0.0, None, 0.0
    for k in (1, 2, 3, 4):
        if k not in order or order[k][2] < LINE_DB:
            continue
        fk = k * f1
        half = max(3.0, 0.1 * fk)
        local = (np.abs(f - fk) <= half) & (np.abs(f - fk) > 4 * df)      # beside the tone, inside a hump
        far = (f > 0.3 * fk) & (f < 3 * fk) & (np.abs(f - fk) > 0.3 * fk)   # the floor away from it
        for j in order:                                                    # other order lines are not floor
            far &= np.abs(f - j * f1) > 4 * df
        if local.sum() < 8 or far.sum() < 8:
            continue
        db = float(20 * np.log10(np.median(V[local]) / max(np.median(V[far]), 1e-300)))
        if db > res_db:
            res_db, res_f = db, float(fk)
    if res_f is not None:
        res_conf = level * float(np.clip((res_db - 10) / 6, 0, 1))
        # an order amplified by a mode next to it is the resonance's doing, not unbalance/misalignment
        for r in rows:
            if (r["fault"] == "unbalance" and abs(res_f - f1) < 0.5 * f1) or \
                    (r["fault"] == "misalignment" and abs(res_f - 2 * f1) < 0.5 * f1):
                r["confidence"] = float(r["confidence"] * (1 - res_conf))
                r["note"] += f"; the order sits on a resonance (hump {res_db:.1f} dB)" if res_conf > 0 else ""
    add("resonance", res_f, res_f, None, res_db, res_conf,
        f"noise floor raised {res_db:.1f} dB around the order at {res_f or 0:.1f} Hz (a structural mode there)")

    # --- twice line frequency (electrical) -------------------------------------------------------------
    if line_frequency is not None:
        lf = positive(line_frequency, "line_frequency")
        fo, am, db = _line(f, A, 2 * lf, max(2.5 * df, 0.002 * lf), max(5.0, 10 * df))
        add("electrical", 2 * lf, fo, am, db, level * float(np.clip((db - LINE_DB) / 12, 0, 1)) *
            (abs(2 * lf - round(2 * lf / f1) * f1) > max(3 * df, 0.01 * f1)),  # not a shaft order in disguise
            f"2 x line frequency ({2 * lf:g} Hz) line {db:.1f} dB")

    # --- bearings (squared-envelope spectrum) -----------------------------------------------------
    env_band = ()
    if bearing is not None:
        from ..signal.demod import envelope_spectrum
        from ..core.record import Record
        f_lo = max(10 * bf["BPFI"], 500.0)
        if band is None:
            b_sel, kurt = _kurtogram_band(a, fsr, f_lo)
            if b_sel is None:
                raise ParameterError(f"fs={fsr:g} Hz leaves no demodulation band above {f_lo:.0f} Hz")
            env_band = b_sel
        else:
            env_band = tuple(band)
        # the fault must show in the most impulsive band and in a broad high band alike
        broad = (max(f_lo, 0.15 * fsr / 2), 0.9 * fsr / 2)
        spectra = [envelope_spectrum(Record(a, fsr), band=b_) for b_ in (env_band, broad)]

        def fam(es, ff, ks=(1, 2, 3)):
            ef, ev = es.freq, es.values[0]
            edf = ef[1]
            ev_sum, best, harm = 0.0, (None, None, -np.inf), 0
            for k in ks:
                fk = k * ff
                fo, am, db = _line(ef, ev, fk, max(2.5 * edf, SLIP * fk), max(0.25 * ff, 10 * edf))
                w = 1.0 if k == 1 else 0.5
                # a line sitting on a shaft harmonic is weaker evidence
                if min(abs(fk - m * f1) for m in range(1, int(fk / f1) + 2)) < max(2.5 * edf, SLIP * fk):
                    w *= 0.3
                ev_sum += w * max(0.0, db - LINE_DB) / 6
                harm += k > 1 and db >= LINE_DB
                if k == 1:
                    best = (fo, am, db)
            return ev_sum, best, harm

        bearing_rows = []
        for fault, key, extra in (("bearing_outer_race", "BPFO", None), ("bearing_inner_race", "BPFI", "1X"),
                                  ("bearing_ball", "2xBSF", "FTF"), ("bearing_cage", "FTF", None)):
            evid, first, harms = [], None, []
            for es in spectra:
                e, b1, h = fam(es, bf[key])
                if fault == "bearing_ball":
                    e2, _, h2 = fam(es, bf["BSF"], (1, 3))
                    e, h = max(e, e2), max(h, h2)
                if extra:
                    side = f1 if extra == "1X" else bf["FTF"]
                    for sgn in (-1, 1):
                        _, _, sdb = _line(es.freq, es.values[0], bf[key] + sgn * side,
                                          max(2.5 * es.freq[1], SLIP * bf[key]), max(side, 10 * es.freq[1]))
                        e += 0.5 * max(0.0, sdb - LINE_DB) / 6
                evid.append(e)
                harms.append(h)
                first = first or b1
            e = min(evid)
            bearing_rows.append([fault, bf[key], first, e, min(harms)])
        for fault, fk, (fo, am, db), e, h in bearing_rows:
            # the strongest other family; a ball fault's cage (FTF) modulation is its own signature
            others = [r[3] for r in bearing_rows if r[0] != fault and not (fault == "bearing_ball"
                                                                           and r[0] == "bearing_cage")]
            second = max(others) if others else 0.0
            dominance = max(0.0, 1 - second / e) if e > 0 else 0.0
            conf = (1 - np.exp(-e / 2)) * dominance * (1.0 if h >= 1 else 0.4)  # harmonics make a fault
            add(fault, fk, fo, am, db, conf, f"{fault.split('_', 1)[1]} family (evidence {e:.2f}, {h} harmonic(s)) "
                f"in the envelope of {env_band[0]:.0f}-{env_band[1]:.0f} Hz and of {broad[0]:.0f}-{broad[1]:.0f} Hz")

    # --- gear mesh ------------------------------------------------------------------------------------
    if gear is not None:
        fm = gear.teeth * f1
        fo, am, db = _line(f, A, fm, max(2.5 * df, 0.005 * fm), max(2 * f1, 10 * df))
        sb = [_line(f, A, fm + s * f1, max(2.5 * df, 0.005 * fm), max(f1, 10 * df))[2] for s in (-1, 1)]
        e = max(0.0, db - LINE_DB) / 6 + sum(0.5 * max(0.0, s - LINE_DB) / 6 for s in sb)
        add("gear_mesh", fm, fo, am, db, (1 - np.exp(-e / 2)) * (sum(s >= LINE_DB for s in sb) >= 1),
            f"mesh {gear.teeth} x 1X with sidebands at +-1X ({sum(s >= LINE_DB for s in sb)} found)")

    import pandas as pd
    table = pd.DataFrame(rows).sort_values("confidence", ascending=False, ignore_index=True)
    best = table.iloc[0]
    second = float(table.iloc[1]["confidence"]) if len(table) > 1 else 0.0
    if best["confidence"] >= TOP_CONFIDENCE and best["confidence"] - second >= 0.15:
        top, conf = str(best["fault"]), float(best["confidence"])
        reason = f"{top}: {best['note']} (confidence {conf:.2f})"
    else:
        top, conf = "none", float(1 - best["confidence"])
        why = "no fault family stands out" if best["confidence"] < TOP_CONFIDENCE else \
            f"{best['fault']} and {table.iloc[1]['fault']} are equally likely"
        reason = f"none: {why}; strongest candidate {best['fault']} at confidence {best['confidence']:.2f}"
    if "speed_inconsistent" in flags:
        reason += "; " + speed["note"]
    return Diagnosis(top, conf, reason, table, speed, severity, tuple(env_band), tuple(flags))
