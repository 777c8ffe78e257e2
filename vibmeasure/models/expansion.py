"""Forced response of a continuum by modal expansion: modal mass, participation, FRF between two points.

H(x_o, x_i, w) = sum_r phi_r(x_o) phi_r(x_i) / (w_r^2 - w^2 + 2 i zeta w_r w), with phi_r the mode shapes
scaled to unit modal mass (the integral of the line mass times phi^2, plus rho I psi^2 for a beam whose
sections rotate), and a free structure's rigid-body modes as terms with w_r = 0. The series is truncated
at ``n_modes``; the static compliance converges as the sum of the omitted modes' 1 / w_r^2.
"""

from __future__ import annotations

import numpy as np

from ..core._validate import positive
from ..core.errors import ParameterError

_FORMS = {"receptance": 0, "mobility": 1, "accelerance": 2}
MAX_EXPANSION_MODES = 60    # beyond this the truncation error is far below any measurement's


class ModalExpansion:
    """Methods a continuum gains from ``_modal_set(n)``: (circular frequencies, fields(r, x) giving the
    displacement and the rotary-inertia weighted rotation of mode r, line mass, rotary inertia per length,
    rigid-body shapes)."""

    def _quadrature(self, n):
        xq, wq = np.polynomial.legendre.leggauss(max(64, 8 * n + 32))
        return (xq + 1) * self.L / 2, wq * self.L / 2

    def _unit_max(self, n):
        """Per mode: circular frequency, unit-maximum modal mass and the integral of the line mass times the shape."""
        w, fields, mu, rho_i, _ = self._modal_set(n)
        x, q = self._quadrature(n)
        mass, first = np.empty(n), np.empty(n)
        for r in range(n):
            y, psi = fields(r, x)
            mass[r] = np.sum(q * (mu * y ** 2 + rho_i * psi ** 2))
            first[r] = np.sum(q * mu * y)
        return w, mass, first

    def modal_mass(self, n: int = 3) -> np.ndarray:
        """Modal masses of the first n modes, for shapes scaled to a largest displacement of 1.

        Parameters
        ----------
        n : int
            How many modes.

        Returns
        -------
        numpy.ndarray
            kg.

        Raises
        ------
        ParameterError
            For n outside 1 .. 60.

        Examples
        --------
        >>> import vibmeasure as vm
        >>> b = vm.models.Beam(E=210e9, I=1e-8, rho=7850.0, A=1e-4, L=1.0)       # 0.785 kg cantilever
        >>> [round(float(m), 5) for m in b.modal_mass(2)]                     # a quarter of it, every mode
        [0.19625, 0.19625]
        """
        return self._unit_max(_count(n))[1]

    def effective_mass(self, n: int = 3) -> np.ndarray:
        """Effective masses (the mass each mode carries when the supports move together), in kg; over all
        modes they add up to the structure's mass.

        Parameters
        ----------
        n : int
            How many modes.

        Returns
        -------
        numpy.ndarray
            kg.

        Raises
        ------
        ParameterError
            For n outside 1 .. 60.

        Examples
        --------
        >>> import vibmeasure as vm
        >>> b = vm.models.Beam(E=210e9, I=1e-8, rho=7850.0, A=1e-4, L=1.0)
        >>> [round(float(m / (7850.0 * 1e-4)), 3) for m in b.effective_mass(3)]   # share of the mass
        [0.613, 0.188, 0.065]
        """
        _, mass, first = self._unit_max(_count(n))
        return first ** 2 / mass

    def participation(self, n: int = 3) -> np.ndarray:
        """Participation factors Gamma_r = (integral of mu phi_r) / m_r of unit-maximum shapes: a support
        acceleration a drives mode r with Gamma_r a.

        Parameters
        ----------
        n : int
            How many modes.

        Returns
        -------
        numpy.ndarray

        Raises
        ------
        ParameterError
            For n outside 1 .. 60.

        Examples
        --------
        >>> import vibmeasure as vm
        >>> s = vm.models.String(T=100.0, mu=0.01, L=0.5)
        >>> [round(float(g), 4) for g in s.participation(3)]          # 4 / (n pi) for odd n, 0 for even
        [1.2732, 0.0, 0.4244]
        """
        _, mass, first = self._unit_max(_count(n))
        return first / mass

    def frf(self, freq, *, at: float, force_at: float, n_modes: int = 20, form: str = "receptance") -> np.ndarray:
        """FRF between a force at ``force_at`` and the response at ``at`` by modal expansion.

        Parameters
        ----------
        freq : array_like
            Frequencies in Hz.
        at : float
            Response position in m from the end x = 0.
        force_at : float
            Force position in m.
        n_modes : int
            Modes in the sum (truncation: the static value converges as the omitted modes' 1 / w_r^2).
        form : {"receptance", "mobility", "accelerance"}
            Displacement, velocity or acceleration per force.

        Returns
        -------
        numpy.ndarray
            Complex, m/N (or m/s/N, m/s^2/N).

        Raises
        ------
        ParameterError
            For positions off the structure, n_modes outside 1 .. 60 or an unknown form.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> b = vm.models.Beam(E=210e9, I=1e-8, rho=7850.0, A=1e-4, L=1.0)
        >>> h0 = b.frf([0.0], at=1.0, force_at=1.0, n_modes=40)[0].real
        >>> round(float(h0 * 3 * 210e9 * 1e-8), 4)           # the static tip compliance L^3 / (3 E I)
        1.0
        """
        if form not in _FORMS:
            raise ParameterError(f"form={form!r} must be one of {tuple(_FORMS)}")
        n = _count(n_modes, "n_modes")
        xo, xi = self._position(at, "at"), self._position(force_at, "force_at")
        w = 2 * np.pi * np.asarray(freq, float)
        if not np.all(np.isfinite(w)):
            raise ParameterError("freq must be finite")
        wr, fields, _, _, rigid = self._modal_set(n)
        _, mass, _ = self._unit_max(n)
        z = float(self.zeta)
        H = np.zeros(w.shape, complex)
        for r in range(n):
            po, pi = fields(r, np.array([xo, xi]))[0] / np.sqrt(mass[r])
            H += po * pi / (wr[r] ** 2 - w ** 2 + 2j * z * wr[r] * w)
        for po, pi in rigid(xo, xi):
            with np.errstate(divide="ignore"):
                H += po * pi / (-(w ** 2) + 0j)
        return H * (1j * w) ** _FORMS[form]

    def harmonic_response(self, freq, F0: float, *, at: float, force_at: float, n_modes: int = 20):
        """Steady displacement amplitude and phase lag at ``at`` under F0 sin(w t) applied at ``force_at``.

        Parameters
        ----------
        freq : array_like
            Frequencies in Hz.
        F0 : float
            Force amplitude in N.
        at, force_at : float
            Response and force positions in m.
        n_modes : int
            Modes in the sum.

        Returns
        -------
        tuple of numpy.ndarray
            (amplitude in m, phase lag in rad).

        Raises
        ------
        ParameterError
            For positions off the structure or a force that is not positive.

        Examples
        --------
        >>> import vibmeasure as vm
        >>> s = vm.models.String(T=100.0, mu=0.01, L=0.5, zeta=0.01)
        >>> x, lag = s.harmonic_response([100.0], 1.0, at=0.25, force_at=0.25)
        >>> round(float(lag[0]), 2)       # at its first mode the midpoint lags by about 90 degrees
        1.57
        """
        H = self.frf(freq, at=at, force_at=force_at, n_modes=n_modes)
        return positive(F0, "F0") * np.abs(H), -np.angle(H)

    def _position(self, x, name):
        try:
            v = float(x)
        except (TypeError, ValueError):
            raise ParameterError(f"{name}={x!r} must be a position in m") from None
        if not 0 <= v <= self.L:
            raise ParameterError(f"{name}={x!r} m is off the structure (0 .. L = {self.L:g} m)")
        return v


def _count(n, name="n"):
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 1 <= n <= MAX_EXPANSION_MODES:
        raise ParameterError(f"{name}={n!r} must be an integer from 1 to {MAX_EXPANSION_MODES}")
    return int(n)
