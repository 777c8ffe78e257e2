"""A small synthetic fleet measured over time, with its manifests."""

from __future__ import annotations

import numpy as np

from ..core.errors import ParameterError
from ..core.record import Record
from .decay import free_decay
from .machine import _impact_train, machine


def fleet(folder=None, *, n_measurements: int = 52, start: str = "2026-01-05", interval_days: float = 7.0,
          fault_onset: int = 26, fs: float = 12800.0, duration: float = 1.0, seed: int = 0):
    """A small synthetic fleet measured over time, for tests, the sample data and the demo.

    Four assets, one point each, measured every ``interval_days``: pump-1 and pump-2 healthy; pump-3
    whose 6205-2RS grows an outer-race defect from measurement ``fault_onset`` on; frame-1, a
    structure rung down at each visit whose stiffness falls by up to 6 %.

    Parameters
    ----------
    folder : str or os.PathLike, optional
        Write each record there as HDF5, with the manifests machines.csv and structures.csv.
    n_measurements : int
        Measurements per asset.
    start : str
        Date of the first measurement (ISO 8601).
    interval_days : float
        Days between measurements.
    fault_onset : int
        Measurement at which the faults begin.
    fs : float
        Sampling rate of the machines in Hz.
    duration : float
        Length of each machine record in s.
    seed : int
        Random seed.

    Returns
    -------
    list of dict
        record, asset, point, time (ISO 8601), rpm, bearing, truth.

    Raises
    ------
    ParameterError
        For values out of range.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> items = vm.synth.fleet(n_measurements=2)
    >>> sorted({i["asset"] for i in items})
    ['frame-1', 'pump-1', 'pump-2', 'pump-3']
    """
    import datetime as _dt
    from pathlib import Path

    from ..core._validate import positive
    from ..models.bearing import BEARINGS
    if isinstance(n_measurements, bool) or not isinstance(n_measurements, (int, np.integer)) or n_measurements < 2:
        raise ParameterError(f"n_measurements={n_measurements!r} must be an integer >= 2")
    fs, duration, interval_days = positive(fs, "fs"), positive(duration, "duration"), positive(interval_days,
                                                                                             "interval_days")
    try:
        t_start = _dt.datetime.fromisoformat(start)
    except (TypeError, ValueError):
        raise ParameterError(f"start={start!r} must be an ISO 8601 date") from None
    rng = np.random.default_rng(seed)
    b = BEARINGS["6205-2RS"]
    items = []
    n = int(round(fs * duration))
    for i in range(n_measurements):
        when = (t_start + _dt.timedelta(days=i * interval_days)).isoformat()
        grow = max(0.0, (i - fault_onset + 1) / max(n_measurements - fault_onset, 1)) if i >= fault_onset else 0.0
        for asset in ("pump-1", "pump-2", "pump-3"):
            rpm = 1480.0 * (1 + 0.01 * rng.uniform(-1, 1))
            rec = machine(fault="none", rpm=rpm, fs=fs, duration=duration, seed=rng.integers(1 << 31))
            x = rec.data[0].copy()
            truth = "none"
            if asset == "pump-3" and grow > 0:
                f_o = b.frequencies(rpm / 60.0)["BPFO"]
                times, tk = [], rng.uniform(0, 1 / f_o)
                while tk < duration:
                    times.append(tk)
                    tk += (1 + 0.01 * rng.normal()) / f_o
                x += 2.0 * grow * np.std(x) * _impact_train(n, fs, times, 3500.0)
                truth = "bearing_outer_race"
            r = Record(x, fs, rec.channels, meta={"rpm": rpm, "time": when, "truth": {"fault": truth, "grow": grow}},
                       history=("synth fleet",))
            items.append({"record": r, "asset": asset, "point": "DE", "time": when, "rpm": rpm,
                          "bearing": "6205-2RS", "truth": truth})
        loss = 0.06 * grow
        fn = 24.0 * np.sqrt(1 - loss)
        r = free_decay(fn=fn, zeta=0.01, fs=1000.0, duration=8.0, snr_db=40, seed=int(rng.integers(1 << 31)),
                       phase=float(rng.uniform(0, 2 * np.pi)), quantity="acceleration")
        r = r.replace(meta={"time": when, "truth": {"fn": fn, "stiffness_loss": loss}})
        items.append({"record": r, "asset": "frame-1", "point": "top", "time": when, "rpm": None, "bearing": None,
                      "truth": "stiffness_loss" if loss > 0 else "none"})
    if folder is not None:
        import csv

        from ..io import write
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        rows = []
        for k, it in enumerate(items):
            name = f"{it['asset']}_{it['time'][:10]}.h5"
            write(folder / name, it["record"])
            it["file"] = str(folder / name)
            rows.append({"file": name, "asset": it["asset"], "point": it["point"], "time": it["time"],
                         "rpm": "" if it["rpm"] is None else f"{it['rpm']:.3f}", "bearing": it["bearing"] or ""})
        for name, keep in (("machines.csv", lambda r: r["rpm"]), ("structures.csv", lambda r: not r["rpm"])):
            with open(folder / name, "w", newline="") as fh:
                w = csv.DictWriter(fh, fieldnames=["file", "asset", "point", "time", "rpm", "bearing"])
                w.writeheader()
                w.writerows(r for r in rows if keep(r))
    return items
