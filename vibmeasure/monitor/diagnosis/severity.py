"""Step: the ISO 10816-3 severity of the primary channel as measured, and the weight a shaft-order fault
gets from the level (``iso_severity``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from scipy import fft as _sfft

from .iso import ISO_10816_3, ISO_SCOPE_RPM, severity_zone

if TYPE_CHECKING:   # for annotations only
    from .job import Job


def _without_drift(a: np.ndarray) -> np.ndarray:
    """``a`` less its least-squares quadratic: an offset, a drift and its curvature (shaft orders from
    10 Hz up over 20 revolutions or more are orthogonal to it to a part in 10^4)."""
    t = np.linspace(-1.0, 1.0, a.size)
    basis = np.stack([np.ones_like(t), t, 1.5 * t ** 2 - 0.5])
    return a - np.linalg.lstsq(basis.T, a, rcond=None)[0] @ basis


def _severity(job: Job, f, rpm, electrical_hz=(), electrical_amp=()):
    """ISO 10816-3 severity of the primary channel; the weight (0-1) a shaft-order fault gets from the
    level, and the velocity RMS that weight is taken from: the channel's without the supply's lines at
    ``electrical_hz`` with their acceleration amplitudes ``electrical_amp`` (``_supply_part``); and the
    weight from the overall level (the electrical fault's: its lines are the supply's). The severity
    reported is the overall one the standard defines, with the supply's part named."""
    lo = 2.0 if rpm < 600 else 10.0
    sel = (f >= lo) & (f <= 1000.0)
    n = job.a.size
    # the transients gated out (``_damage``) hold no power: the rest of the record stands for the whole
    kept = 1.0 - job.quality.get(job.primary, {}).get("transient_share", 0.0)
    # the standard's band must hold: a drift (thermal, an integrating amplifier) is taken off, or its
    # leakage over the record's ends (1/f, divided again by 2 pi f for velocity)
    # fills the band: 0.3 g/s read zone C on a zone-A machine. (No window: the gated transients' share
    # ``kept`` restores the power of a rectangular record.)
    spec = _sfft.rfft(_without_drift(job.a))
    v_rms = float(np.sqrt(np.sum(np.abs(spec[sel] / (2 * np.pi * f[sel])) ** 2) * 2 / kept) / n) * 1e3 \
        if sel.any() else np.nan
    hz, amp = np.asarray(electrical_hz, float), np.asarray(electrical_amp, float)
    inside = (hz >= lo) & (hz <= 1000.0)
    v_el = float(np.sqrt(np.sum((amp[inside] / (2 * np.pi * hz[inside])) ** 2) / 2)) * 1e3
    v_gate = float(np.sqrt(max(v_rms ** 2 - v_el ** 2, 0.0))) if np.isfinite(v_rms) else v_rms
    known = "unit_unknown" not in job.flags
    in_scope = ISO_SCOPE_RPM[0] <= rpm <= ISO_SCOPE_RPM[1]
    severity = {"velocity_rms_mm_s": v_rms if known else None, "band_hz": [lo, 1000.0], "group": job.group,
                "foundation": job.foundation, "zone": severity_zone(v_rms, group=job.group, foundation=job.foundation)
                if known else None, "in_scope": in_scope,
                "note": "" if in_scope else f"{rpm:g} rpm is outside ISO 10816-3's 120-15000 rpm: zone is indicative"}
    if electrical_hz and known:
        severity["electrical_velocity_rms_mm_s"] = v_el
        severity["note"] = "; ".join(filter(None, [severity["note"], (
            f"{v_el:.3g} mm/s of it stands at the supply's lines ({', '.join(f'{h:.1f}' for h in electrical_hz)} "
            f"Hz: pickup or the motor's electromagnetic force); shaft-order faults are weighed on the "
            f"{v_gate:.3g} mm/s without them")]))
    ab = ISO_10816_3[(job.group, job.foundation)][0]
    # shaft-order faults must matter: nothing below half the zone A/B boundary, full weight from it on
    def weight(v):
        return float(np.clip((v - 0.5 * ab) / (0.5 * ab), 0, 1)) if np.isfinite(v_rms) and known else 1.0

    return severity, weight(v_gate), v_gate, weight(v_rms)


def iso_severity(measured: Job, job: Job, supply) -> tuple[dict, tuple]:
    """(severity, (level weight, velocity RMS without the supply's lines, level weight of the overall
    RMS)) of the record as measured (``measured``: before order tracking); a channel that saturated
    gives a lower bound."""
    f = np.fft.rfftfreq(measured.a.size, 1 / measured.fs)
    severity, level, v_rms, level_all = _severity(measured, f, measured.rpm, supply.hz, supply.amp)
    if severity["velocity_rms_mm_s"] is None:
        v_rms = np.nan
    saturated = job.quality.get(job.primary, {}).get("saturated_share")
    if saturated and severity["velocity_rms_mm_s"] is not None:
        # the peaks beyond the converter's range are lost: what is measured is less than what shook
        severity["lower_bound"] = True
        severity["note"] = "; ".join(filter(None, [severity["note"], (
            f"the channel saturated ({100 * saturated:.2g} % of its samples at its extremes): the level is a "
            f"lower bound")]))
    return severity, (level, v_rms, level_all)
