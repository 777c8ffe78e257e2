"""Which analysis a record calls for: the one rule the report, the batch's "auto" task and the
command line share."""

from __future__ import annotations

__all__ = ["analysis_for", "ANALYSES", "load_input", "mark_force"]

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


def mark_force(rec, channel):
    """The record with ``channel`` marked as the force (the hammer's or shaker's input): its quantity
    "force", its unit left to the file (a unit given for the responses is not the force's).

    Parameters
    ----------
    rec : vm.Record
        The record.
    channel : str or int
        The input channel.

    Returns
    -------
    vm.Record
        A new record; the history says which channel was marked.

    Raises
    ------
    ParameterError
        For a channel the record does not have (the message lists its channels).

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> from vibmeasure.core.dispatch import mark_force, analysis_for
    >>> rec = vm.Record(np.random.default_rng(0).normal(size=(2, 100)), fs=100.0, channels=["hammer", "acc"])
    >>> analysis_for(mark_force(rec, "hammer"))
    'modes'
    """
    import dataclasses

    from .errors import ParameterError
    try:
        i = rec.index(channel)
    except (ParameterError, IndexError, KeyError):
        raise ParameterError(f"input channel {channel!r} is not in this record; its channels are {rec.names}") \
            from None
    chans = list(rec.channels)
    if chans[i].quantity == "force":
        return rec
    unit = chans[i].unit if chans[i].unit in ("N", "kN", "lbf") else ""
    chans[i] = dataclasses.replace(chans[i], quantity="force", unit=unit)
    return rec.replace(channels=tuple(chans), note=f"channel {chans[i].name!r} marked as force")


def load_input(item, *, fs=None, unit=None, channels=None, input=None):
    """The record an input names, prepared the same way for the report, the batch and the command line.

    A path is read (``fs`` and ``unit`` for files that do not say); a ``vm.Record`` is taken as it
    is. ``channels`` keeps only those channels (the input channel is kept beside them), ``input``
    marks the force channel, so that :func:`analysis_for` makes it a hammer or shaker test.

    Parameters
    ----------
    item : str, os.PathLike or vm.Record
        A record file or a record.
    fs : float, optional
        Sampling rate for a file without timing.
    unit : str, optional
        Unit of the data when the file does not say (e.g. "g").
    channels : str or sequence of str, optional
        The channels to analyse (default: every channel).
    input : str, optional
        The force channel of a hammer or shaker test.

    Returns
    -------
    (vm.Record, str)
        The record and its name for tables and titles (the file name, or the record's
        ``meta["source"]`` or "record").

    Raises
    ------
    ParameterError
        For an unreadable file, an unknown channel, or an item that is neither a path nor a record.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> from vibmeasure.core.dispatch import load_input
    >>> rec, name = load_input(vm.synth.free_decay(fn=10.0, zeta=0.02, fs=500.0, duration=2.0))
    >>> name, rec.n_channels
    ('record', 1)
    """
    import os
    from pathlib import Path

    from .errors import ParameterError
    from .record import Record
    if isinstance(item, Record):
        rec, name = item, str(item.meta.get("source") or "record")
        if fs is not None or unit is not None:
            raise ParameterError("fs= and unit= apply to files; a vm.Record carries its own (use rec.to_unit or "
                                 "vm.Record.from_array to change them)")
    elif isinstance(item, (str, os.PathLike)):
        from .. import io
        rec, name = io.read(item, fs=fs, unit=unit), Path(item).name
    else:
        raise ParameterError(f"an input must be a file path or a vm.Record, got {type(item).__name__} (vm.report "
                             "also takes a ModalEstimate, Diagnosis or Comparison, alone or as (record, result))")
    if channels is not None:
        keep = [channels] if isinstance(channels, str) else list(channels)
        if input is not None and input not in keep:
            keep.append(input)
        rec = rec.select(keep)
    if input is not None:
        rec = mark_force(rec, input)
    return rec, name
