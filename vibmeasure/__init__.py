"""vibmeasure: vibration measurements to natural frequencies, damping and FRFs you can trust.

>>> import vibmeasure as vm
>>> rec = vm.synth.free_decay(fn=10.37, zeta=0.02, fs=1000.0, duration=10.0, snr_db=40, seed=1)
>>> est = vm.ringdown(rec)          # ModalEstimate: fn, zeta, fn_std, zeta_std, flags
"""

from . import models, synth
from .core import units
from .core.errors import FitError, ParameterError, QualityWarning, UnitError, VibMeasureError
from .core.record import Channel, Record
from .core.results import FRF, Kurtogram, ModalEstimate, Peaks, Spectrogram, Spectrum
from .identify.damping import half_power, hilbert_decay, log_decrement, zeta_from_delta
from .identify.frf import estimate_frf, find_hits, impact_frf
from .identify.modal import circle_fit, fit_modes, mac, modal_crb, synthesize_frf
from .identify.ringdown import ringdown, ringdown_crb
from .models.bearing import BEARINGS, Bearing, Gear
from .monitor.compare import Comparison, History, compare
from .monitor.machinery import Diagnosis, diagnose, severity_zone
from .io import LazyRecord, read, read_frf, read_spectrum, write
from .io import open_record as open  # noqa: A001  (vm.open: the documented name)
from .signal.demod import envelope, envelope_spectrum, order_track, time_synchronous_average
from .signal.kurtogram import band_ses, kurtogram
from .signal.whiten import prewhiten, remove_synchronous
from .signal.peaks import harmonic_family, pick_peaks, sideband_family
from .signal.preprocess import decimate, detrend, differentiate, integrate, resample
from .signal.preprocess import filter  # noqa: A004  (vm.filter: Butterworth, zero-phase)
from .signal.spectral import amplitude_spectrum, band_rms, coherence, csd, octave_bands, psd, spectrogram

__version__ = "0.1.0"

__all__ = [
    "Channel", "Record", "LazyRecord", "ModalEstimate", "FRF", "Spectrum", "Spectrogram", "Peaks", "Kurtogram",
    "VibMeasureError", "ParameterError", "UnitError", "FitError", "QualityWarning",
    "read", "write", "open", "read_frf", "read_spectrum",
    "amplitude_spectrum", "psd", "csd", "coherence", "spectrogram", "band_rms", "octave_bands",
    "pick_peaks", "harmonic_family", "sideband_family", "envelope", "envelope_spectrum", "order_track", "time_synchronous_average",
    "prewhiten", "remove_synchronous", "kurtogram", "band_ses",
    "detrend", "filter", "decimate", "resample", "integrate", "differentiate",
    "ringdown", "ringdown_crb", "estimate_frf", "impact_frf", "find_hits", "fit_modes", "circle_fit", "mac",
    "modal_crb", "synthesize_frf", "log_decrement", "hilbert_decay", "half_power", "zeta_from_delta",
    "compare", "Comparison", "History", "diagnose", "Diagnosis", "severity_zone", "Bearing", "Gear", "BEARINGS", "models", "synth", "units", "__version__",
]
