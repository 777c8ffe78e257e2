"""vibmeasure: vibration measurements to natural frequencies, damping and FRFs you can trust."""
from .core.errors import FitError, ParameterError, QualityWarning, UnitError, VibMeasureError
from .core.record import Channel, Record
from .core.results import ModalEstimate
from .io import read, write
