"""Acceptance limits every modal estimator shares."""

# A mode whose damping ratio has a relative std above this is refused (or flagged) by ringdown,
# fit_modes and OMA alike: at 30 % the damping is not a measurement, and one limit keeps the three
# estimators' answers comparable.
MAX_REL_ZETA_STD = 0.3
