"""Model predictions: SDOF, MDOF, continua and equivalent systems; TOML model files; updating."""

from .bearing import BEARINGS, Bearing, Gear
from .beams import RayleighBeam, TimoshenkoBeam, slenderness_limit
from .continua import Beam, Rod, Shaft, String, beta_l
from .equivalent import (chain, compound_pendulum_fn, parallel, pendulum_gravity, pendulum_period, series,
                         stiffness, tip_mass_beam, whirling_speed_rpm)
from .inverse import (amplitude_phase, decrement_from_amplitudes, fn_from_deflection, harmonic_frequency,
                      harmonic_motion, isolator_stiffness, q_factor, static_deflection, zeta_from_magnification,
                      zeta_from_peak_frequency)
from .loader import load
from .mdof import MDOF, absorber, den_hartog
from .sdof import SDOF, stiffness_for
from .updating import update_mdof, update_sdof

__all__ = ["Bearing", "Gear", "BEARINGS", "SDOF", "MDOF", "Beam", "Rod", "Shaft", "String", "absorber", "den_hartog", "beta_l", "stiffness",
           "series", "parallel", "pendulum_period", "pendulum_gravity", "compound_pendulum_fn",
           "whirling_speed_rpm", "stiffness_for", "load", "update_sdof", "update_mdof",
           "TimoshenkoBeam", "RayleighBeam", "slenderness_limit", "chain", "tip_mass_beam",
           "zeta_from_magnification", "zeta_from_peak_frequency", "isolator_stiffness", "decrement_from_amplitudes",
           "q_factor", "amplitude_phase", "static_deflection", "fn_from_deflection", "harmonic_motion",
           "harmonic_frequency"]
