"""Output-only (operational) modal analysis: modes from the response to ambient excitation alone.

``oma_ssi`` (ssi.py): covariance-driven stochastic subspace identification. The output covariances
R_i = E[y_{k+i} y_k^T] of a system driven by white noise are C A^(i-1) G, so the block Toeplitz
matrix of R_1..R_(2s-1) factors into observability times controllability; its SVD gives the
observability matrix, from which A (poles) and C (mode shapes) follow at every model order. Poles
that persist across orders (frequency, damping and shape) are clustered into modes; each mode's
standard deviations come from a block jackknife of the covariance estimate.

``oma_fdd`` (fdd.py): frequency-domain decomposition. The SVD of the output cross-spectral matrix at
every line separates the modes: near a mode the first singular value is that mode's SDOF bell and its
singular vector the shape. EFDD takes each bell back to a free decay and fits it with the ring-down
estimator. ``oma_cross_check`` (crosscheck.py) flags the modes the two place apart. ``_common.py`` holds what both share: output checks, duration rule, band kurtosis.
"""

from ..shapes import mpc, mpd
from .crosscheck import oma_cross_check
from .fdd import oma_fdd
from .ssi import oma_ssi

__all__ = ["oma_ssi", "oma_fdd", "oma_cross_check", "mpc", "mpd"]
