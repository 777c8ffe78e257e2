"""Transient responses of an SDOF to forces: impulse, step, ramp, any sampled force, a periodic force."""

from __future__ import annotations

import numpy as np

from ..core._validate import finite_number, positive
from ..core.errors import ParameterError


class _Transient:
    """Methods of :class:`SDOF` (transient responses of an sdof to forces: impulse, step, ramp, any sampled force, a periodic force); SDOF inherits them."""

    # --- transient response ------------------------------------------------------------------
    def impulse_response(self, t) -> np.ndarray:
        """Displacement per unit impulse (N s): the free response from v0 = 1/m.

        Parameters
        ----------
        t : array_like
            Times in s.

        Returns
        -------
        numpy.ndarray

        Raises
        ------
        ParameterError
            For times that are not finite.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> s = vm.models.SDOF(m=1.0, k=3947.84, zeta=0.05)     # 10 Hz, Q 10
        >>> float(s.impulse_response(np.array([0.0]))[0])
        0.0
        """
        return self.free_response(t, x0=0.0, v0=1.0 / self.m)

    def step_response(self, t, F0: float = 1.0) -> np.ndarray:
        """Displacement under a force F0 switched on at t = 0, from rest.

        Parameters
        ----------
        t : array_like
            Times in s.
        F0 : float
            Force in N.

        Returns
        -------
        numpy.ndarray

        Raises
        ------
        ParameterError
            For times that are not finite.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> s = vm.models.SDOF(m=1.0, k=3947.84, zeta=0.05)     # 10 Hz, Q 10
        >>> round(float(s.step_response(np.array([10.0]))[0] * 3947.84), 3)   # settles at F0 / k
        1.0
        """
        return F0 / self.k * (1 - self.free_response(t, x0=1.0, v0=0.0))

    def ramp_response(self, t, rate: float = 1.0) -> np.ndarray:
        """Displacement under F = rate t from rest: the integral of the step response.

        Parameters
        ----------
        t : array_like
            Times in s.
        rate : float
            Force rate in N/s.

        Returns
        -------
        numpy.ndarray

        Raises
        ------
        ParameterError
            For times that are not finite.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> s = vm.models.SDOF(m=1.0, k=3947.84, zeta=0.05)     # 10 Hz, Q 10
        >>> float(s.ramp_response(np.array([0.0]))[0])
        0.0
        """
        t = np.asarray(t, float)
        # x = (rate/k) (t - 2 zeta/wn) + rate/k * free response from x0 = 2 zeta/wn, v0 = -1
        return rate / self.k * (t - 2 * self.zeta / self.wn + self.free_response(t, x0=2 * self.zeta / self.wn,
                                                                               v0=-1.0))

    def response(self, t, force, *, x0: float = 0.0, v0: float = 0.0) -> np.ndarray:
        """Displacement under an arbitrary force sampled at times t, starting from x0, v0 (the forced
        response plus the free response), by exact state-space integration with the force linear between
        samples. A loss factor acts as its equivalent viscous damping at resonance.

        Parameters
        ----------
        t : array_like
            Uniform times in s.
        force : array_like
            Force samples in N.
        x0 : float
            Displacement at t[0] in m.
        v0 : float
            Velocity at t[0] in m/s.

        Returns
        -------
        numpy.ndarray

        Raises
        ------
        ParameterError
            For times that are not uniform, a force of another length or initial conditions that are not
            finite.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> s = vm.models.SDOF(m=1.0, k=3947.84, zeta=0.05)     # 10 Hz, Q 10
        >>> t = np.arange(20000) / 1000.0
        >>> round(float(s.response(t, np.ones(t.size))[-1] * 3947.84), 3)
        1.0
        >>> round(float(s.response(t[:1], [0.0], x0=0.002)[0]), 6)      # starts where it is released
        0.002
        """
        from scipy.signal import lsim
        t = np.asarray(t, float)
        force = np.asarray(force, float)
        if force.shape != t.shape:
            raise ParameterError(f"force has shape {force.shape}; it must match t {t.shape}")
        x0, v0 = finite_number(x0, "x0"), finite_number(v0, "v0")
        if t.size == 1:   # lsim needs two samples; at t[0] the state is the initial one
            return np.array([x0])
        A = [[0.0, 1.0], [-self.k / self.m, -self.c_equivalent / self.m]]
        _, y, _ = lsim((A, [[0.0], [1.0 / self.m]], [[1.0, 0.0]], [[0.0]]), force, t, X0=[x0, v0])
        return y

    def periodic_response(self, t, *, period: float, a0: float = 0.0, a=(), b=()) -> np.ndarray:
        """Steady response to F(t) = a0/2 + sum a_n cos(n w t) + b_n sin(n w t), each harmonic through the FRF.

        Parameters
        ----------
        t : array_like
            Times in s.
        period : float
            The force's period in s.
        a0 : float
            Twice the mean force.
        a, b : sequence of float
            Cosine and sine coefficients of harmonics 1, 2, ...

        Returns
        -------
        numpy.ndarray

        Raises
        ------
        ParameterError
            For a period that is not positive.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> s = vm.models.SDOF(m=1.0, k=3947.84, zeta=0.05)     # 10 Hz, Q 10
        >>> s.periodic_response(np.arange(5) / 100.0, period=0.4, b=[1.0, 0.0, 1 / 3]).shape
        (5,)
        """
        t = np.asarray(t, float)
        w0 = 2 * np.pi / positive(period, "period")
        x = np.full_like(t, a0 / 2 / self.k)
        a, b = np.atleast_1d(np.asarray(a, float)), np.atleast_1d(np.asarray(b, float))
        n_h = max(a.size, b.size)
        a, b = np.pad(a, (0, n_h - a.size)), np.pad(b, (0, n_h - b.size))
        for n in range(1, n_h + 1):
            H = self.frf(n * w0 / (2 * np.pi))
            x += np.real((a[n - 1] - 1j * b[n - 1]) * H * np.exp(1j * n * w0 * t))
        return x
