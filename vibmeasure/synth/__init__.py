"""Synthetic measurements with known answers: free decays (viscous and Coulomb, with noise, clipping,
DC offset and sensor drift: decay.py), FRFs, hammer tests and ambient responses (modal.py), rotating
machines (machine.py) and a small fleet over time (fleet.py).

Every generator returns a :class:`~vibmeasure.Record` whose ``meta["truth"]`` holds the
parameters used, so tests and demos can compare identification with the truth.
"""

from ..models.sdof import coulomb_response
from .decay import coulomb_decay, free_decay, noise_std_for_snr
from .fleet import fleet
from .machine import cage_pulsing, machine
from .modal import ambient, base_excited, hammer_test, modal_frf, modal_response

__all__ = ["free_decay", "coulomb_decay", "coulomb_response", "noise_std_for_snr", "machine", "cage_pulsing", "fleet",
           "ambient", "base_excited", "modal_frf", "modal_response", "hammer_test"]
