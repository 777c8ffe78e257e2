"""Measured versus predicted (a model or a healthy baseline): paired modes, deviations, verdicts,
the stiffness change a frequency shift implies; baselines and trends per machine/point."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..core.errors import ParameterError
from ..core.results import Comparison, ModalEstimate

__all__ = ["compare", "Comparison", "History"]

LEVELS = ("ok", "watch", "alarm")


def _as_estimate(obj, what):
    if isinstance(obj, ModalEstimate):
        return obj
    if hasattr(obj, "modes") and callable(obj.modes):
        est = obj.modes()
        if isinstance(est, ModalEstimate):
            return est
    if isinstance(obj, History):
        return obj.baseline()
    raise ParameterError(f"{what} must be a vm.ModalEstimate, a model with .modes() or a History, "
                         f"got {type(obj).__name__}")


def _pair(meas: ModalEstimate, pred: ModalEstimate, max_rel: float):
    """Pairs (i_meas, j_pred) by frequency (log ratio), helped by MAC when both have shapes."""
    from scipy.optimize import linear_sum_assignment
    fm, fp = meas.fn, pred.fn
    ok_m, ok_p = np.isfinite(fm) & (fm > 0), np.isfinite(fp) & (fp > 0)
    cost = np.full((fm.size, fp.size), 1e6)
    for i in np.flatnonzero(ok_m):
        for j in np.flatnonzero(ok_p):
            cost[i, j] = abs(np.log(fm[i] / fp[j]))
    macm = None
    if meas.shapes is not None and pred.shapes is not None and np.shape(meas.shapes)[0] == np.shape(pred.shapes)[0]:
        from ..identify.shapes import mac
        macm = mac(np.asarray(meas.shapes), np.asarray(pred.shapes))
        cost = cost + 0.5 * (1 - macm)
    r, c = linear_sum_assignment(cost)
    pairs = [(i, j) for i, j in zip(r, c) if cost[i, j] < np.log1p(max_rel) + (0.5 if macm is not None else 0)]
    return pairs, macm




def compare(measured, predicted, *, rtol_fn: float = 0.02, rtol_zeta: float = 0.5, pair_rtol: float = 0.25,
            n_sigma: float = 3.0) -> Comparison:
    """Compare measured modes with a prediction (a model, a baseline estimate or a History).

    Per mode: the deviation of fn and zeta in % and in units of the combined std, the stiffness change
    the frequency shift implies (dk/k = (f_meas / f_pred)^2 - 1, mass unchanged), and a verdict: "alarm"
    when |dfn| exceeds ``rtol_fn`` and ``n_sigma`` stds, "watch" when it exceeds half of ``rtol_fn``
    (significantly) or zeta deviates by more than ``rtol_zeta``, else "ok".

    Parameters
    ----------
    measured : ModalEstimate
        The measurement.
    predicted : model, ModalEstimate or History
        Anything with ``modes()``, an estimate, or a baseline history.
    rtol_fn : float
        Relative frequency tolerance of an alarm.
    rtol_zeta : float
        Relative damping tolerance of a watch.
    pair_rtol : float
        Modes further apart than this (relative) find no partner.
    n_sigma : float
        Standard deviations a deviation must exceed to count.

    Returns
    -------
    Comparison
        ``verdict``, ``reason``, ``rows`` and ``to_frame()``.

    Raises
    ------
    ParameterError
        For a prediction without modes.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> est = vm.ringdown(vm.synth.free_decay(fn=10.0, zeta=0.02, fs=1000.0, duration=10.0, snr_db=40, seed=1))
    >>> model = vm.models.SDOF(m=1.0, k=(2 * 3.141592653589793 * 10.0) ** 2, zeta=0.02)
    >>> vm.compare(est, model).verdict
    'ok'
    """
    meas = _as_estimate(measured, "measured")
    pred = _as_estimate(predicted, "predicted")
    for name, v in (("rtol_fn", rtol_fn), ("rtol_zeta", rtol_zeta), ("pair_rtol", pair_rtol), ("n_sigma", n_sigma)):
        if not (np.isfinite(v) and v > 0):
            raise ParameterError(f"{name}={v!r} must be > 0")
    pairs, macm = _pair(meas, pred, pair_rtol)
    rows = []
    worst = 0
    reasons = []
    for i, j in pairs:
        fm, fp = meas.fn[i], pred.fn[j]
        zm, zp = meas.zeta[i], pred.zeta[j]
        sf = np.hypot(np.nan_to_num(meas.fn_std[i]), np.nan_to_num(pred.fn_std[j]))
        sz = np.hypot(np.nan_to_num(meas.zeta_std[i]), np.nan_to_num(pred.zeta_std[j]))
        dfn = (fm - fp) / fp
        dz = (zm - zp) / zp if zp > 0 else np.nan
        zf = (fm - fp) / sf if sf > 0 else np.inf * np.sign(fm - fp)
        significant = abs(zf) > n_sigma
        level = 0
        why = "within tolerance"
        if abs(dfn) > rtol_fn and significant:
            level, why = 2, f"fn {dfn * 100:+.2f} % (> {rtol_fn * 100:g} %, {abs(zf):.1f} std)"
        elif abs(dfn) > rtol_fn / 2 and significant:
            level, why = 1, f"fn {dfn * 100:+.2f} % (> {rtol_fn * 50:g} %, {abs(zf):.1f} std)"
        if np.isfinite(dz) and abs(dz) > rtol_zeta and (sz == 0 or abs(zm - zp) > n_sigma * sz) and level < 1:
            level, why = 1, f"zeta {dz * 100:+.1f} % (> {rtol_zeta * 100:g} %)"
        if not np.isfinite(zm) and np.isfinite(zp) and level < 1:
            # a missing damping value is not agreement: say that it was not compared
            level, why = 1, "measured zeta is NaN (not identified, e.g. dry friction): damping not compared"
        worst = max(worst, level)
        if level:
            reasons.append(f"mode at {fp:.4g} Hz: {why}")
        rows.append({"fn_measured_hz": fm, "fn_predicted_hz": fp, "fn_dev_pct": dfn * 100, "fn_dev_std": zf,
                     "zeta_measured": zm, "zeta_predicted": zp, "zeta_dev_pct": dz * 100 if np.isfinite(dz) else None,
                     "zeta_dev_std": (zm - zp) / sz if sz > 0 else None,
                     "implied_stiffness_change_pct": ((fm / fp) ** 2 - 1) * 100,
                     "mac": float(macm[i, j]) if macm is not None else None,
                     "verdict": LEVELS[level], "reason": why})
    nan_fn = [i for i in range(meas.n_modes) if not np.isfinite(meas.fn[i])]
    if nan_fn:  # a mode whose frequency was not identified cannot be paired: never "ok"
        worst = max(worst, 1)
        reasons.append(f"{len(nan_fn)} measured mode(s) with fn NaN (not identified) were not compared")
    um = tuple(float(meas.fn[i]) for i in range(meas.n_modes) if i not in {p[0] for p in pairs})
    up = tuple(float(pred.fn[j]) for j in range(pred.n_modes) if j not in {p[1] for p in pairs})
    if not rows:
        return Comparison((), "watch", "no measured mode pairs with a predicted one", um, up,
                          {"rtol_fn": rtol_fn, "rtol_zeta": rtol_zeta})
    reason = "; ".join(reasons) if reasons else f"{len(rows)} mode(s) within tolerance"
    return Comparison(tuple(rows), LEVELS[worst], reason, um, up,
                      {"rtol_fn": rtol_fn, "rtol_zeta": rtol_zeta, "n_sigma": n_sigma})


class History:
    """Modal estimates of one measurement point over time: baseline, trends, HDF5 storage.

    Parameters
    ----------
    name : str
        The point's name.
    baseline_count : int
        Entries the baseline averages.

    Raises
    ------
    ParameterError
        For a baseline count below 1.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> h = vm.History("pump-3 DE")
    >>> for day, f in enumerate([10.0, 9.9, 9.8]):
    ...     _ = h.add(vm.ModalEstimate(fn=[f], zeta=[0.02], fn_std=[0.01], zeta_std=[0.001]), time=day * 86400.0)
    >>> len(h.entries)
    3
    """

    def __init__(self, name: str = "point", *, baseline_count: int = 1):
        self.name = str(name)
        self.baseline_count = int(baseline_count)
        self.entries: list[tuple[float, ModalEstimate]] = []

    def add(self, est: ModalEstimate, *, time) -> "History":
        """Append an estimate measured at a time; times must increase.

        Parameters
        ----------
        est : ModalEstimate
            The estimate.
        time : float, datetime or pandas.Timestamp
            Seconds (any epoch, e.g. Unix time) or a date (naive times taken as UTC).

        Returns
        -------
        History
            Itself, for chaining.

        Raises
        ------
        ParameterError
            For an object that is no estimate, or a time that does not increase.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> h = vm.History("pump-3 DE")
        >>> for day, f in enumerate([10.0, 9.9, 9.8]):
        ...     _ = h.add(vm.ModalEstimate(fn=[f], zeta=[0.02], fn_std=[0.01], zeta_std=[0.001]), time=day * 86400.0)
        >>> h.entries[-1][0]
        172800.0
        """
        if not isinstance(est, ModalEstimate):
            raise ParameterError(f"est must be a vm.ModalEstimate, got {type(est).__name__}")
        time = _seconds(time)
        if self.entries and time <= self.entries[-1][0]:
            raise ParameterError(f"time={time} must increase (last entry at {self.entries[-1][0]})")
        self.entries.append((float(time), est))
        return self

    def baseline(self) -> ModalEstimate:
        """The healthy reference: the mean of the first ``baseline_count`` entries (per mode, by order).

        Returns
        -------
        ModalEstimate

        Raises
        ------
        ParameterError
            For an empty history.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> h = vm.History("pump-3 DE")
        >>> for day, f in enumerate([10.0, 9.9, 9.8]):
        ...     _ = h.add(vm.ModalEstimate(fn=[f], zeta=[0.02], fn_std=[0.01], zeta_std=[0.001]), time=day * 86400.0)
        >>> float(h.baseline().fn[0])
        10.0
        """
        if not self.entries:
            raise ParameterError(f"history {self.name!r} is empty: add a baseline measurement first")
        base = [e for _, e in self.entries[: self.baseline_count]]
        n = min(e.n_modes for e in base)
        fn = np.mean([e.fn[:n] for e in base], axis=0)
        z = np.mean([e.zeta[:n] for e in base], axis=0)
        fs = np.sqrt(np.mean([np.nan_to_num(e.fn_std[:n]) ** 2 for e in base], axis=0) / len(base))
        zs = np.sqrt(np.mean([np.nan_to_num(e.zeta_std[:n]) ** 2 for e in base], axis=0) / len(base))
        return ModalEstimate(fn=fn, zeta=z, fn_std=fs, zeta_std=zs, method="baseline")

    def trend(self, *, mode: int = 0, quantity: str = "fn", threshold: float | None = None,
              horizon: float | None = None) -> dict:
        """Weighted line through one quantity of a mode over time: slope with its std, and when it crosses
        a threshold ("watch" when predicted within ``horizon``).

        Parameters
        ----------
        mode : int
            The mode (paired by frequency with the baseline).
        quantity : {"fn", "zeta"}
            What to trend.
        threshold : float, optional
            The level whose crossing is predicted.
        horizon : float, optional
            Seconds ahead a predicted crossing makes a watch.

        Returns
        -------
        dict
            slope_per_time, slope_std, value_now, n_points, crossing_time, verdict.

        Raises
        ------
        ParameterError
            For fewer than 3 entries or an unknown quantity.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> h = vm.History("pump-3 DE")
        >>> for day, f in enumerate([10.0, 9.9, 9.8]):
        ...     _ = h.add(vm.ModalEstimate(fn=[f], zeta=[0.02], fn_std=[0.01], zeta_std=[0.001]), time=day * 86400.0)
        >>> round(h.trend()["slope_per_time"] * 86400, 3)
        -0.1
        """
        if quantity not in ("fn", "zeta"):
            raise ParameterError(f"quantity={quantity!r} must be 'fn' or 'zeta'")
        if len(self.entries) < 3:
            raise ParameterError(f"a trend needs at least 3 entries; history {self.name!r} has {len(self.entries)}")
        ref = self.baseline().fn[mode]
        t, y, s = [], [], []
        for ti, e in self.entries:
            k = int(np.argmin(np.abs(e.fn - ref)))
            t.append(ti)
            y.append(getattr(e, quantity)[k])
            s.append(getattr(e, f"{quantity}_std")[k])
        t, y, s = np.array(t), np.array(y), np.array(s)
        w = 1 / np.where(np.isfinite(s) & (s > 0), s, np.nanmax(np.where(s > 0, s, np.nan)) if np.any(s > 0) else 1) ** 2
        A = np.column_stack([np.ones_like(t), t - t.mean()])
        cov = np.linalg.inv(A.T @ (A * w[:, None]))
        b = cov @ A.T @ (w * y)
        res = y - A @ b
        chi2 = float(res @ (w * res)) / max(len(t) - 2, 1)
        cov = cov * max(chi2, 1.0)  # scatter beyond the stated std widens the trend's uncertainty
        out = {"slope_per_time": float(b[1]), "slope_std": float(np.sqrt(cov[1, 1])), "value_now": float(A[-1] @ b),
               "n_points": len(t)}
        if threshold is not None and b[1] != 0:
            t_cross = t.mean() + (threshold - b[0]) / b[1]
            out["crossing_time"] = float(t_cross) if t_cross > t[-1] else None
            early = (out["crossing_time"] is not None and horizon is not None and t_cross - t[-1] <= horizon
                     and abs(b[1]) > 2 * out["slope_std"])
            out["verdict"] = "watch" if early else "ok"
        return out

    # --- storage ---------------------------------------------------------------------------------
    def save(self, path) -> None:
        """Write to HDF5, atomically and sealed with a checksum, merging what another process saved meanwhile.

        Under an exclusive lock the file is read again and merged (by time and values), so concurrent
        load-add-save cycles lose no entry.

        Parameters
        ----------
        path : str or os.PathLike
            The file.

        Returns
        -------
        None

        Raises
        ------
        ParameterError
            For a folder that does not exist or a damaged file at the path.

        Examples
        --------
        >>> import numpy as np
        >>> import vibmeasure as vm
        >>> h = vm.History("pump-3 DE")
        >>> for day, f in enumerate([10.0, 9.9, 9.8]):
        ...     _ = h.add(vm.ModalEstimate(fn=[f], zeta=[0.02], fn_std=[0.01], zeta_std=[0.001]), time=day * 86400.0)
        >>> import tempfile, pathlib
        >>> p = pathlib.Path(tempfile.mkdtemp()) / "h.h5"
        >>> h.save(p)
        >>> len(vm.History.load(p).entries)
        3
        """
        with _locked(path):
            if Path(path).is_file():
                self._merge(History.load(path))
            self._write(path)

    def _merge(self, other: "History"):
        def key(e):
            t, m = e
            return (t, m.method, tuple(np.round(m.fn, 12)), tuple(np.round(m.zeta, 15)))
        seen = {key(e) for e in self.entries}
        self.entries = sorted(self.entries + [e for e in other.entries if key(e) not in seen], key=lambda e: e[0])

    def _write(self, path) -> None:
        import h5py
        from ..io._common import atomic_path
        from ..io.hdf5 import USERBLOCK, seal
        with atomic_path(path) as tmp:
            with h5py.File(tmp, "w", userblock_size=USERBLOCK) as f:
                f.attrs["vibmeasure_schema"] = "vibmeasure.history"
                f.attrs["schema_version"] = 1
                f.attrs["name"] = self.name
                f.attrs["baseline_count"] = self.baseline_count
                for i, (ti, e) in enumerate(self.entries):
                    g = f.create_group(f"entry{i:05d}")
                    g.attrs["time"] = ti
                    g.attrs["method"] = e.method
                    g.attrs["flags"] = json.dumps(list(e.flags))
                    for k in ("fn", "zeta", "fn_std", "zeta_std"):
                        g[k] = getattr(e, k)
            seal(tmp)

    @classmethod
    def load(cls, path) -> "History":
        import h5py
        from ..io.hdf5 import check_seal
        if not Path(path).is_file():
            raise ParameterError(f"history file {str(path)!r} does not exist")
        check_seal(path, f"history file {str(path)!r}")
        try:
            f = h5py.File(path, "r")
        except (OSError, ValueError) as exc:
            raise ParameterError(f"history file {str(path)!r} is unreadable: {exc}") from None
        with f:
            if f.attrs.get("vibmeasure_schema") not in ("vibmeasure.history", b"vibmeasure.history"):
                raise ParameterError(f"{str(path)!r} is not a vibmeasure history (baseline) file")
            try:
                h = cls(str(f.attrs["name"]), baseline_count=int(f.attrs["baseline_count"]))
                for key in sorted(f):
                    g = f[key]
                    h.entries.append((float(g.attrs["time"]), ModalEstimate(
                        fn=g["fn"][()], zeta=g["zeta"][()], fn_std=g["fn_std"][()], zeta_std=g["zeta_std"][()],
                        method=str(g.attrs["method"]), flags=tuple(json.loads(g.attrs["flags"])))))
            except (KeyError, ValueError, TypeError, OSError, AttributeError) as exc:
                raise ParameterError(f"history file {str(path)!r} is damaged ({type(exc).__name__}: {exc})") from None
        return h


def _seconds(time) -> float:
    from ..core._validate import as_seconds
    return as_seconds(time)


class _locked:
    """An exclusive lock on path + ".lock" (fcntl) for a read-modify-write of one file."""

    def __init__(self, path):
        self.lock = Path(str(path) + ".lock")

    def __enter__(self):
        import fcntl
        if not self.lock.parent.exists():
            raise ParameterError(f"path={str(self.lock)[:-5]!r}: folder {str(self.lock.parent)!r} does not exist")
        self.fh = open(self.lock, "a")
        fcntl.flock(self.fh, fcntl.LOCK_EX)
        return self

    def __exit__(self, *exc):
        import fcntl
        fcntl.flock(self.fh, fcntl.LOCK_UN)
        self.fh.close()
