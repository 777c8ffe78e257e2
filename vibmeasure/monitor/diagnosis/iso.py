"""ISO 10816-3 (machines 15 kW - 50 MW, 120-15 000 rpm): the zone boundaries and the zone of a
velocity RMS."""

from __future__ import annotations

from ...core.errors import ParameterError

__all__ = ["ISO_10816_3", "ISO_SCOPE_RPM", "severity_zone"]

# ISO 10816-3:2009, Annex A (Tables A.1 and A.2): zone boundaries A/B, B/C, C/D in mm/s RMS,
# velocity 10-1000 Hz (2-1000 Hz below 600 rpm). Group 1: large machines, 300 kW - 50 MW;
# group 2: medium machines, 15 - 300 kW. Scope: 120 - 15 000 rpm.
ISO_10816_3 = {(1, "rigid"): (2.3, 4.5, 7.1), (1, "flexible"): (3.5, 7.1, 11.0),
               (2, "rigid"): (1.4, 2.8, 4.5), (2, "flexible"): (2.3, 4.5, 7.1)}
ISO_SCOPE_RPM = (120.0, 15000.0)


def severity_zone(v_rms_mm_s: float, *, group: int = 2, foundation: str = "rigid") -> str:
    """ISO 10816-3 zone of an overall velocity RMS for a machine group and foundation.

    Parameters
    ----------
    v_rms_mm_s : float
        Velocity RMS in mm/s over the standard's band (10-1000 Hz; 2-1000 Hz below 600 rpm).
    group : {1, 2}
        Group 1: large machines (300 kW - 50 MW); group 2: medium machines (15 - 300 kW).
    foundation : {"rigid", "flexible"}
        Rigid when the lowest support mode lies above the running speed.

    Returns
    -------
    str
        "A", "B", "C" or "D".

    Raises
    ------
    ParameterError
        For a group or foundation the standard does not define.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> vm.severity_zone(3.2, group=2, foundation="rigid")
    'C'
    """
    key = (int(group), foundation)
    if key not in ISO_10816_3:
        raise ParameterError(f"machine_group={group!r}, foundation={foundation!r}: group 1 or 2, rigid or flexible")
    ab, bc, cd = ISO_10816_3[key]
    return "A" if v_rms_mm_s < ab else "B" if v_rms_mm_s < bc else "C" if v_rms_mm_s < cd else "D"
