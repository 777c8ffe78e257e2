"""vibmeasure: vibration measurements to natural frequencies, damping and FRFs you can trust.

>>> import vibmeasure as vm
>>> rec = vm.synth.free_decay(fn=10.37, zeta=0.02, fs=1000.0, duration=10.0, snr_db=40, seed=1)
>>> est = vm.ringdown(rec)          # ModalEstimate: fn, zeta, fn_std, zeta_std, flags
"""

from . import synth
from .core import units
from .core.errors import FitError, ParameterError, QualityWarning, UnitError, VibMeasureError
from .core.record import Channel, Record
from .core.results import ModalEstimate
from .identify.damping import half_power, hilbert_decay, log_decrement, zeta_from_delta
from .identify.ringdown import ringdown, ringdown_crb
from .io import read, write

__version__ = "0.1.0"

__all__ = [
    "Channel", "Record", "ModalEstimate",
    "VibMeasureError", "ParameterError", "UnitError", "FitError", "QualityWarning",
    "read", "write",
    "ringdown", "ringdown_crb", "log_decrement", "hilbert_decay", "half_power", "zeta_from_delta",
    "synth", "units", "__version__",
]
