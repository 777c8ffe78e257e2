"""Result objects: data and derived properties, no algorithms. One module per kind: modal.py
(ModalEstimate), spectra.py (Spectrum, Spectrogram, Peaks, Kurtogram), frf.py (FRF), shock.py
(ShockSpectrum, Transmissibility), loop.py (LoopDamping), verdicts.py (Diagnosis, Comparison); _common.py holds the flags' text
and ``jsonable``, the one conversion to JSON."""

from ._common import FLAG_TEXT, jsonable
from .frf import FORM_OF_QUANTITY, FRF, form_of
from .loop import LoopDamping
from .modal import ModalEstimate
from .shock import ShockSpectrum, Transmissibility
from .spectra import Kurtogram, Peaks, Spectrogram, Spectrum
from .verdicts import Comparison, Diagnosis

__all__ = ["ModalEstimate", "Spectrum", "Spectrogram", "Peaks", "FRF", "Kurtogram", "FLAG_TEXT", "jsonable", "Diagnosis",
           "Comparison", "ShockSpectrum", "Transmissibility", "LoopDamping", "form_of", "FORM_OF_QUANTITY"]
