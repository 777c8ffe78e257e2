"""Machine fault diagnosis: ``diagnose`` reads as its steps (pipeline.py), one module a step."""

from ...core.results import Diagnosis
from .iso import ISO_10816_3, severity_zone
from .pipeline import diagnose

__all__ = ["diagnose", "Diagnosis", "ISO_10816_3", "severity_zone"]
