"""Bearing fault evidence from squared-envelope spectra (SES), as a statistical test.

The test for one record (``bearing_evidence``), one step a module:

1. ``spectra``: per channel, pre-whitened SES in their demodulation bands (cepstral pre-whitening of
   the whole band above the shaft-harmonic region, and the bands of the fast kurtogram and the
   infogram); each line divided by its local floor and mapped through the floor's exact law, so that
   under Gaussian noise the ratio is exponential with mean 1; the channels' fused view.
2. ``cage``: where the cage comb stands, the lines it shares with the other families count only by
   what they stand above it.
3. ``families``: shaft harmonics, artefact combs and the cage comb claim their lines first; the bearing
   families are tested and the best explanation claims its lines; a line is evidence for one family.
4. ``lines``: a family's statistic is the sum of the line ratios over its comb at the best common
   slip; its Gamma tail gives a p-value, corrected for every slip, bin, sub-model and spectrum
   searched; ``decoys``: the share of decoy combs it beats on its own spectrum.
5. ``evidence``: a family is found when its corrected p is below ``ALPHA``, it shows two lines (one at
   a harmonic 1-3), and it claims first in two views of the record (or in one with p below
   ``SINGLE_VIEW_P``); the confidence is the posterior from the p-value's Bayes-factor bound
   (Sellke, Bayarri & Berger 2001) with prior odds ``PRIOR_ODDS``.
6. ``smeared``: where no family passes, the ball's comb is asked for as humps (a ball's spin wanders).

docs/methods/diagnosis.md explains each step with its references and measured figures.
"""

from .evidence import BearingEvidence, bearing_evidence
from .rules import ALPHA, FAMILIES, SLIP
from .spectra import WHITENING

__all__ = ["bearing_evidence", "BearingEvidence", "FAMILIES", "ALPHA", "SLIP", "WHITENING"]
