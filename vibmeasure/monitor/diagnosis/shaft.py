"""Step: shaft-order faults from the velocity and acceleration spectra: unbalance, misalignment,
looseness, resonance and twice line frequency (electrical); the gear has its own step (``gears``). Each returns table rows with
a confidence scaled by ``level`` (0 below half the ISO zone A/B boundary, 1 from it on): a shaft-order
fault must matter in the overall level before it is called."""

from __future__ import annotations

import numpy as np

from ...core._validate import positive
from .lines import LINE_DB, _line, _row, _spectrum

ORDERS = (0.5, 1, 1.5, 2, 2.5, 3, 4, 5, 6, 7, 8, 9, 10)
# Looseness and misalignment are weighed by the share of the velocity power their own lines carry (2X
# and up with the half orders; 1X and 2X), at full weight from SHAFT_SHARE on. The ISO level gate alone
# let a clean floor's small shaft harmonics through wherever something else (a bearing's impacts,
# broadband noise) made the level: on the eight MFPT records (1.7-3.2 mm/s, zones B and C) 2-6
# harmonics stand 12 dB above the floor but carry 0.5-5.8 % of the velocity power, and "looseness"
# (score up to 1.00) was the answer wherever the bearing's evidence fell short
# (benchmarks/diagnosis_robustness.py: a knock, a noise burst). On a healthy synthetic machine with
# strong shaft-rate impacts (a rub) 2X/1X = 1.14 made "misalignment" though 1X and 2X carry 9 %. The
# synthetic machines' looseness carries 57-76 % (10 to -10 dB), their misalignment 46-79 %; unbalance
# already needs its 1X to carry half the velocity power and more. Without the data's unit (v_rms NaN)
# no share is weighed: the patterns are then named, never called.
SHAFT_SHARE = 0.2


def _orders(f, V, f1):
    df = f[1]
    tol1 = max(2.5 * df, 0.01 * f1)
    return {k: _line(f, V, k * f1, max(tol1, 2 * df), max(0.4 * f1, 10 * df)) for k in ORDERS if k * f1 < f[-1]}


def shaft_order_rows(f, V, f1, v_rms, level, flags):
    """Unbalance (1X dominates the velocity), misalignment (2X against 1X), looseness (many
    harmonics and half orders). Returns (rows, orders)."""
    order = _orders(f, V, f1)
    v1 = order[1][1] if order.get(1) and order[1][1] is not None else 0.0
    v2 = order[2][1] if order.get(2) and order[2][1] is not None else 0.0
    v1_rms_mm = v1 / np.sqrt(2) * 1e3
    frac1 = (v1_rms_mm / v_rms) ** 2 if v_rms > 0 else 0.0
    rows = [_row("unbalance", f1, order[1][0], v1, order[1][2],
                level * np.clip((frac1 - 0.5) / 0.3, 0, 1) * (v2 < 0.5 * v1) * (order[1][2] >= LINE_DB),
                f"1X carries {frac1 * 100:.0f} % of the velocity power")]
    ratio = v2 / v1 if v1 > 0 else np.inf
    share2 = ((v1 ** 2 + v2 ** 2) / 2 * 1e6) / v_rms ** 2 if v_rms > 0 else 1.0   # 1X and 2X's share
    mis = level * np.clip((ratio - 0.5) / 0.5, 0, 1) * (order[2][2] >= LINE_DB) * min(1.0, share2 / SHAFT_SHARE)
    rows.append(_row("misalignment", 2 * f1, order[2][0], v2, order[2][2], mis,
                    f"2X/1X = {ratio:.2f}; 1X and 2X carry {100 * share2:.0f} % of the velocity power"))
    harmonics = [k for k in (3, 4, 5, 6, 7, 8, 9, 10) if k in order and order[k][2] >= LINE_DB
                 and order[k][1] > 0.1 * max(v1, 1e-300)]
    subs = [k for k in (0.5, 1.5, 2.5) if k in order and order[k][2] >= LINE_DB]
    # its lines (2X and up, the half orders) must carry the level the ISO gate weighs
    own = harmonics + subs + ([2] if order.get(2) and order[2][2] >= LINE_DB else [])
    share = sum((order[k][1] / np.sqrt(2) * 1e3) ** 2 for k in own) / v_rms ** 2 if v_rms > 0 else 1.0
    loose = np.clip((len(harmonics) - 2) / 4 + 0.35 * len(subs), 0, 1) * level * min(1.0, share / SHAFT_SHARE)
    if "speed_inconsistent" in flags:
        loose *= 0.3  # the sub-harmonics are explained by the sampling-rate contradiction
    rows.append(_row("looseness", f1, None, None, float(len(harmonics)), loose,
                    f"{len(harmonics)} harmonics above 2X, sub-harmonics at {subs or 'none'}; they carry "
                    f"{100 * share:.0f} % of the velocity power"))
    return rows, order


def resonance_row(f, V, f1, order, level, rows):
    """The noise floor raised into a hump around a shaft order: a structural mode there (V: an
    acceleration spectrum, flat for broadband forces, with a low-sidelobe window; lines +-6 bins left
    out). An order
    amplified by it is the resonance's doing, so unbalance/misalignment next to it lose confidence."""
    df = f[1]
    res_f, res_db = None, 0.0
    for k in (1, 2, 3, 4):
        if k not in order or order[k][2] < LINE_DB:
            continue
        fk = k * f1
        half = max(3.0, 0.1 * fk)
        local = (np.abs(f - fk) <= half) & (np.abs(f - fk) > 6 * df)      # beside the tone, inside a hump
        far = (f > 0.3 * fk) & (f < 3 * fk) & (np.abs(f - fk) > 0.3 * fk)   # the floor away from it
        for j in order:                                                    # other order lines are not floor
            far &= np.abs(f - j * f1) > 6 * df
        if local.sum() < 8 or far.sum() < 8:
            continue
        db = float(20 * np.log10(np.median(V[local]) / max(np.median(V[far]), 1e-300)))
        if db > res_db:
            res_db, res_f = db, float(fk)
    # a healthy machine's acceleration floor is flat to about 1 dB around the orders: a hump from 5 dB
    # on is a mode (full weight at 10 dB); from 2 dB on it already casts doubt on the order's own fault
    res_conf = level * float(np.clip((res_db - 5) / 5, 0, 1)) if res_f is not None else 0.0
    doubt = level * float(np.clip((res_db - 2) / 4, 0, 1)) if res_f is not None else 0.0
    for r in rows:
        if res_f is not None and ((r["fault"] == "unbalance" and abs(res_f - f1) < 0.5 * f1) or
                                  (r["fault"] == "misalignment" and abs(res_f - 2 * f1) < 0.5 * f1)):
            r["confidence"] = float(r["confidence"] * (1 - doubt))
            r["note"] += f"; the order sits on a resonance (hump {res_db:.1f} dB)" if doubt > 0 else ""
    return _row("resonance", res_f, res_f, None, res_db, res_conf,
               f"noise floor raised {res_db:.1f} dB around the order at {res_f or 0:.1f} Hz (a structural mode there)")


def electrical_row(f, A, f1, line_frequency, level):
    """Twice line frequency (stator, air gap): a 2 x line line that is not a shaft order in disguise."""
    df = f[1]
    lf = positive(line_frequency, "line_frequency")
    fo, am, db = _line(f, A, 2 * lf, max(2.5 * df, 0.002 * lf), max(5.0, 10 * df))
    not_order = abs(2 * lf - round(2 * lf / f1) * f1) > max(3 * df, 0.01 * f1)
    return _row("electrical", 2 * lf, fo, am, db, level * float(np.clip((db - LINE_DB) / 12, 0, 1)) * not_order,
               f"2 x line frequency ({2 * lf:g} Hz) line {db:.1f} dB")


SHAFT_FAULTS = ("unbalance", "misalignment", "looseness", "resonance", "electrical", "gear_mesh")


def shaft_rows(run, supply, gate: tuple, line_frequency) -> list:
    """Unbalance, misalignment, looseness, resonance and (with ``line_frequency``) electrical rows, from
    the primary channel without the supply's lines, weighed by the level (``gate``)."""
    level, v_rms, level_all = gate
    _, _, V = _spectrum(supply.shaft_job)
    rows, order = shaft_order_rows(run.f, V, run.f1, v_rms, level, run.job.flags)
    rows.append(resonance_row(run.f, _spectrum(supply.shaft_job, "blackmanharris")[1], run.f1, order, level, rows))
    if line_frequency is not None:
        rows.append(electrical_row(run.f, run.A, run.f1, line_frequency, level_all))
    return rows


def gate_rows(rows: list, flags: list, contradicted: bool) -> None:
    """Rows that cannot be weighed are not called: shaft orders smear where the speed varies unfollowed,
    and every line is looked for at a wrong frequency where the declared speed is contradicted."""
    if "speed_varies" in flags and "order_tracked" not in flags:
        for r in rows:
            if r["fault"] in SHAFT_FAULTS and r["confidence"] > 0:
                r["note"] = "not called, the speed varies over the record: " + r["note"]
                r["confidence"] = 0.0
    if contradicted:
        for r in rows:
            if r["confidence"] > 0:
                r["note"] = "not called, the declared speed is contradicted: " + r["note"]
            r["confidence"] = 0.0
