"""vibmeasure: vibration measurements to natural frequencies, damping and FRFs you can trust.

>>> import vibmeasure as vm
>>> rec = vm.synth.free_decay(fn=10.37, zeta=0.02, fs=1000.0, duration=10.0, snr_db=40, seed=1)
>>> est = vm.ringdown(rec)          # ModalEstimate: fn, zeta, fn_std, zeta_std, flags

The data model and errors load with the package; every analysis module (and scipy behind it) loads
on first use of its name, so ``import vibmeasure`` and ``vibmeasure --help`` start fast.
"""

from importlib import import_module as _import_module

from .core import units
from .core.errors import FitError, ParameterError, QualityWarning, UnitError, VibMeasureError
from .core.record import Channel, Record
from .core.results import FRF, Kurtogram, ModalEstimate, Peaks, Spectrogram, Spectrum

__version__ = "0.1.0"

# public name -> (module, attribute): imported when first used (PEP 562)
_LAZY = {
    "half_power": (".identify.halfpower", "half_power"),
    "loop_damping": (".identify.loop", "loop_damping"),
    "stepped_sine": (".identify.stepped", "stepped_sine"),
    "antiresonances": (".identify.antiresonance", "antiresonances"),
    "LoopDamping": (".core.results", "LoopDamping"),
    "hilbert_decay": (".identify.damping", "hilbert_decay"),
    "log_decrement": (".identify.damping", "log_decrement"),
    "zeta_from_delta": (".identify.damping", "zeta_from_delta"),
    "estimate_frf": (".identify.frf", "estimate_frf"),
    "find_hits": (".identify.frf", "find_hits"),
    "impact_frf": (".identify.frf", "impact_frf"),
    "circle_fit": (".identify.modal", "circle_fit"),
    "oma_ssi": (".identify.oma", "oma_ssi"),
    "oma_fdd": (".identify.oma", "oma_fdd"),
    "oma_cross_check": (".identify.oma", "oma_cross_check"),
    "fit_modes": (".identify.modal", "fit_modes"),
    "mac": (".identify.shapes", "mac"),
    "modal_crb": (".identify.modal", "modal_crb"),
    "synthesize_frf": (".identify.modal", "synthesize_frf"),
    "ringdown": (".identify.ringdown", "ringdown"),
    "ringdown_crb": (".identify.ringdown", "ringdown_crb"),
    "BEARINGS": (".models.bearing", "BEARINGS"),
    "Bearing": (".models.bearing", "Bearing"),
    "Gear": (".models.bearing", "Gear"),
    "Comparison": (".core.results", "Comparison"),
    "History": (".monitor.compare", "History"),
    "compare": (".monitor.compare", "compare"),
    "Diagnosis": (".core.results", "Diagnosis"),
    "diagnose": (".monitor.diagnosis", "diagnose"),
    "severity_zone": (".monitor.diagnosis", "severity_zone"),
    "LazyRecord": (".io", "LazyRecord"),
    "read": (".io", "read"),
    "read_frf": (".io", "read_frf"),
    "read_spectrum": (".io", "read_spectrum"),
    "write": (".io", "write"),
    "open": (".io", "open_record"),
    "envelope": (".signal.demod", "envelope"),
    "envelope_spectrum": (".signal.demod", "envelope_spectrum"),
    "order_track": (".signal.demod", "order_track"),
    "time_synchronous_average": (".signal.demod", "time_synchronous_average"),
    "band_ses": (".signal.kurtogram", "band_ses"),
    "kurtogram": (".signal.kurtogram", "kurtogram"),
    "prewhiten": (".signal.whiten", "prewhiten"),
    "remove_synchronous": (".signal.whiten", "remove_synchronous"),
    "harmonic_family": (".signal.peaks", "harmonic_family"),
    "pick_peaks": (".signal.peaks", "pick_peaks"),
    "sideband_family": (".signal.peaks", "sideband_family"),
    "decimate": (".signal.preprocess", "decimate"),
    "detrend": (".signal.preprocess", "detrend"),
    "differentiate": (".signal.preprocess", "differentiate"),
    "integrate": (".signal.preprocess", "integrate"),
    "resample": (".signal.preprocess", "resample"),
    "filter": (".signal.preprocess", "filter"),
    "despike": (".signal.quality", "despike"),
    "amplitude_spectrum": (".signal.spectral", "amplitude_spectrum"),
    "band_rms": (".signal.bands", "band_rms"),
    "coherence": (".signal.spectral", "coherence"),
    "csd": (".signal.spectral", "csd"),
    "octave_bands": (".signal.bands", "octave_bands"),
    "srs": (".signal.shock", "srs"),
    "transmissibility": (".signal.shock", "transmissibility"),
    "psd": (".signal.spectral", "psd"),
    "spectrogram": (".signal.spectral", "spectrogram"),
    "Store": (".io.store", "Store"),
    "StoreLockedError": (".io.store", "StoreLockedError"),
    "batch": (".monitor.batch", "batch"),
    "read_manifest": (".monitor.inputs", "read_manifest"),
    "trend": (".monitor.trend", "trend"),
    "report": (".reporting", "report"),
    "models": (".", "models"),
    "synth": (".", "synth"),
}


def __getattr__(name: str):
    try:
        mod, attr = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module 'vibmeasure' has no attribute {name!r}") from None
    value = _import_module("." + attr, __name__) if mod == "." else getattr(_import_module(mod, __name__), attr)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))


__all__ = [
    "Channel", "Record", "LazyRecord", "ModalEstimate", "FRF", "Spectrum", "Spectrogram", "Peaks", "Kurtogram",
    "VibMeasureError", "ParameterError", "UnitError", "FitError", "QualityWarning",
    "read", "write", "open", "read_frf", "read_spectrum",
    "amplitude_spectrum", "psd", "csd", "coherence", "spectrogram", "band_rms", "octave_bands",
    "srs", "transmissibility", "pick_peaks", "harmonic_family", "sideband_family", "envelope", "envelope_spectrum", "order_track", "time_synchronous_average",
    "prewhiten", "remove_synchronous", "kurtogram", "band_ses", "despike",
    "detrend", "filter", "decimate", "resample", "integrate", "differentiate",
    "ringdown", "ringdown_crb", "estimate_frf", "impact_frf", "find_hits", "fit_modes", "circle_fit", "mac",
    "modal_crb", "synthesize_frf", "oma_ssi", "oma_fdd", "oma_cross_check", "log_decrement", "hilbert_decay", "half_power", "zeta_from_delta",
    "loop_damping", "LoopDamping", "stepped_sine", "antiresonances",
    "compare", "Comparison", "History", "diagnose", "Diagnosis", "severity_zone", "Bearing", "Gear", "BEARINGS",
    "Store", "StoreLockedError", "batch", "read_manifest", "trend", "report", "models", "synth", "units", "__version__",
]
