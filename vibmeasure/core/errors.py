"""The exceptions and warnings of vibmeasure.

One root exception, :class:`VibMeasureError`; bad arguments raise
:class:`ParameterError` (a :class:`ValueError`), unit mismatches :class:`UnitError`,
identification that cannot give a sound answer :class:`FitError` (a
:class:`RuntimeError`). Results that are usable but need care come with a
:class:`QualityWarning` and flags on the result.
"""

from __future__ import annotations

import warnings

__all__ = ["VibMeasureError", "ParameterError", "UnitError", "FitError", "QualityWarning", "warn_quality"]


class VibMeasureError(Exception):
    """Root of all vibmeasure exceptions."""


class ParameterError(VibMeasureError, ValueError):
    """An argument breaks a rule; the message names the argument, its value and the rule."""


class UnitError(ParameterError):
    """A unit does not fit the quantity, or two units cannot be converted."""


class FitError(VibMeasureError, RuntimeError):
    """Identification cannot give a sound answer from this data."""


class QualityWarning(UserWarning):
    """A result is returned, but a quality finding (see its ``flags``) limits its trust."""


def warn_quality(message: str, *, stacklevel: int = 3) -> None:
    """Issue a :class:`QualityWarning` pointing at the caller of the public function."""
    warnings.warn(message, QualityWarning, stacklevel=stacklevel)
