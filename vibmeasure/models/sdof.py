"""Single-degree-of-freedom model: what a test on a mass-spring-damper should measure.

x'' m + c x' + k x = F(t) (viscous) or k (1 + i eta) for structural (hysteretic) damping in
harmonic response; Coulomb (dry friction) free response by its closed form.

Hysteretic damping has one definition across every property: the FRF and the harmonic responses use
k (1 + i eta) exactly; everything else (zeta, Q, the log decrement, the free and transient responses,
``modes()``) uses its equivalent viscous damping at resonance, zeta = eta / 2 (c = eta k / wn), because
a loss factor independent of frequency has no causal time-domain form.
"""

from __future__ import annotations

import numpy as np

from ..core._validate import positive
from ..core.errors import ParameterError
from ..core.results import ModalEstimate
from .sdof_transient import _Transient

__all__ = ["SDOF", "coulomb_response"]

_FORMS = {"receptance": 0, "mobility": 1, "accelerance": 2}



def coulomb_response(t, *, fn: float, friction_decay: float, amplitude: float, order: int = 0) -> np.ndarray:
    """Closed-form dry-friction decay released from rest at ``amplitude`` at t = 0 (t >= 0).

    Each half cycle is a cosine about a centre shifted by the friction displacement mu = F/k
    (= friction_decay / 4) against the motion; the turning amplitude falls by 2 mu per half cycle until
    it is below mu and the mass sticks.

    Parameters
    ----------
    t : array_like
        Times in s.
    fn : float
        Undamped natural frequency in Hz.
    friction_decay : float
        Amplitude lost per cycle (4 F/k).
    amplitude : float
        Release amplitude.
    order : {0, 1, 2}
        Displacement, velocity or acceleration.

    Returns
    -------
    numpy.ndarray

    Raises
    ------
    ParameterError
        For values out of range.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> x = vm.synth.coulomb_response(np.array([0.0, 1.0]), fn=1.0, friction_decay=0.04, amplitude=1.0)
    >>> [round(float(v), 3) for v in x]
    [1.0, 0.96]
    """
    t = np.asarray(t, dtype=float)
    mu = friction_decay / 4.0
    wn = 2 * np.pi * fn
    half = np.pi / wn
    x = np.zeros_like(t)
    a, side = abs(float(amplitude)), (1.0 if amplitude >= 0 else -1.0)
    k = np.floor(np.maximum(t, 0.0) / half).astype(int)
    n_half = int(k.max()) + 1 if t.size else 0
    for j in range(n_half):
        r = a - mu  # amplitude about the shifted centre
        seg = k == j
        if r <= 0:  # stuck: friction holds the mass where it turned
            x[k >= j] = side * a if order == 0 else 0.0
            break
        tau = t[seg] - j * half
        if order == 0:
            x[seg] = side * (mu + r * np.cos(wn * tau))
        elif order == 1:
            x[seg] = -side * r * wn * np.sin(wn * tau)
        else:
            x[seg] = -side * r * wn ** 2 * np.cos(wn * tau)
        a, side = r - mu, -side
    return x


class SDOF(_Transient):
    """A mass-spring-damper m x'' + c x' + k x = f.

    Properties: wn (rad/s), fn, fd (Hz), c_crit, zeta, c, c_equivalent, Td, log_decrement, Q, regime.
    A loss factor (hysteretic damping) enters the FRF as k (1 + i eta) and every other property as its
    equivalent viscous damping at resonance: zeta = c / c_crit + eta / 2, so Q = 1 / eta for a loss
    factor alone (the FRF's peak magnification).

    Parameters
    ----------
    m : float
        Mass in kg.
    k : float
        Stiffness in N/m.
    c : float, optional
        Viscous damping in N s/m (give c or zeta; a loss factor may come with either).
    zeta : float, optional
        Damping ratio.
    loss_factor : float, optional
        Hysteretic loss factor eta.

    Raises
    ------
    ParameterError
        For values that are not positive, or more than one damping given.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> s = vm.models.SDOF(m=1.0, k=3947.84, zeta=0.05)     # 10 Hz, Q 10
    >>> round(s.fn, 3), round(s.Q, 3)
    (10.0, 10.0)
    """

    def __init__(self, *, m: float = 1.0, k: float, c: float | None = None, zeta: float | None = None,
                 loss_factor: float | None = None):
        self.m = positive(m, "m")
        self.k = positive(k, "k")
        if c is not None and zeta is not None:
            raise ParameterError("give one of c and zeta, not both (a loss_factor may come with either)")
        self.c_crit = 2 * np.sqrt(self.k * self.m)
        self.loss_factor = 0.0 if loss_factor is None else positive(loss_factor, "loss_factor", allow_zero=True)
        if zeta is not None:
            self.c = positive(zeta, "zeta", allow_zero=True) * self.c_crit
        else:
            self.c = 0.0 if c is None else positive(c, "c", allow_zero=True)
        # the viscous part plus the loss factor's equivalent at resonance (module docstring)
        self.zeta = self.c / self.c_crit + self.loss_factor / 2

    @property
    def c_equivalent(self) -> float:
        """Viscous c plus the loss factor's equivalent at resonance, eta k / wn (N s/m)."""
        return self.zeta * self.c_crit

    # --- natural properties --------------------------------------------------------------------
    @property
    def wn(self) -> float:
        return float(np.sqrt(self.k / self.m))

    @property
    def fn(self) -> float:
        return self.wn / (2 * np.pi)

    def _need_under(self, what):
        if self.zeta >= 1:
            raise ParameterError(f"{what}: zeta={self.zeta:.4g} >= 1 (critically or over damped): the system does "
                                 "not oscillate")

    @property
    def wd(self) -> float:
        self._need_under("wd")
        return self.wn * np.sqrt(1 - self.zeta ** 2)

    @property
    def fd(self) -> float:
        return self.wd / (2 * np.pi)

    @property
    def Td(self) -> float:
        """Damped period, s."""
        return 1 / self.fd

    @property
    def log_decrement(self) -> float:
        self._need_under("log_decrement")
        return 2 * np.pi * self.zeta / np.sqrt(1 - self.zeta ** 2)

    @property
    def Q(self) -> float:
        return np.inf if self.zeta == 0 else float(1 / (2 * self.zeta))

    @property
    def regime(self) -> str:
        return "undamped" if self.zeta == 0 else "underdamped" if self.zeta < 1 else \
            "critically damped" if np.isclose(self.zeta, 1.0, rtol=1e-9) else "overdamped"

    def modes(self) -> ModalEstimate:
        """The prediction as a ModalEstimate (so ``vm.compare`` works the same for every model).

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
        >>> s = vm.models.SDOF(m=1.0, k=3947.84, zeta=0.05)     # 10 Hz, Q 10
        >>> round(float(s.modes().fn[0]), 3)
        10.0
        """
        return ModalEstimate(fn=[self.fn], zeta=[self.zeta], fn_std=[0.0], zeta_std=[0.0], method="model:sdof",
                             extras={"m": self.m, "k": self.k, "c": self.c, "loss_factor": self.loss_factor})

    # --- free response -------------------------------------------------------------------------
    def free_response(self, t, *, x0: float = 0.0, v0: float = 0.0) -> np.ndarray:
        """Displacement from x0, v0: the under-, critically and over-damped closed forms.

        Parameters
        ----------
        t : array_like
            Times in s.
        x0 : float
            Initial displacement.
        v0 : float
            Initial velocity.

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
        >>> float(s.free_response(np.array([0.0]), x0=1.0)[0])
        1.0
        """
        t = np.asarray(t, float)
        wn, z = self.wn, self.zeta
        if z < 1 and not np.isclose(z, 1.0, rtol=1e-9):
            wd = wn * np.sqrt(1 - z ** 2)
            return np.exp(-z * wn * t) * (x0 * np.cos(wd * t) + (v0 + z * wn * x0) / wd * np.sin(wd * t))
        if np.isclose(z, 1.0, rtol=1e-9):
            return np.exp(-wn * t) * (x0 + (v0 + wn * x0) * t)
        r = wn * np.sqrt(z ** 2 - 1)
        s1, s2 = -z * wn + r, -z * wn - r
        c1 = (v0 - s2 * x0) / (s1 - s2)
        c2 = (s1 * x0 - v0) / (s1 - s2)
        return c1 * np.exp(s1 * t) + c2 * np.exp(s2 * t)

    def time_to_decay(self, ratio: float) -> float:
        """Time for the envelope exp(-zeta wn t) to fall to ``ratio`` of its start.

        Parameters
        ----------
        ratio : float
            Between 0 and 1 (e.g. 1/50).

        Returns
        -------
        float
            s.

        Raises
        ------
        ParameterError
            For a ratio outside (0, 1), or an undamped system.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> s = vm.models.SDOF(m=1.0, k=3947.84, zeta=0.05)     # 10 Hz, Q 10
        >>> round(s.time_to_decay(1 / 50), 3)
        1.245
        """
        if not 0 < ratio < 1:
            raise ParameterError(f"ratio={ratio} must be between 0 and 1")
        if self.zeta == 0:
            return np.inf
        return float(-np.log(ratio) / (self.zeta * self.wn))

    def settling_time(self, fraction: float = 0.02) -> float:
        """Time until the free or step response stays within ``fraction`` (envelope criterion).

        Parameters
        ----------
        fraction : float
            The band, as a share of the start (0.02: 2 %).

        Returns
        -------
        float
            s.

        Raises
        ------
        ParameterError
            For a fraction outside (0, 1).

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> s = vm.models.SDOF(m=1.0, k=3947.84, zeta=0.05)     # 10 Hz, Q 10
        >>> round(s.settling_time(0.02), 3)
        1.245
        """
        return self.time_to_decay(fraction)

    def coulomb_free_response(self, t, *, x0: float, friction_force: float) -> np.ndarray:
        """Dry friction instead of viscous damping, released from rest at x0: the amplitude falls by 4 F / k
        per cycle at wn and stops once it is below F / k.

        Parameters
        ----------
        t : array_like
            Times in s.
        x0 : float
            Release displacement in m.
        friction_force : float
            The friction force F in N.

        Returns
        -------
        numpy.ndarray

        Raises
        ------
        ParameterError
            For a friction force that is not positive.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> s = vm.models.SDOF(m=1.0, k=3947.84, zeta=0.05)     # 10 Hz, Q 10
        >>> float(s.coulomb_free_response(np.array([0.0]), x0=1.0, friction_force=10.0)[0])
        1.0
        """
        f = positive(friction_force, "friction_force")
        return coulomb_response(t, fn=self.fn, friction_decay=4 * f / self.k, amplitude=x0)

    # --- harmonic response -----------------------------------------------------------------------
    def frf(self, freq, *, form: str = "receptance") -> np.ndarray:
        """H(f) = 1 / (k - m w^2 + i w c) (receptance; hysteretic k (1 + i eta)), times (i w)^n.

        Parameters
        ----------
        freq : array_like
            Frequencies in Hz.
        form : {"receptance", "mobility", "accelerance"}
            The FRF form.

        Returns
        -------
        numpy.ndarray
            Complex.

        Raises
        ------
        ParameterError
            For an unknown form.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> s = vm.models.SDOF(m=1.0, k=3947.84, zeta=0.05)     # 10 Hz, Q 10
        >>> round(float(abs(s.frf([0.0])[0]) * 3947.84), 6)   # static compliance 1/k
        1.0
        """
        if form not in _FORMS:
            raise ParameterError(f"form={form!r} must be one of {tuple(_FORMS)}")
        w = 2 * np.pi * np.asarray(freq, float)
        h = 1 / (self.k * (1 + 1j * self.loss_factor) - self.m * w ** 2 + 1j * w * self.c)
        return h * (1j * w) ** _FORMS[form]

    def magnification(self, freq) -> tuple[np.ndarray, np.ndarray]:
        """Dynamic magnification |X k / F0| and phase lag of the steady response to a force.

        Parameters
        ----------
        freq : array_like
            Frequencies in Hz.

        Returns
        -------
        tuple of numpy.ndarray
            (magnification, phase lag in rad).

        Raises
        ------
        ParameterError
            For frequencies that are not finite.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> s = vm.models.SDOF(m=1.0, k=3947.84, zeta=0.05)     # 10 Hz, Q 10
        >>> mag, lag = s.magnification([10.0])
        >>> round(float(mag[0]), 2), round(float(lag[0]), 3)      # Q at resonance, 90 degrees
        (10.0, 1.571)
        """
        h = self.frf(freq) * self.k
        return np.abs(h), -np.angle(h)

    def harmonic_response(self, freq, F0: float) -> tuple[np.ndarray, np.ndarray]:
        """Steady displacement amplitude and phase lag under F0 sin(w t).

        Parameters
        ----------
        freq : array_like
            Frequencies in Hz.
        F0 : float
            Force amplitude in N.

        Returns
        -------
        tuple of numpy.ndarray
            (amplitude in m, phase lag in rad).

        Raises
        ------
        ParameterError
            For frequencies that are not finite.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> s = vm.models.SDOF(m=1.0, k=3947.84, zeta=0.05)     # 10 Hz, Q 10
        >>> x, _ = s.harmonic_response([10.0], 1.0)
        >>> round(float(x[0]), 5)
        0.00253
        """
        mag, ph = self.magnification(freq)
        return mag * F0 / self.k, ph

    def transmissibility(self, freq) -> np.ndarray:
        """Force (to the foundation) and displacement (from a moving base) transmissibility:
        sqrt(1 + (2 zeta r)^2) / sqrt((1 - r^2)^2 + (2 zeta r)^2) for viscous damping.

        Parameters
        ----------
        freq : array_like
            Frequencies in Hz.

        Returns
        -------
        numpy.ndarray

        Raises
        ------
        ParameterError
            For frequencies that are not finite.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> s = vm.models.SDOF(m=1.0, k=3947.84, zeta=0.05)     # 10 Hz, Q 10
        >>> round(float(s.transmissibility([10.0 * 2 ** 0.5])[0]), 2)   # isolation starts at sqrt(2) fn
        1.0
        """
        w = 2 * np.pi * np.asarray(freq, float)
        num = self.k * (1 + 1j * self.loss_factor) + 1j * w * self.c
        return np.abs(num / (self.k * (1 + 1j * self.loss_factor) - self.m * w ** 2 + 1j * w * self.c))

    def base_excitation(self, freq, Y: float) -> dict:
        """Base moving as Y sin(w t): absolute amplitude X = Y T and relative amplitude Z.

        Parameters
        ----------
        freq : array_like
            Frequencies in Hz.
        Y : float
            Base amplitude in m.

        Returns
        -------
        dict
            "absolute" and "relative" amplitudes in m.

        Raises
        ------
        ParameterError
            For frequencies that are not finite.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> s = vm.models.SDOF(m=1.0, k=3947.84, zeta=0.05)     # 10 Hz, Q 10
        >>> round(float(s.base_excitation([10.0], 1e-3)["relative"][0] * 1e3), 2)   # Q x Y at resonance
        10.0
        """
        w = 2 * np.pi * np.asarray(freq, float)
        T = self.transmissibility(freq)
        rel = np.abs(self.m * w ** 2 * self.frf(freq)) * Y
        return {"absolute": T * Y, "relative": rel}

    def unbalance_response(self, freq, *, me: float) -> np.ndarray:
        """Amplitude from a rotating unbalance me (kg m) at rotation frequency f: me w^2 |H|.

        Parameters
        ----------
        freq : array_like
            Rotation frequencies in Hz.
        me : float
            Unbalance in kg m.

        Returns
        -------
        numpy.ndarray
            m.

        Raises
        ------
        ParameterError
            For an unbalance that is not positive.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> s = vm.models.SDOF(m=1.0, k=3947.84, zeta=0.05)     # 10 Hz, Q 10
        >>> round(float(s.unbalance_response([10.0], me=0.01)[0]), 3)   # Q me / m at resonance
        0.1
        """
        w = 2 * np.pi * np.asarray(freq, float)
        return positive(me, "me") * w ** 2 * np.abs(self.frf(freq))

    def __repr__(self) -> str:
        eta = f", loss_factor={self.loss_factor:g}" if self.loss_factor else ""
        return f"SDOF(m={self.m:g}, k={self.k:g}, c={self.c:g}{eta}; fn={self.fn:.5g} Hz, zeta={self.zeta:.4g})"


def stiffness_for(fn: float, m: float) -> float:
    """Stiffness k = m (2 pi fn)^2 that puts a mass at a natural frequency.

    Parameters
    ----------
    fn : float
        Natural frequency in Hz.
    m : float
        Mass in kg.

    Returns
    -------
    float
        N/m.

    Raises
    ------
    ParameterError
        For values that are not positive.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> round(vm.models.stiffness_for(10.0, 1.0), 1)
    3947.8
    """
    return positive(m, "m") * (2 * np.pi * positive(fn, "fn")) ** 2
