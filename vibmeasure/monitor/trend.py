"""Trends and alarms over a measurement store: per asset, point and metric a baseline from the first
healthy measurements, limits from its statistics (and ISO 10816-3 zones for velocity RMS), the trend
slope with its std and the projected crossing of the alarm limit; a verdict ok / watch / alarm per
metric, rolled up per point and per asset.

Limits: watch at baseline mean + K_WATCH std, alarm at + K_ALARM std, in the metric's bad direction,
never closer to the baseline than the metric's floor (a relative change, or an absolute level), so a
very quiet baseline does not turn measurement noise into alarms. A level counts only when the last
two measurements both reach it (one outlier is a watch at most). A significant slope (above 2 std)
that reaches the alarm limit within ``horizon_days``, and no further ahead than the history since the
baseline reaches back (a warm-up over hours says nothing about weeks), raises ok to watch.

Absolute rules need no baseline: a fault the diagnosis names with confidence >= 0.5 in the last two
measurements is an alarm (in the last one, a watch), and the ISO 10816-3 zone C or D of the velocity
is a watch or an alarm; a baseline taken while a fault was already there cannot hide it. A point
with fewer measurements than the baseline needs is listed ("no baseline yet") with what the absolute rules
say, never left out. A measurement analysed again (``batch(force=True)``) counts once, by its
latest result.

NA4 (Zakrajsek 1993, in the form normalised by a healthy history), per gear (``gear_na4`` on the
measured shaft, ``gear_mating_na4`` on its mating one): the fourth moment of the gear's synchronous
residual over the square of the baseline's mean variance, ``FM4 x (variance / baseline mean
variance)^2``. FM4 stays near 3 as damage spreads over every tooth (the residual grows but stays
Gaussian); NA4 grows with the residual's level. Watch at 4/3 of the baseline's NA4 (FM4's fault
threshold, 4, over a healthy 3), alarm at twice it.
"""

from __future__ import annotations

import numpy as np

from ..core.errors import ParameterError

__all__ = ["trend", "metric_history", "with_na4", "METRICS"]

K_WATCH, K_ALARM = 3.0, 6.0
LEVELS = ("ok", "watch", "alarm")
TOO_FEW = -1            # a point whose history is shorter than the baseline: no relative limit yet
NAMED = 0.5             # a diagnosis naming a fault from this confidence on counts as a finding
# task, summary column, bad direction (+1 rising, -1 falling, 0 either), floor kind, watch floor, alarm floor
METRICS = (
    ("diagnose", "velocity_rms_mm_s", +1, "relative", 0.5, 1.0),
    ("diagnose", "bearing_evidence", +1, "absolute", 8.0, 12.0),
    ("diagnose", "gear_na4", +1, "relative", 1 / 3, 1.0),
    ("diagnose", "gear_mating_na4", +1, "relative", 1 / 3, 1.0),
    ("spectrum", "rms", +1, "relative", 0.5, 1.0),
    ("ringdown", "fn1_hz", 0, "relative", 0.005, 0.01),
    ("modes", "fn1_hz", 0, "relative", 0.005, 0.01),
)
ISO_VERDICT = {"A": 0, "B": 0, "C": 1, "D": 2}
# a derived metric's stored column: the measurements that count toward it
SOURCE = {"gear_na4": "gear_fm4", "gear_mating_na4": "gear_mating_fm4"}


def _limits(base, direction, kind, fw, fa):
    mu, sd = float(np.mean(base)), float(np.std(base, ddof=1)) if base.size > 1 else 0.0
    if kind == "relative":
        dw, da = max(K_WATCH * sd, fw * abs(mu)), max(K_ALARM * sd, fa * abs(mu))
        return mu, sd, dw, da
    # absolute floors: the limit is a level of the metric itself (e.g. -log10 p)
    return mu, sd, max(K_WATCH * sd, fw - mu), max(K_ALARM * sd, fa - mu)


def _levels(v: np.ndarray, mu, dw, da, direction) -> list:
    """0 (within the watch limit), 1 (watch) or 2 (alarm) for each value (a NaN deviation is 0)."""
    dev = (v - mu) if direction > 0 else (mu - v) if direction < 0 else np.abs(v - mu)
    return np.where(dev >= da, 2, np.where(dev >= dw, 1, 0)).tolist()


def trend(store, *, asset: str | None = None, point: str | None = None, baseline_count: int = 8,
          horizon_days: float = 90.0):
    """Verdicts per asset, point and metric of a store, worst first.

    A baseline per point and metric from the first measurements; watch and alarm limits at 3 and 6
    baseline stds in the metric's bad direction (never closer than a floor; ISO zones for velocity);
    the trend slope with its std and the projected alarm date.

    Parameters
    ----------
    store : str, os.PathLike or Store
        The store.
    asset, point : str, optional
        Only this asset or point.
    baseline_count : int
        Measurements in the baseline.
    horizon_days : float
        A significant slope reaching the alarm limit within this many days is a watch.

    Returns
    -------
    pandas.DataFrame
        One row per metric (baseline, limits, last value, slope, projected alarm date, verdict, reason);
        ``attrs["points"]`` and ``attrs["assets"]`` hold the worst verdict per point and per asset.

    Raises
    ------
    ParameterError
        For a store that cannot be read.

    Examples
    --------
    >>> import tempfile, pathlib, warnings
    >>> import vibmeasure as vm
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = vm.synth.fleet(folder / "fleet", n_measurements=6, fault_onset=3)
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("ignore")
    ...     _ = vm.batch(task="diagnose", store=folder / "s.h5", manifest=folder / "fleet" / "machines.csv")
    >>> sorted(vm.trend(folder / "s.h5", baseline_count=3).attrs["assets"])[:2]
    ['pump-1', 'pump-2']
    """
    import pandas as pd
    from ..io.store import Store, is_store
    st = store if is_store(store) else Store(store)
    _check_baseline_count(baseline_count)
    rows = []
    # one row per measurement: a measurement analysed again counts once, by its latest result
    # (the summary values only: the full result documents are most of a long history's query time)
    frames = st._results_by_task([t for t, *_ in METRICS], asset=asset, point=point, with_result=False)
    frames["diagnose"] = with_na4(frames["diagnose"], baseline_count)
    rows += _diagnosis_rows(frames.get("diagnose"))
    for task, col, direction, kind, fw, fa in METRICS:
        df = frames[task]
        if df.empty or col not in df:
            continue
        for (a, p), g in df.groupby(["asset", "point"], sort=True):
            have = g[np.isfinite(pd.to_numeric(g[SOURCE.get(col, col)], errors="coerce"))]
            if have.empty:   # a metric the point never had (no unit, no gear): its diagnosis row lists it
                continue
            g = have[np.isfinite(pd.to_numeric(have[col], errors="coerce"))]
            if len(g) < baseline_count + 1:
                rows.append(_too_few(a, p, task, col, have, baseline_count))
                continue
            rows.append(_relative(a, p, task, col, g, (direction, kind, fw, fa), baseline_count, horizon_days))
    out = pd.DataFrame(rows, columns=["asset", "point", "task", "metric", "n", "baseline_mean", "baseline_std",
                                      "watch_limit", "alarm_limit", "last", "last_time", "slope_per_day",
                                      "slope_std", "alarm_date", "first_watch", "first_alarm", "level",
                                      "verdict", "reason"])
    out = out.sort_values(["level", "asset", "point"], ascending=[False, True, True], kind="stable")
    out = out.reset_index(drop=True)
    pts = out.groupby(["asset", "point"])["level"].max() if not out.empty else {}
    ass = out.groupby("asset")["level"].max() if not out.empty else {}
    out.attrs["points"] = {f"{a}/{p}": _verdict(v) for (a, p), v in dict(pts).items()}
    out.attrs["assets"] = {a: _verdict(v) for a, v in dict(ass).items()}
    return out.drop(columns="level")


def _check_baseline_count(baseline_count) -> None:
    if isinstance(baseline_count, bool) or not isinstance(baseline_count, (int, np.integer)) or baseline_count < 2:
        raise ParameterError(f"baseline_count={baseline_count!r} must be an integer >= 2")


def with_na4(df, baseline_count: int):
    """The diagnose results with NA4 per point for each gear whose synchronous residual they hold:
    ``gear_na4`` from ``gear_fm4`` and ``gear_residual_var`` (the gear on the measured shaft),
    ``gear_mating_na4`` from ``gear_mating_fm4`` and ``gear_mating_residual_var`` (its mating gear):
    FM4 x (variance / the mean variance of the point's first ``baseline_count`` measurements that have
    one)^2, NaN until that many exist. ``df`` is returned as it is without them.

    Raises
    ------
    ParameterError
        For a baseline_count that is not an integer >= 2, or a df that is not a DataFrame with asset
        and point columns.

    Examples
    --------
    >>> import pandas as pd
    >>> from vibmeasure.monitor.trend import with_na4
    >>> df = pd.DataFrame({"asset": "g", "point": "p", "gear_fm4": [3.0, 3.0, 3.0], "gear_residual_var": [1.0, 1.0, 2.0]})
    >>> with_na4(df, 2)["gear_na4"].tolist()
    [3.0, 3.0, 12.0]
    """
    import pandas as pd
    _check_baseline_count(baseline_count)
    if df is None:
        return df
    if not isinstance(df, pd.DataFrame) or not (df.empty or {"asset", "point"} <= set(df.columns)):
        raise ParameterError(f"df must be a results DataFrame with asset and point columns; got "
                             f"{type(df).__name__}{' without them' if isinstance(df, pd.DataFrame) else ''}")
    if df.empty:
        return df
    out = df
    for prefix in ("gear", "gear_mating"):
        if f"{prefix}_fm4" not in df or f"{prefix}_residual_var" not in df:
            continue
        fm4 = pd.to_numeric(df[f"{prefix}_fm4"], errors="coerce").to_numpy(float)
        var = pd.to_numeric(df[f"{prefix}_residual_var"], errors="coerce").to_numpy(float)
        na4 = np.full(len(df), np.nan)
        for idx in df.groupby(["asset", "point"], sort=False).indices.values():
            ok = idx[np.isfinite(fm4[idx]) & np.isfinite(var[idx]) & (var[idx] > 0)]
            if ok.size >= baseline_count:
                na4[ok] = fm4[ok] * (var[ok] / np.mean(var[ok[:baseline_count]])) ** 2
        out = out.assign(**{f"{prefix}_na4": na4})
    return out


def _verdict(level) -> str:
    return "no baseline yet" if int(level) == TOO_FEW else LEVELS[int(level)]


def _row(a, p, task, metric, n, last, last_time, level, reason, **values) -> dict:
    """A trend row without a baseline's statistics (absolute rules, too short a history)."""
    nan = float("nan")
    row = {"asset": a, "point": p, "task": task, "metric": metric, "n": n, "baseline_mean": nan,
           "baseline_std": nan, "watch_limit": nan, "alarm_limit": nan, "last": last, "last_time": last_time,
           "slope_per_day": nan, "slope_std": nan, "alarm_date": None, "first_watch": None, "first_alarm": None,
           "level": level, "verdict": _verdict(level), "reason": reason}
    row.update(values)
    return row


def _too_few(a, p, task, col, g, baseline_count) -> dict:
    """A point whose history is shorter than the baseline needs: listed, with the ISO zone of the
    velocity where it is C or D in the last two measurements."""
    n = len(g)
    last = float(g[col].iloc[-1]) if n else float("nan")
    level, reason = TOO_FEW, (f"{n} measurement(s) of {col}: no baseline yet (it needs {baseline_count} to "
                              "estimate the spread, and one more to judge against it)")
    if col == "velocity_rms_mm_s" and "zone" in g and n:
        zones = [ISO_VERDICT.get(str(z), 0) for z in g["zone"].iloc[-2:]]
        z = min(zones)
        if z:
            level = z
            reason += f"; ISO 10816-3 zone {g['zone'].iloc[-1]} in the last {len(zones)} measurement(s)"
    return _row(a, p, task, col, n, last, g["time"].iloc[-1] if n else None, level, reason)


def _diagnosis_rows(df) -> list:
    """Per point, the absolute rule on the diagnosis itself: a fault named with confidence >= NAMED
    in the last two measurements is an alarm, in the last one a watch, whatever the baseline (an
    asset whose first measurements already carry the fault has a baseline that hides it)."""
    if df is None or df.empty or "top" not in df or "confidence" not in df:
        return []
    rows = []
    for (a, p), g in df.groupby(["asset", "point"], sort=True):
        conf = g["confidence"].astype(float).to_numpy()
        named = [(t not in ("none", "undetermined") and c >= NAMED) for t, c in zip(g["top"], conf)]
        last2 = named[-2:]
        level = 2 if len(last2) == 2 and all(last2) and g["top"].iloc[-1] == g["top"].iloc[-2] else \
            1 if named[-1] else 0 if len(g) > 1 else TOO_FEW
        top = g["top"].iloc[-1]
        from ..core.labels import label
        reason = (f"{label(top)} named at {conf[-1]:.2f}" + (" in the last two measurements" if level == 2 else "")
                  if named[-1] else f"last diagnosis {top} ({conf[-1]:.2f}): no fault named")
        rows.append(_row(a, p, "diagnose", "diagnosis", len(g), float(conf[-1]), g["time"].iloc[-1], level,
                         reason))
    return rows


def metric_history(store, *, asset: str, point: str, metric: str, task: str | None = None,
                   baseline_count: int = 8):
    """One metric of one point over time, with its trend verdict: what ``plot_trend`` draws.

    Parameters
    ----------
    store : str, pathlib.Path or vm.Store
        The measurement store.
    asset, point : str
        The asset and its measurement point.
    metric : str
        A trended summary column (``METRICS``: velocity_rms_mm_s, bearing_evidence, gear_na4,
        gear_mating_na4, rms, fn1_hz).
    task : str, optional
        The task whose results hold the metric (default: the first that has it).
    baseline_count : int
        Measurements in the baseline.

    Returns
    -------
    (pandas.DataFrame, pandas.Series or None)
        The results (``time`` and the metric among the columns) and the metric's row of
        :func:`trend` (baseline mean and std, watch and alarm limits, verdict), None when not trended.

    Raises
    ------
    ParameterError
        When the metric is not trended, or the store holds no result of it for the point.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> from vibmeasure.monitor.trend import metric_history
    >>> metric_history("missing.h5", asset="a", point="p", metric="nope")  # doctest: +SKIP
    """
    from ..io.store import Store, is_store
    st = store if is_store(store) else Store(store)
    tasks = [t for t, c, *_ in METRICS if c == metric and (task is None or t == task)]
    if not tasks:
        raise ParameterError(f"metric={metric!r} is not trended; one of {sorted({c for _, c, *_ in METRICS})}")
    found = (with_na4(st.results(t, asset=asset, point=point, with_result=False), baseline_count) for t in tasks)
    df = next((d for d in found if not d.empty and metric in d), None)
    if df is None:
        raise ParameterError(f"no {metric} results for {asset}/{point} in the store")
    tr = trend(st, asset=asset, point=point, baseline_count=baseline_count)
    row = tr[tr["metric"] == metric]
    return df, (None if row.empty else row.iloc[0])


def _relative(a, p, task, col, g, rule, baseline_count, horizon_days) -> dict:
    """The trend row of one point's metric with a baseline: limits from the baseline's spread (``rule``:
    direction, floor kind, watch and alarm floors), the level held over the last two measurements, the
    slope since the baseline and where it leads, the ISO zone for velocity."""
    import pandas as pd
    direction, kind, fw, fa = rule
    y = g[col].to_numpy(float)
    t = (g["time"] - g["time"].iloc[0]).dt.total_seconds().to_numpy() / 86400.0
    base = y[:baseline_count]
    mu, sd, dw, da = _limits(base, direction, kind, fw, fa)
    lv = _levels(y[baseline_count:], mu, dw, da, direction)
    level = min(lv[-2:]) if len(lv) >= 2 else min(lv[-1], 1)
    # when each level was first reached (two measurements in a row): the alarm history
    held = np.minimum(lv[:-1], lv[1:])
    first = {}
    for lvl in (1, 2):
        j = np.flatnonzero(held >= lvl)
        first[lvl] = None if not j.size else g["time"].iloc[baseline_count + int(j[0]) + 1]
    from ..core.labels import label
    from ..core.rounding import with_std
    base, spread = with_std(mu, sd, digits=4)
    reason = f"{label(col)} {y[-1]:.4g} against baseline {base} +- {spread}"
    if level:
        reason += f" (beyond the {LEVELS[level]} limit in the last two measurements)"
    elif lv[-1]:
        reason += f" (one measurement beyond the {LEVELS[lv[-1]]} limit)"
        level = 1
    # trend over the measurements since the baseline
    tt, yy = t[baseline_count:], y[baseline_count:]
    slope = slope_std = np.nan
    cross = None
    if tt.size >= 3 and np.ptp(tt) > 0:
        A = np.column_stack([np.ones_like(tt), tt - tt.mean()])
        coef, res, *_ = np.linalg.lstsq(A, yy, rcond=None)
        r = yy - A @ coef
        s2 = float(r @ r) / max(tt.size - 2, 1)
        slope = float(coef[1])
        slope_std = float(np.sqrt(s2 / np.sum((tt - tt.mean()) ** 2)))
        sign = direction if direction else (np.sign(yy[-1] - mu) or 1)
        lim = mu + sign * da
        if slope * sign > 2 * slope_std and slope != 0:
            t_cross = tt.mean() + (lim - coef[0]) / slope
            # no further ahead than the history since the baseline reaches back
            if tt[-1] < t_cross <= tt[-1] + np.ptp(tt):
                cross = g["time"].iloc[0] + pd.Timedelta(days=float(t_cross))
                if level == 0 and t_cross - tt[-1] <= horizon_days:
                    level = 1
                    reason += f"; trending to the alarm limit by {cross:%Y-%m-%d}"
    if col == "velocity_rms_mm_s" and "zone" in g:
        z = ISO_VERDICT.get(str(g["zone"].iloc[-1]), 0)
        if z and (len(g) < 2 or ISO_VERDICT.get(str(g["zone"].iloc[-2]), 0) >= z) and z > level:
            level, reason = z, reason + f"; ISO 10816-3 zone {g['zone'].iloc[-1]}"
    sign = direction if direction else (1 if y[-1] >= mu else -1)  # either way: the side it went
    return {"asset": a, "point": p, "task": task, "metric": col, "n": len(y),
                 "baseline_mean": mu, "baseline_std": sd, "watch_limit": mu + sign * dw,
                 "alarm_limit": mu + sign * da, "last": float(y[-1]), "last_time": g["time"].iloc[-1],
                 "slope_per_day": slope, "slope_std": slope_std, "alarm_date": cross,
                 "first_watch": first[1], "first_alarm": first[2],
                 "level": level, "verdict": LEVELS[level], "reason": reason}
