"""The bearing test's thresholds and families, each with the reason for its value."""

from __future__ import annotations

SLIP = 0.02          # rolling elements slip: the family's frequencies may all be off by up to +-2 %
ALPHA = 1e-3         # false-alarm probability per family and record (after every correction)
PRIOR_ODDS = 0.01    # prior odds that a given family is present in a record
R_LINE = 6.0         # a single line stands this far (power ratio, 7.8 dB) above its floor: p = 0.25 %
CONTESTED = 0.005    # a shaft harmonic this close to a bearing line at its catalogue frequency may be either's
OWN_ORDERS = 12      # the shaft shows on its own with a line at one of its first orders no bearing line is
MIN_VOTES = 2        # a family is called where it claims first in this many views of the record (_views) ...
SINGLE_VIEW_P = 1e-10  # ... or in one, with a p-value (after every correction) below this: see _one_view
R_CAP = 20.0         # one line adds at most this much (13 dB) to a comb's statistic: a comb needs several
# family -> (catalogue key of the fundamental, sub-models: (harmonics, sideband spacing key or None))
FAMILIES = {
    "bearing_outer_race": ("BPFO", (((1, 2, 3), None), ((1, 2, 3, 4, 5), None))),
    "bearing_inner_race": ("BPFI", (((1, 2, 3), None), ((1, 2, 3), "1X"), ((1, 2, 3, 4, 5), None))),
    "bearing_ball": ("2xBSF", (((1, 2, 3), None), ((1, 2, 3), "FTF"), ((0.5, 1, 1.5), None))),
}


SHAFT_PRECISION = 0.001   # a shaft line stands within this share of its harmonic's frequency (0.6 bin at least)


MODULATION = {"bearing_inner_race": "1X", "bearing_ball": "FTF"}


SAME_DATA = 0.5   # two spectra of one channel share more than this part of their bands' union: one view
