"""Sections for results a user hands to ``vm.report`` (nothing is analysed again): an estimate, a
diagnosis or a comparison alone, or paired with what it was computed from, ``(record, estimate)``,
``(record, diagnosis)`` or ``(frf, estimate)``, so the figures that need the data can be drawn."""

from __future__ import annotations

import hashlib
import json

from ..core.errors import ParameterError
from ..core.record import Record
from ..core.results import FRF, Comparison, Diagnosis, ModalEstimate
from .sections import comparison_section, diagnosis_section, modes_section, ringdown_section

RESULT_TYPES = (ModalEstimate, Diagnosis, Comparison)
_MODES_METHODS = ("fit_modes", "oma_ssi", "oma_fdd")


def is_result(item) -> bool:
    """True for a result, or a pair (source, result), that ``result_sections`` reports."""
    if isinstance(item, tuple) and len(item) == 2:
        return isinstance(item[0], (Record, FRF)) and isinstance(item[1], RESULT_TYPES)
    return isinstance(item, RESULT_TYPES)


def result_sections(item, index: int) -> tuple[list, dict]:
    """(sections, provenance row) for a result or a (source, result) pair handed in by the user."""
    source, res = item if isinstance(item, tuple) else (None, item)
    name = _name(source, res, index)
    rec = source if isinstance(source, Record) else None
    frf = source if isinstance(source, FRF) else None
    if isinstance(res, Comparison):
        secs = [comparison_section(res, name)]
    elif isinstance(res, Diagnosis):
        secs = [diagnosis_section(rec, res, name)]
    elif res.method in _MODES_METHODS:
        secs = [modes_section(frf, res, name)]
    elif frf is not None:
        raise ParameterError(f"inputs[{index}]: an FRF pairs with a fit_modes estimate, got method {res.method!r}")
    else:
        secs = [ringdown_section(rec, res, name)]
    method = getattr(res, "method", "") or type(res).__name__.lower()
    return secs, {"input": name, "sha256": _digest(res), "method": f"given as a result ({method})"}


def _name(source, res, index: int) -> str:
    if isinstance(source, Record):
        return str(source.meta.get("source") or "record")
    if isinstance(source, FRF):
        return "FRF " + ", ".join(f"{o}/{i}" for o in source.outputs[:2] for i in source.inputs[:1])
    return f"{type(res).__name__} (input {index + 1})"


def _digest(res) -> str:
    """The provenance hash of a result: SHA-256 of its JSON form (``to_dict``), so the page names what
    it shows even without a file."""
    try:
        text = json.dumps(res.to_dict(), sort_keys=True, default=str)
    except (AttributeError, TypeError, ValueError):
        return "(result)"
    return hashlib.sha256(text.encode()).hexdigest()
