"""Which analysis a record calls for: the one rule the report, the batch's "auto" task and the
command line share."""

from __future__ import annotations

__all__ = ["analysis_for", "ANALYSES"]

ANALYSES = ("modes", "diagnose", "ringdown")


def analysis_for(rec, *, rpm=None, tach=None) -> str:
    """The analysis a record's content calls for.

    A force channel makes it a hammer or shaker test ("modes": FRFs and fit_modes); a shaft speed
    (``rpm``, a tachometer channel ``tach``, or the record's ``meta["rpm"]``) makes it a machine
    ("diagnose"); anything else is a free decay ("ringdown").

    Parameters
    ----------
    rec : vm.Record
        The record.
    rpm : float, optional
        The declared shaft speed.
    tach : str or int, optional
        The tachometer channel.

    Returns
    -------
    str
        "modes", "diagnose" or "ringdown".

    Raises
    ------
    ParameterError
        When ``rec`` is not a record (read a file with ``vm.read`` first).

    Examples
    --------
    >>> import vibmeasure as vm
    >>> from vibmeasure.core.dispatch import analysis_for
    >>> analysis_for(vm.synth.free_decay(fn=10.0, zeta=0.02, fs=500.0, duration=4.0))
    'ringdown'
    >>> analysis_for(vm.synth.machine(rpm=1797, duration=1.0))
    'diagnose'
    """
    from .errors import ParameterError
    from .record import Record
    if not isinstance(rec, Record) and not hasattr(rec, "channels"):   # a Record or a LazyRecord
        raise ParameterError(f"rec must be a vm.Record (read the file with vm.read first), got {type(rec).__name__}")
    if any(c.quantity == "force" for c in rec.channels):
        return "modes"
    if rpm or tach is not None or rec.meta.get("rpm"):
        return "diagnose"
    return "ringdown"
