"""Human names for the identifiers results carry (fault families, trend metrics, summary columns):
one table, read by the report's tables, the plots' axes and the command line's text, so that
``bearing_outer_race`` reads "bearing outer race" and ``velocity_rms_mm_s`` "velocity RMS [mm/s]"
everywhere. The identifiers themselves stay what scripts and JSON use."""

from __future__ import annotations

import re

__all__ = ["LABELS", "label"]

LABELS = {
    "bearing_outer_race": "bearing outer race",
    "bearing_inner_race": "bearing inner race",
    "bearing_ball": "bearing rolling element (ball)",
    "bearing_cage": "bearing cage",
    "gear_mesh": "gear mesh",
    "unbalance": "unbalance",
    "misalignment": "misalignment",
    "looseness": "mechanical looseness",
    "resonance": "structural resonance",
    "electrical": "electrical (2 x line)",
    "none": "no fault",
    "undetermined": "undetermined",
    "velocity_rms_mm_s": "velocity RMS [mm/s]",
    "bearing_evidence": "bearing evidence [-log10 p]",
    "gear_na4": "gear NA4",
    "gear_mating_na4": "mating gear NA4",
    "rms": "RMS",
    "zone": "ISO zone",
    "top": "diagnosis",
    "confidence": "confidence",
}

_SUFFIX_UNITS = {"hz": "Hz", "mm_s": "mm/s", "db": "dB", "s": "s", "g": "g", "m_s2": "m/s²", "pct": "%"}
_MODE = re.compile(r"^(fn|zeta|fn_std|zeta_std)(\d+)(?:_(hz|std))?$")


def label(key, unit: str | None = None) -> str:
    """The human name of an identifier, with its unit in brackets.

    Known identifiers come from ``LABELS``; a mode's metric (``fn1_hz``, ``zeta2``, ``fn1_std``) reads
    "fn, mode 1 [Hz]"; any other ``a_b_hz`` reads "a b [Hz]" (the unit from its suffix, or ``unit``).

    Parameters
    ----------
    key : str
        The identifier.
    unit : str, optional
        A unit to show when the identifier carries none.

    Returns
    -------
    str

    Examples
    --------
    >>> from vibmeasure.core.labels import label
    >>> label("bearing_outer_race"), label("velocity_rms_mm_s"), label("fn1_hz"), label("zeta2")
    ('bearing outer race', 'velocity RMS [mm/s]', 'fn, mode 1 [Hz]', 'zeta, mode 2')
    """
    k = str(key)
    if k in LABELS:
        text = LABELS[k]
    else:
        m = _MODE.match(k)
        if m:
            what, n, suffix = m.groups()
            std = what.endswith("_std") or suffix == "std"
            base = what.replace("_std", "")
            text = f"{base}{' std' if std else ''}, mode {n}"
            if base == "fn":
                text += " [Hz]"
        else:
            text = k
            for suf, u in sorted(_SUFFIX_UNITS.items(), key=lambda kv: -len(kv[0])):
                if k.endswith("_" + suf) and len(k) > len(suf) + 1:
                    text = f"{k[:-len(suf) - 1].replace('_', ' ')} [{u}]"
                    break
            else:
                text = k.replace("_", " ")
    if unit and "[" not in text:
        text += f" [{unit}]"
    return text
