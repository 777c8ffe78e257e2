"""Multi-degree-of-freedom model: M x'' + C x' + K x = F.

Undamped modes (mass-normalised), damping as a matrix C, Rayleigh (alpha M + beta K) or modal
ratios; complex modes of general viscous damping from the state-space eigenproblem; FRF matrix;
time response; the tuned vibration absorber.
"""

from __future__ import annotations

import numpy as np
from scipy import linalg

from ..core.errors import ParameterError
from ..core.results import ModalEstimate

__all__ = ["MDOF", "absorber", "den_hartog"]


def _spd(A, name):
    A = np.asarray(A, float)
    if A.ndim != 2 or A.shape[0] != A.shape[1]:
        raise ParameterError(f"{name} must be a square matrix, got shape {A.shape}")
    if not np.all(np.isfinite(A)):
        raise ParameterError(f"{name} has NaN/inf entries")
    if not np.allclose(A, A.T, rtol=1e-10, atol=1e-12 * np.abs(A).max()):
        raise ParameterError(f"{name} must be symmetric")
    if np.linalg.eigvalsh(A).min() <= 0:
        raise ParameterError(f"{name} must be positive definite (smallest eigenvalue "
                             f"{np.linalg.eigvalsh(A).min():.3g} <= 0)")
    return A


class MDOF:
    """A multi-degree-of-freedom system M x'' + C x' + K x = f.

    Parameters
    ----------
    M : array_like
        Mass matrix in kg (symmetric, positive definite).
    K : array_like
        Stiffness matrix in N/m (symmetric).
    C : array_like, optional
        Damping matrix in N s/m.
    rayleigh : tuple of float, optional
        (alpha, beta): C = alpha M + beta K.
    modal_zeta : array_like, optional
        One damping ratio per mode (classical damping).

    Raises
    ------
    ParameterError
        For matrices of different shapes, not symmetric, or a mass matrix that is not positive definite.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> chain = vm.models.MDOF(np.eye(2), np.array([[2e4, -1e4], [-1e4, 1e4]]), modal_zeta=[0.02, 0.02])
    >>> np.round(chain.modes().fn, 2).tolist()
    [9.84, 25.75]
    """

    def __init__(self, M, K, C=None, *, rayleigh=None, modal_zeta=None):
        self.M = _spd(M, "M")
        self.K = _spd(K, "K")
        if self.M.shape != self.K.shape:
            raise ParameterError(f"M {self.M.shape} and K {self.K.shape} must have the same shape")
        if sum(x is not None for x in (C, rayleigh, modal_zeta)) > 1:
            raise ParameterError("give one of C, rayleigh and modal_zeta")
        n = self.M.shape[0]
        w2, phi = linalg.eigh(self.K, self.M)
        self._w = np.sqrt(w2)
        self._phi = phi  # eigh(K, M) normalises phi^T M phi = I
        self.kind = "undamped"
        if modal_zeta is not None:
            z = np.broadcast_to(np.atleast_1d(np.asarray(modal_zeta, float)), (n,)).copy()
            if np.any(z < 0) or np.any(z >= 1):
                raise ParameterError(f"modal_zeta={modal_zeta!r} must be in [0, 1)")
            Mphi = self.M @ phi
            self.C = Mphi @ np.diag(2 * z * self._w) @ Mphi.T
            self.kind = "modal"
        elif rayleigh is not None:
            try:
                a, b = (float(v) for v in rayleigh)
            except (TypeError, ValueError):
                raise ParameterError(f"rayleigh={rayleigh!r} must be a pair (alpha, beta)") from None
            if not (np.isfinite(a) and np.isfinite(b)) or a < 0 or b < 0:
                raise ParameterError(f"rayleigh={rayleigh!r}: alpha and beta must be finite and >= 0 (negative "
                                     "damping makes an unstable model)")
            self.C = a * self.M + b * self.K
            self.kind = "rayleigh"
        elif C is not None:
            C = np.asarray(C, float)
            if C.shape != self.M.shape:
                raise ParameterError(f"C has shape {C.shape}; M is {self.M.shape}")
            if not np.all(np.isfinite(C)):
                raise ParameterError("C must hold finite values")
            if not np.allclose(C, C.T, atol=1e-12 * max(np.abs(C).max(), 1e-300)):
                raise ParameterError("C must be symmetric")
            lo = float(np.min(linalg.eigvalsh(C))) if C.any() else 0.0
            if lo < -1e-12 * max(np.abs(C).max(), 1e-300):
                raise ParameterError(f"C has a negative eigenvalue ({lo:.3g}): negative damping makes an unstable "
                                     "model; C must be positive semi-definite")
            self.C = C
            self.kind = "general"
        else:
            self.C = np.zeros_like(self.M)

    @property
    def n_dof(self) -> int:
        return self.M.shape[0]

    def undamped_modes(self) -> tuple[np.ndarray, np.ndarray]:
        """Natural frequencies and mass-normalised shapes: phi^T M phi = I, phi^T K phi = w^2.

        Returns
        -------
        tuple of numpy.ndarray
            (fn in Hz, shapes as columns).

        Raises
        ------
        ParameterError
            Never for a valid model.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> fn, phi = vm.models.MDOF(np.eye(2), np.array([[2e4, -1e4], [-1e4, 1e4]])).undamped_modes()
        >>> np.round(phi.T @ phi, 6).tolist()
        [[1.0, 0.0], [0.0, 1.0]]
        """
        return self._w / (2 * np.pi), self._phi.copy()

    def is_proportional(self) -> bool:
        """Whether C is diagonalised by the undamped modes (classical damping).

        Returns
        -------
        bool

        Raises
        ------
        ParameterError
            Never.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> vm.models.MDOF(np.eye(2), np.array([[2e4, -1e4], [-1e4, 1e4]]), rayleigh=(0.1, 1e-4)).is_proportional()
        True
        """
        Cm = self._phi.T @ self.C @ self._phi
        off = Cm - np.diag(np.diag(Cm))
        return bool(np.abs(off).max() <= 1e-9 * max(np.abs(Cm).max(), 1e-300))

    def complex_modes(self):
        """Eigenvalues and complex shapes of the state-space problem [0 I; -M^-1 K  -M^-1 C].

        Returns
        -------
        tuple of numpy.ndarray
            (lambda: one per oscillating pair, Im > 0; shapes as columns).

        Raises
        ------
        ParameterError
            Never for a valid model.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> lam, phi = vm.models.MDOF(np.eye(1), np.array([[1e4]]), modal_zeta=[0.02]).complex_modes()
        >>> round(float(-lam[0].real / abs(lam[0])), 3)
        0.02
        """
        n = self.n_dof
        Minv = np.linalg.inv(self.M)
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ self.K, -Minv @ self.C]])
        lam, V = np.linalg.eig(A)
        keep = lam.imag > 0
        lam, V = lam[keep], V[:n, keep]
        order = np.argsort(np.abs(lam))
        return lam[order], V[:, order]

    def modes(self) -> ModalEstimate:
        """The prediction as a ModalEstimate: fn (Hz, |lambda| / 2 pi), zeta (-Re lambda / |lambda|), shapes.

        Returns
        -------
        ModalEstimate

        Raises
        ------
        ParameterError
            Never for a valid model.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> vm.models.MDOF(np.eye(2), np.array([[2e4, -1e4], [-1e4, 1e4]])).modes().n_modes
        2
        """
        if self.kind == "undamped" or not np.any(self.C):
            fn, phi = self.undamped_modes()
            return ModalEstimate(fn=fn, zeta=np.zeros_like(fn), fn_std=np.zeros_like(fn),
                                 zeta_std=np.zeros_like(fn), shapes=phi, method="model:mdof")
        lam, V = self.complex_modes()
        if lam.size < self.n_dof:
            raise ParameterError("a mode is critically or over damped: no natural frequency for it")
        wn = np.abs(lam)
        shapes = V / V[np.argmax(np.abs(V), axis=0), np.arange(V.shape[1])]
        if self.is_proportional():
            shapes = self._phi[:, np.argsort(self._w)]
        return ModalEstimate(fn=wn / (2 * np.pi), zeta=-lam.real / wn, fn_std=np.zeros(lam.size),
                             zeta_std=np.zeros(lam.size), shapes=shapes, method="model:mdof")

    def frf(self, freq, *, form: str = "receptance") -> np.ndarray:
        """H(f) by direct inversion of K - w^2 M + i w C.

        Parameters
        ----------
        freq : array_like
            Frequencies in Hz.
        form : {"receptance", "mobility", "accelerance"}
            The FRF form.

        Returns
        -------
        numpy.ndarray
            (n_dof, n_dof, n_freq) complex.

        Raises
        ------
        ParameterError
            For an unknown form.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> vm.models.MDOF(np.eye(2), np.array([[2e4, -1e4], [-1e4, 1e4]])).frf([1.0, 2.0]).shape
        (2, 2, 2)
        """
        k = {"receptance": 0, "mobility": 1, "accelerance": 2}.get(form)
        if k is None:
            raise ParameterError(f"form={form!r} must be receptance, mobility or accelerance")
        w = 2 * np.pi * np.asarray(freq, float)
        Z = self.K[None] - w[:, None, None] ** 2 * self.M[None] + 1j * w[:, None, None] * self.C[None]
        H = np.linalg.inv(Z) * ((1j * w) ** k)[:, None, None]
        return np.transpose(H, (1, 2, 0))

    def response(self, t, force, *, x0=None, v0=None) -> np.ndarray:
        """Displacements under forces, by modal superposition for proportional damping (each mode exact for
        a force linear between samples), else by state space.

        Parameters
        ----------
        t : array_like
            Uniform times in s.
        force : array_like
            Forces (n_dof, n_t) in N.
        x0, v0 : array_like, optional
            Initial displacements and velocities.

        Returns
        -------
        numpy.ndarray
            (n_dof, n_t).

        Raises
        ------
        ParameterError
            For a force of the wrong shape or times that are not uniform.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> sys2 = vm.models.MDOF(np.eye(2), np.array([[2e4, -1e4], [-1e4, 1e4]]), modal_zeta=[0.02, 0.02])
        >>> t = np.arange(1000) / 1000.0
        >>> sys2.response(t, np.vstack([np.ones(1000), np.zeros(1000)])).shape
        (2, 1000)
        """
        from scipy.signal import lsim
        t = np.asarray(t, float)
        F = np.asarray(force, float)
        if F.shape != (self.n_dof, t.size):
            raise ParameterError(f"force must have shape ({self.n_dof}, {t.size}), got {F.shape}")
        x0, v0 = self._initial(x0, "x0"), self._initial(v0, "v0")
        if self.is_proportional():
            phi, w = self._phi, self._w
            c = np.diag(phi.T @ self.C @ phi)
            q0, qd0 = phi.T @ self.M @ x0, phi.T @ self.M @ v0
            Q = phi.T @ F
            x = np.zeros((self.n_dof, t.size))
            for r in range(self.n_dof):
                A = [[0.0, 1.0], [-w[r] ** 2, -c[r]]]
                _, q, _ = lsim((A, [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]]), Q[r], t, X0=[q0[r], qd0[r]])
                x += np.outer(phi[:, r], q)
            return x
        n = self.n_dof
        Minv = np.linalg.inv(self.M)
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ self.K, -Minv @ self.C]])
        B = np.vstack([np.zeros((n, n)), Minv])
        _, y, _ = lsim((A, B, np.hstack([np.eye(n), np.zeros((n, n))]), np.zeros((n, n))), F.T, t,
                       X0=np.r_[x0, v0])
        return y.T

    def _initial(self, value, name: str) -> np.ndarray:
        """An initial state: zeros when not given, else n_dof finite numbers."""
        if value is None:
            return np.zeros(self.n_dof)
        try:
            v = np.asarray(value, float).reshape(-1)
        except (TypeError, ValueError):
            raise ParameterError(f"{name} must be {self.n_dof} numbers") from None
        if v.size != self.n_dof or not np.all(np.isfinite(v)):
            raise ParameterError(f"{name} must be {self.n_dof} finite numbers (one per degree of freedom), "
                                 f"got {np.asarray(value).shape}")
        return v

    def scaled(self, *, k_scale: float = 1.0, c_scale: float = 1.0) -> "MDOF":
        """The same system with K (and C) multiplied by scale factors (model updating).

        Parameters
        ----------
        k_scale : float
            Factor on K.
        c_scale : float
            Factor on C.

        Returns
        -------
        MDOF

        Raises
        ------
        ParameterError
            For a factor that is not positive.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> s = vm.models.MDOF(np.eye(1), np.array([[1e4]])).scaled(k_scale=4.0)
        >>> round(float(s.modes().fn[0] * 2 * np.pi), 1)
        200.0
        """
        return MDOF(self.M, self.K * k_scale, self.C * c_scale if np.any(self.C) else None)

    def __repr__(self) -> str:
        return f"MDOF({self.n_dof} dof, {self.kind} damping; fn={np.round(self._w / (2 * np.pi), 4).tolist()} Hz)"


def absorber(m1: float, k1: float, m2: float, k2: float, c2: float = 0.0, c1: float = 0.0) -> MDOF:
    """A main mass on a spring with a tuned absorber attached to it (a 2-DOF MDOF).

    Parameters
    ----------
    m1, k1 : float
        Main mass (kg) and stiffness (N/m).
    m2, k2 : float
        Absorber mass and stiffness.
    c2 : float
        Absorber damping (N s/m).
    c1 : float
        Main damping (N s/m).

    Returns
    -------
    MDOF

    Raises
    ------
    ParameterError
        For values that are not positive.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> vm.models.absorber(100.0, 1e5, 5.0, 5e3).modes().n_modes
    2
    """
    M = np.diag([m1, m2])
    K = np.array([[k1 + k2, -k2], [-k2, k2]])
    C = np.array([[c1 + c2, -c2], [-c2, c2]])
    return MDOF(M, K, C if (c1 or c2) else None)


def den_hartog(mass_ratio: float) -> dict:
    """Optimal tuning of a damped absorber (Den Hartog).

    Parameters
    ----------
    mass_ratio : float
        mu = m2 / m1.

    Returns
    -------
    dict
        frequency_ratio 1 / (1 + mu) and zeta sqrt(3 mu / (8 (1 + mu)^3)).

    Raises
    ------
    ParameterError
        For a ratio that is not positive.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> round(vm.models.den_hartog(0.05)["frequency_ratio"], 4)
    0.9524
    """
    mu = float(mass_ratio)
    if not mu > 0:
        raise ParameterError(f"mass_ratio={mass_ratio} must be > 0")
    return {"frequency_ratio": 1 / (1 + mu), "zeta": float(np.sqrt(3 * mu / (8 * (1 + mu) ** 3))),
            "max_magnification": float(np.sqrt(1 + 2 / mu))}
