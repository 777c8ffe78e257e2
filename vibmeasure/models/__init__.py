"""Model predictions: SDOF, MDOF, continua and equivalent systems; TOML model files; updating."""

from .bearing import BEARINGS, Bearing, Gear
from .continua import (Beam, Rod, Shaft, String, beta_l, compound_pendulum_fn, parallel, pendulum_gravity,
                       pendulum_period, series, stiffness, whirling_speed_rpm)
from .loader import load
from .mdof import MDOF, absorber, den_hartog
from .sdof import SDOF, stiffness_for
from .updating import update_mdof, update_sdof

__all__ = ["Bearing", "Gear", "BEARINGS", "SDOF", "MDOF", "Beam", "Rod", "Shaft", "String", "absorber", "den_hartog", "beta_l", "stiffness",
           "series", "parallel", "pendulum_period", "pendulum_gravity", "compound_pendulum_fn",
           "whirling_speed_rpm", "stiffness_for", "load", "update_sdof", "update_mdof"]
