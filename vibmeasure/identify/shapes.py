"""Mode-shape comparison: the modal assurance criterion (MAC) and the complexity of a shape (MPC, MPD),
one definition each, used by fit_modes, OMA, compare and the plots."""

from __future__ import annotations

import numpy as np

from ..core.errors import ParameterError

__all__ = ["mac", "mac_pair", "mpc", "mpd"]


def mac(a, b=None) -> np.ndarray:
    """Modal assurance criterion between the columns of a and b.

    Parameters
    ----------
    a : array_like
        Shapes (n_dof, n_modes), real or complex.
    b : array_like, optional
        Shapes (n_dof, n_modes_b); default ``a`` (the auto-MAC).

    Returns
    -------
    numpy.ndarray
        (n_modes, n_modes_b): |a_i^H b_j|^2 / (|a_i|^2 |b_j|^2), 1 for parallel shapes, 0 for orthogonal.

    Raises
    ------
    ParameterError
        When a or b is not 2-D or their n_dof differ.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> vm.mac(np.eye(3)).round(3).tolist()
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    """
    a = np.asarray(a, complex)
    b = a if b is None else np.asarray(b, complex)
    if a.ndim != 2 or b.ndim != 2 or a.shape[0] != b.shape[0]:
        raise ParameterError(f"mac needs two (n_dof, n_modes) arrays with equal n_dof, got {a.shape} and {b.shape}")
    num = np.abs(a.conj().T @ b) ** 2
    den = np.outer(np.sum(np.abs(a) ** 2, 0), np.sum(np.abs(b) ** 2, 0))
    return num / den


def mac_pair(a, b) -> float:
    """The MAC of two shape vectors as a float (``mac`` of one pair, without its checks: the form the
    stabilisation and clustering loops call many times); 0 where a shape is zero."""
    return float(np.abs(np.vdot(a, b)) ** 2 / max(np.vdot(a, a).real * np.vdot(b, b).real, 1e-300))


def mpc(phi) -> np.ndarray:
    """Modal phase collinearity (0..1) of shapes (n_out, n_modes): 1 for a real (normal) mode."""
    phi = np.atleast_2d(np.asarray(phi, complex).T).T
    out = []
    for v in phi.T:
        sxx, syy, sxy = np.sum(v.real ** 2), np.sum(v.imag ** 2), np.sum(v.real * v.imag)
        if sxx + syy == 0:
            out.append(np.nan)
            continue
        out.append(((sxx - syy) ** 2 + 4 * sxy ** 2) / (sxx + syy) ** 2)
    return np.array(out)


def mpd(phi) -> np.ndarray:
    """Mean phase deviation (degrees) of shapes (n_out, n_modes) from their best straight line in the
    complex plane, weighted by the components' magnitudes: 0 for a real mode."""
    phi = np.atleast_2d(np.asarray(phi, complex).T).T
    out = []
    for v in phi.T:
        w = np.abs(v)
        if not w.any():
            out.append(np.nan)
            continue
        _, _, vt = np.linalg.svd(np.c_[v.real, v.imag], full_matrices=False)
        t = vt[0]
        den = np.abs(v) * np.hypot(*t)
        with np.errstate(invalid="ignore", divide="ignore"):
            dev = np.degrees(np.arccos(np.clip(np.abs(v.real * t[0] + v.imag * t[1]) / np.maximum(den, 1e-300),
                                               0, 1)))
        out.append(float(np.sum(w * dev) / np.sum(w)))
    return np.array(out)
