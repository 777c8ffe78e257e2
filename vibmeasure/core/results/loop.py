"""Damping read off a measured force-displacement (hysteresis) loop."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field


from ._common import jsonable


@dataclass(frozen=True)
class LoopDamping:
    """Energy dissipated per cycle and what it implies, each the mean over whole cycles with its std.

    ``zeta`` is the equivalent viscous ratio eta / 2 (exact at resonance).

    Parameters
    ----------
    energy_per_cycle, energy_std : float
        W, the loop's area, in J, and its std over the cycles.
    loss_factor, loss_factor_std : float
        eta = W / (2 pi U) with U = k X^2 / 2, and its std.
    c_equivalent, c_std : float
        W / (pi w X^2) in N s/m: the viscous damper that dissipates as much at this frequency and amplitude.
    stiffness : float
        k in N/m, the part of the force in phase with the displacement.
    amplitude : float
        X in m, half the peak-to-peak displacement.
    freq : float
        Hz.
    n_cycles : int
        Whole cycles used.
    flags : tuple of str
        Quality flags (``vm.core.results.FLAG_TEXT``).

    Raises
    ------
    ParameterError
        Never (a plain record of numbers).

    Examples
    --------
    >>> import vibmeasure as vm
    >>> r = vm.LoopDamping(0.1, 0.0, 0.05, 0.0, 10.0, 0.0, 2e4, 1e-3, 5.0, 10)
    >>> r.zeta
    0.025
    """

    energy_per_cycle: float
    energy_std: float
    loss_factor: float
    loss_factor_std: float
    c_equivalent: float
    c_std: float
    stiffness: float
    amplitude: float
    freq: float
    n_cycles: int
    flags: tuple = field(default_factory=tuple)

    @property
    def zeta(self) -> float:
        return self.loss_factor / 2

    def to_dict(self) -> dict:
        """The fields and zeta as JSON-ready values.

        Returns
        -------
        dict

        Raises
        ------
        ParameterError
            Never.

        Examples
        --------
        >>> import vibmeasure as vm
        >>> vm.LoopDamping(0.1, 0.0, 0.05, 0.0, 10.0, 0.0, 2e4, 1e-3, 5.0, 10).to_dict()["zeta"]
        0.025
        """
        d = asdict(self)
        d["zeta"] = self.zeta
        d["flags"] = list(self.flags)
        return jsonable(d)

    def __repr__(self) -> str:
        from ..rounding import with_std
        eta, eta_std = with_std(self.loss_factor, self.loss_factor_std, digits=4)
        std = "" if eta_std == "n/a" else f" +- {eta_std}"
        return (f"LoopDamping(W={self.energy_per_cycle:.4g} J per cycle, eta={eta}{std}, "
                f"c_eq={self.c_equivalent:.4g} N s/m at {self.freq:.4g} Hz, X={self.amplitude:.4g} m, "
                f"{self.n_cycles} cycles{', ' + ', '.join(self.flags) if self.flags else ''})")
