"""Batch analysis into a measurement store, serially or on a Dask cluster.

Inputs are files, folders and globs, with an optional manifest (CSV: ``file`` (name or glob relative
to the manifest), ``asset``, ``point``, ``channel``, ``rpm``, ``bearing``, ``gear`` (teeth, or teeth/mating
teeth), ``model``, ``time``, ``unit`` and ``fs`` (for files that do not state them), and for a speed that
varies ``tach`` (the tachometer channel) and ``pulses_per_rev``). A manifest row's ``channel`` is the
point's sensor: the only one analysed.
Each input is read and analysed by a pure function (:func:`analyse_file`) that returns plain data;
with Dask the workers run it and only the client writes the store, committing every few dozen
results. One bad file never stops the batch: its error is stored and listed. An input whose content
is already stored at its asset and point with a result of every task asked is skipped unless
``force=True``; one whose analysis failed is analysed again; either way a re-analysis adds results
to the measurement already stored, never a second measurement of the same content. A file a manifest
names is analysed once, with the manifest's metadata, even when it is also given as an input.
"""

from __future__ import annotations

import os
import re
import time as _time
from pathlib import Path

import numpy as np

from ..core._threads import one_blas_thread
from ..core.dispatch import analysis_for
from ..core.errors import ParameterError, VibMeasureError
from ..io._common import file_sha256
from .inputs import _expand, _unique, read_manifest

__all__ = ["batch", "analyse_file", "TASKS"]

TASKS = ("ringdown", "modes", "spectrum", "diagnose", "compare")
COMMIT_EVERY = 50       # inputs per commit (each commit rewrites the store: see io/store.py)
MAX_PER_TASK = 8        # inputs per Dask task at most (fewer when the batch is small: every worker keeps busy)
COMMIT_SECONDS = 10.0
SPECTRUM_BANDS = ((2.0, 10.0), (10.0, 1000.0), (1000.0, 10000.0))  # Hz: sub-synchronous, ISO 10816, bearing/gear


def _tasks(task) -> tuple[str, ...]:
    items = [task] if isinstance(task, str) else list(task)
    out = []
    for t in items:
        for part in str(t).replace("+", ",").split(","):
            part = part.strip()
            if part not in TASKS + ("auto",):
                raise ParameterError(f"task={part!r} must be one of {TASKS}, or 'auto' (each file by what it "
                                     "holds: core.dispatch.analysis_for), or several joined by '+'")
            if part not in out:
                out.append(part)
    if not out:
        raise ParameterError(f"task must name at least one of {TASKS}")
    return tuple(out)


# --- the work of one input (runs on a worker) ------------------------------------------------------
def _summary_modes(est) -> dict:
    out = {"n_modes": int(est.n_modes)}
    for k in range(min(est.n_modes, 4)):
        out[f"fn{k + 1}_hz"] = float(est.fn[k])
        out[f"zeta{k + 1}"] = float(est.zeta[k])
        out[f"fn{k + 1}_std"] = float(est.fn_std[k])
    return out


def _run(task, rec, item, options):
    import vibmeasure as vm
    ch = item.get("channel")
    if task == "ringdown":
        est = vm.ringdown(rec, channel=ch)
        return est.to_dict(), _summary_modes(est), {"channel": est.extras.get("channel")}
    if task == "modes":
        forces = [c.name for c in rec.channels if c.quantity == "force"]
        if not forces:
            raise ParameterError("task 'modes' needs a force channel (quantity 'force') in the record")
        band = options.get("band") or (max(1.0, 2 * rec.fs / rec.n_samples), 0.4 * rec.fs)
        frf = vm.estimate_frf(rec, input=forces[0])
        est = vm.fit_modes(frf, band=tuple(band))
        return est.to_dict(), _summary_modes(est), {"input": forces[0], "band": list(band)}
    if task == "spectrum":
        names = [ch] if ch else None
        psd = vm.psd(rec, channels=names)
        amp = vm.amplitude_spectrum(rec, channels=names, nperseg=min(rec.n_samples, 1 << 14))
        pk = vm.pick_peaks(amp, n=5)
        summary = {"rms": float(np.sqrt(np.sum(psd.values[0]) * psd.df))}
        for lo, hi in SPECTRUM_BANDS:
            if lo < rec.fs / 2:
                summary[f"rms_{lo:g}_{min(hi, rec.fs / 2):g}_hz"] = float(vm.band_rms(psd, (lo, min(hi, 0.499 * rec.fs)))[0])
        for k in range(len(pk)):
            summary[f"peak{k + 1}_hz"] = float(pk.freq[k])
            summary[f"peak{k + 1}_amp"] = float(pk.amplitude[k])
        result = {"unit": psd.unit, "df_hz": psd.df, "peaks_hz": list(pk.freq), "peaks_amp": list(pk.amplitude),
                  "bands": summary}
        return result, summary, {"nperseg": psd.params["nperseg"], "channel": psd.channels[0]}
    if task == "diagnose":
        rpm, tach = item.get("rpm"), item.get("tach")
        # a row's channel is its point's sensor: the only one searched (another sensor's bearing is another point)
        channels = [ch] if ch else None
        rpm = rec.meta.get("rpm") if rpm is None and tach is None else rpm   # the speed the file states
        if rpm is None and tach is None:
            raise ParameterError("task 'diagnose' needs the shaft speed: give rpm (or a tach channel) in the manifest, "
                                 "or a file that states it")
        d = vm.diagnose(rec, rpm=None if rpm is None else float(rpm), bearing=item.get("bearing"),
                        gear=_gear(item.get("gear")), channel=ch, channels=channels, tach=tach,
                        pulses_per_rev=item.get("pulses_per_rev") or 1)
        rpm = d.speed.get("estimated_rpm") if rpm is None else rpm
        sev = d.severity or {}
        summary = {"top": d.top, "confidence": float(d.confidence),
                   "velocity_rms_mm_s": sev.get("velocity_rms_mm_s"), "zone": sev.get("zone"),
                   "bearing_checked": bool(d.bearing_checked)}
        fam = d.faults
        if fam is not None and "log10_p" in getattr(fam, "columns", ()):
            # the bearing evidence, -log10 p of the strongest family (0 when nothing was tested)
            lp = [float(v) for f, v in zip(fam["fault"], fam["log10_p"])
                  if str(f).startswith("bearing_") and f != "bearing_cage" and v == v and v is not None]
            summary["bearing_evidence"] = float(-min(lp)) if lp else 0.0
        if fam is not None and "shaft_fm4" in getattr(fam, "columns", ()):
            # each shaft's synchronous residual under the gear: FM4 and variance (the trend's NA4 needs both)
            row = fam[fam["fault"] == "gear_mesh"]
            for key, prefix in (("shaft", "gear"), ("mating", "gear_mating")):
                if len(row) and f"{key}_fm4" in row:
                    summary[f"{prefix}_fm4"] = _finite(row[f"{key}_fm4"].iloc[0])
                    summary[f"{prefix}_residual_var"] = _finite(row[f"{key}_residual_var"].iloc[0])
        params = {"rpm": float(rpm), "bearing": item.get("bearing"), "channel": d.channel}
        return d.to_dict(), summary, (dict(params, gear=item["gear"]) if item.get("gear") else params)
    raise ParameterError(f"task {task!r} is not a per-file task")


def _gear(spec):
    """A manifest's gear (``inputs._gear_spec``: teeth, or "teeth/mating teeth") as a vm.Gear, or None."""
    if spec is None or spec == "":
        return None
    from ..models.bearing import Gear
    teeth = [int(p) for p in str(spec).split("/")]
    return Gear(teeth[0], mating_shaft_ratio=teeth[0] / teeth[1] if len(teeth) == 2 else None)


def _finite(v):
    """A finite float, or None (a summary holds no NaN)."""
    try:
        v = float(v)
    except (TypeError, ValueError):
        return None
    return v if np.isfinite(v) else None


def analyse_files(items: list, tasks, options: dict | None = None) -> list:
    """:func:`analyse_file` for each of a few inputs: one Dask task (a retried task analyses all again)."""
    return [analyse_file(it, tasks, options) for it in items]


def analyse_file(item: dict, tasks, options: dict | None = None) -> dict:
    """Read one input and run the per-file tasks on it (``compare`` is done by the client, which
    knows the history). Returns plain data: the item, the file's SHA-256, its time, per task
    (result, summary, params) or an error message. Never raises for a bad file. BLAS runs on one
    thread: workers share the machine."""
    import warnings
    options = options or {}
    out = {"item": dict(item), "sha256": None, "time": None, "results": {}, "errors": {}, "channels": []}
    with one_blas_thread(), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            out["sha256"] = file_sha256(item["file"])
            rec = _read(item, options)
            out["channels"] = [c.name for c in rec.channels]
            out["n_samples"], out["fs"] = int(rec.n_samples), float(rec.fs)
            t = item.get("time") or rec.meta.get("time") or rec.meta.get("start_time")
            out["time"] = t if t is not None else os.path.getmtime(item["file"])
        except (VibMeasureError, OSError, ValueError) as exc:
            out["errors"]["read"] = f"{type(exc).__name__}: {exc}"
            return out
        for task in tasks:
            if task == "compare" or ("_only" in item and task not in item["_only"]):
                continue   # compare is the client's; a re-run does only the tasks still missing
            if task == "auto":   # the file's content decides, as in the report
                task = analysis_for(rec, rpm=item.get("rpm"), tach=item.get("tach"))
            try:
                out["results"][task] = _run(task, rec, item, options)
            except (VibMeasureError, ValueError, ArithmeticError) as exc:
                out["errors"][task] = f"{type(exc).__name__}: {exc}"
            except Exception as exc:  # a defect of vibmeasure: stored, named, the batch goes on
                out["errors"][task] = f"unexpected {type(exc).__name__}: {exc} (a defect of vibmeasure)"
    return out


def _read(item: dict, options: dict):
    """The input as a Record, with the row's fs and unit where the file does not state them."""
    import vibmeasure as vm
    fs = item.get("fs") or options.get("fs")
    return vm.read(item["file"], fs=fs, **({"unit": item["unit"]} if item.get("unit") else {}))


# --- the client -----------------------------------------------------------------------------------
def _asset_of(item) -> str:
    return item.get("asset") or Path(item["file"]).parent.name or "default"


def _register(store, item, channels):
    asset = _asset_of(item)
    point = item.get("point") or item.get("channel") or (channels[0] if channels else "point")
    if asset not in store._assets:
        store.add_asset(asset, bearing=item.get("bearing"), gear=item.get("gear"), model=item.get("model"))
    if (asset, point) not in store._points:
        store.add_point(asset, point, channel=item.get("channel"))
    return asset, point


_BASELINES: dict = {}  # per open store: the first estimate of each point (read from the file once)


def _estimate(d: dict, method: str):
    """A ModalEstimate (fn, zeta and their std) back from its stored ``to_dict()`` form."""
    from ..core.results import ModalEstimate
    modes = d.get("modes", [])
    if not modes:
        raise ParameterError("the stored estimate has no mode to compare")
    col = lambda k: [np.nan if m.get(k) is None else m[k] for m in modes]  # noqa: E731
    return ModalEstimate(fn=col("fn_hz"), zeta=col("zeta"), fn_std=col("fn_std_hz"), zeta_std=col("zeta_std"),
                         method=method)


def _compare(store, asset, point, mid, results):
    """Compare this measurement's modal estimate with the asset's model (TOML) or, failing that, the
    point's first stored estimate (the baseline)."""
    import vibmeasure as vm
    src = results.get("ringdown") or results.get("modes")
    if src is None:
        raise ParameterError("task 'compare' needs 'ringdown' or 'modes' in the same batch")
    meas = _estimate(src[0], src[0].get("method", "ml"))
    model = store._assets[asset].get("model")
    if model:
        pred, against = vm.models.load(model), f"model {model}"
    else:
        task = "ringdown" if "ringdown" in results else "modes"
        key = (asset, point, task)
        if key not in _BASELINES.get(id(store), {}):
            prev = store.results(task, asset=asset, point=point)
            prev = prev[prev["measurement"] != mid]
            if prev.empty:
                return None
            _BASELINES.setdefault(id(store), {})[key] = (_estimate(prev.iloc[0]["result"], "baseline"),
                                                        prev.iloc[0]["measurement"])
        pred, first = _BASELINES[id(store)][key]
        against = f"baseline {first}"
    c = vm.compare(meas, pred)
    dev = [abs(r["fn_dev_pct"]) for r in c.rows]
    return c.to_dict(), {"verdict": c.verdict, "max_fn_dev_pct": max(dev) if dev else None}, {"against": against}


def _store_one(store, out, tasks, keep_raw, options):
    item = out["item"]
    asset, point = _register(store, item, out.get("channels", []))
    item["_asset"] = asset   # the caller's alarm history covers the assets a run touched
    rec = None
    if keep_raw and not out["errors"].get("read") and item.get("_mid") is None:
        rec = _read(item, options)
    mid = item.get("_mid")   # a measurement already stored is analysed again: its results are added to it
    if mid is None:
        mid = store.add_measurement(asset, point, time=out["time"] if out["time"] is not None else _time.time(),
                                    rpm=item.get("rpm"), sha256=out["sha256"], file=str(item["file"]), record=rec,
                                    keep_raw=keep_raw)
    for task, (result, summary, params) in out["results"].items():
        store.add_result(mid, task, result, params=params, summary=summary)
    if "compare" in tasks and not out["errors"].get("read"):
        try:
            c = _compare(store, asset, point, mid, out["results"])
            if c is not None:
                store.add_result(mid, "compare", c[0], params=c[2], summary=c[1])
        except (VibMeasureError, ValueError) as exc:
            out["errors"]["compare"] = f"{type(exc).__name__}: {exc}"
    for task, msg in out["errors"].items():
        store.add_result(mid, "error", {"task": task, "message": msg}, summary={"failed_task": task, "message": msg})
    return mid


def batch(inputs=(), *, task="diagnose", store, manifest=None, client=None, workers: int | None = None,
          scheduler: str | None = None, force: bool = False, keep_raw: bool = False, fs: float | None = None,
          band=None, progress=None):
    """Analyse many inputs into a :class:`vibmeasure.Store`.

    A bad file never stops the batch (it is stored as an error); inputs already stored (same content)
    are skipped unless ``force``. Serially, or on Dask: only the client writes the store, and a task
    that fails on a worker is retried twice.

    Parameters
    ----------
    inputs : sequence of str or os.PathLike
        Files, folders and globs.
    task : str
        "ringdown", "modes", "spectrum", "diagnose", "compare", "auto" (each file by what it holds:
        ``core.dispatch.analysis_for``), or several joined by "+".
    store : str, os.PathLike or Store
        The store, created when missing.
    manifest : str or os.PathLike, optional
        A manifest CSV (``read_manifest``).
    client : dask.distributed.Client, optional
        An existing Dask client.
    workers : int, optional
        Start a local Dask cluster on 127.0.0.1 with this many processes.
    scheduler : str, optional
        Address of an existing Dask scheduler ("tcp://host:8786").
    force : bool
        Analyse inputs already in the store again.
    keep_raw : bool
        Store the raw records too.
    fs : float, optional
        Sampling rate for files without timing.
    band : tuple of float, optional
        (lo, hi) Hz for the modes task.
    progress : callable, optional
        ``progress(done, total)``: once with 0 when the inputs to analyse are known, then as each finishes.

    Returns
    -------
    pandas.DataFrame
        One row per input: file, status (done, skipped, error), measurement id, message.

    Raises
    ------
    ParameterError
        For an unknown task, no input, or a store that cannot be opened.

    Examples
    --------
    >>> import tempfile, pathlib, warnings
    >>> import vibmeasure as vm
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = vm.write(folder / "decay.h5", vm.synth.free_decay(fn=12.0, zeta=0.02, fs=500.0, duration=6.0, seed=1))
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("ignore")
    ...     rep = vm.batch([folder / "decay.h5"], task="ringdown", store=folder / "s.h5")
    >>> rep["status"].tolist()
    ['done']
    """
    from ..io.store import Store, is_store
    tasks = _tasks(task)
    items, notes = _unique(_expand(inputs) if inputs else [], read_manifest(manifest) if manifest is not None else [],
                           manifest)
    bad = [it for it in items if "error" in it]
    items = [it for it in items if "error" not in it]
    if not items and not bad:
        raise ParameterError("no input: give files, folders or globs, or a manifest")
    options = {"fs": fs, "band": band}
    own = not is_store(store)
    st = Store(store, writable=True) if own else store
    rows = [(f, "skipped", None, m) for f, m in notes] + [(it["file"], "error", None, it["error"]) for it in bad]
    todo = []
    try:
        shas = {}
        if st.n_measurements:   # the skip rule reads what the store holds of these inputs' contents only
            for it in items:
                try:
                    shas[it["file"]] = file_sha256(it["file"])
                except (OSError, VibMeasureError) as exc:
                    shas[it["file"]] = exc
        stored = _Stored(st, tasks, [v for v in shas.values() if isinstance(v, str)]) if shas else None
        for it in items:
            if stored is None:
                todo.append(it)
                continue
            sha = shas[it["file"]]
            if not isinstance(sha, str):
                rows.append((it["file"], "error", None, str(sha)))
                continue
            mid, missing = stored.find(sha, it)
            if mid is not None and not missing and not force:
                rows.append((it["file"], "skipped", mid, "already in the store (same content, every task done); "
                             "force=True to analyse again"))
            else:
                todo.append(it if mid is None else dict(it, _mid=mid) if force else dict(it, _mid=mid, _only=missing))
        total = len(todo)
        done = committed = 0
        last_commit = _time.monotonic()
        if progress is not None:   # the bar, and what a Ctrl-C during the first input says, know the total
            progress(0, total)

        touched: set = set()

        def take(out):
            nonlocal done, committed, last_commit
            mid = _store_one(st, out, tasks, keep_raw, options)
            touched.add(out["item"].get("_asset"))
            err = "; ".join(f"{k}: {v}" for k, v in out["errors"].items())
            rows.append((out["item"]["file"], "error" if err else "done", mid, err))  # a short row per input
            done += 1
            if progress is not None:
                progress(done, total)
            if done - committed >= COMMIT_EVERY or _time.monotonic() - last_commit > COMMIT_SECONDS:
                st.commit()
                committed, last_commit = done, _time.monotonic()

        _execute(todo, tasks, options, take, client, workers, scheduler)
        st.commit()
        _record_alarms(st, touched)
    finally:
        _BASELINES.pop(id(st), None)
        if own:
            st.close()
    import pandas as pd
    return pd.DataFrame(rows, columns=["file", "status", "measurement", "message"])


def _execute(todo, tasks, options, take, client, workers, scheduler) -> None:
    """Analyse the inputs, serially or on Dask, handing each outcome to ``take`` (the client alone
    writes the store)."""
    dask_client, cluster = _client(client, workers, scheduler)
    try:
        if dask_client is None:
            for it in todo:
                take(analyse_file(it, tasks, options))
        else:
            from distributed import as_completed
            # a few inputs per task, one map call, results taken in batches: a task per input cost the
            # client, which also hosts a local scheduler, 7-8 ms of CPU per input (a sixth of a core at
            # 24 records/s on 2 cores), time the workers then lacked
            n_w = max(1, len(dask_client.scheduler_info().get("workers", {})))
            size = max(1, min(MAX_PER_TASK, len(todo) // (8 * n_w)))
            chunks = [todo[i:i + size] for i in range(0, len(todo), size)]
            futs = dask_client.map(analyse_files, chunks, tasks=tasks, options=options, retries=2, pure=False)
            # the futures' own client's loop: as_completed otherwise takes the default client's, and
            # with two clients in one process that can hang (dask/distributed issue 4357)
            for batch_done in as_completed(futs, loop=dask_client.loop, with_results=True).batches():
                for fut, outs in batch_done:
                    for out in outs:
                        take(out)
                    fut.release()
    finally:
        if cluster is not None:  # a client (and cluster) this call started is closed by it
            dask_client.close()
            if cluster is not True:
                cluster.close()


def _record_alarms(st, assets) -> None:
    """The trend verdicts of the assets this run added to into the store's alarm history
    (``Store.alarms``): a database store keeps each change of verdict; the HDF5 store has no history."""
    assets = sorted(a for a in assets if a)
    if not assets or not hasattr(st, "record_verdicts"):
        return
    import pandas as pd

    from .trend import trend
    frames = [trend(st, asset=a) for a in assets]
    frames = [f for f in frames if len(f)]
    if frames:
        st.record_verdicts(pd.concat(frames, ignore_index=True))
        st.commit()


class _Stored:
    """What a store holds for a batch's skip rule, of the inputs' contents (``shas``) only: per content
    hash and asset, the measurements (point, id), and per measurement the tasks with a result (an error
    is no result). A store of a million measurements is not read whole to skip a few dozen inputs."""

    def __init__(self, st, tasks, shas):
        self.by_content: dict = {}
        for mid, sha, asset, point in st._with_contents(shas):
            self.by_content.setdefault((sha, asset), []).append((point, mid))
        wanted = [t for t in tasks if t not in ("compare", "auto")] or list(TASKS)
        self.tasks = [t for t in tasks if t != "auto"]
        self.any_task = "auto" in tasks
        self.done: dict = {}
        ids = [mid for hits in self.by_content.values() for _, mid in hits]
        # ids only (no result is parsed to learn which inputs are done)
        for t, mids in st._measurements_with(sorted(set(wanted) | (set(TASKS) if self.any_task else set())),
                                             ids).items():
            for mid in mids:
                self.done.setdefault(mid, set()).add(t)

    def find(self, sha: str, item: dict) -> tuple:
        """(measurement id or None, tasks still missing) for an input: the latest measurement of that
        content at its asset and (when the item names one) point."""
        point = item.get("point") or item.get("channel")
        hits = [mid for p, mid in self.by_content.get((sha, _asset_of(item)), ()) if point is None or p == point]
        if not hits:
            return None, list(self.tasks)
        mid = hits[-1]
        have = self.done.get(mid, set())
        missing = [t for t in self.tasks if t not in have]
        if self.any_task and not have:
            missing.append("auto")
        return mid, missing


def _client(client, workers, scheduler):
    if client is not None:
        return client, None
    if workers is None and scheduler is None:
        return None, None
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise ParameterError("workers= and scheduler= need Dask: pip install 'vibmeasure[dask]'") from None
    if scheduler is not None:
        # checked here: a Client that fails on a malformed address can hang in its own clean-up when
        # another cluster runs in the process
        m = re.fullmatch(r"(tcp|tls|ws|wss|ucx)://(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+):(\d{1,5})/?", str(scheduler))
        if m is None or not 0 < int(m.group(3)) < 65536:
            raise ParameterError(f"scheduler={scheduler!r} is not a scheduler address; the form is tcp://HOST:PORT")
        try:
            return Client(scheduler, timeout=30), True
        except (OSError, TimeoutError) as exc:
            raise ParameterError(f"scheduler={scheduler!r}: no Dask scheduler answers there ({exc})") from None
        except (ValueError, TypeError) as exc:
            raise ParameterError(f"scheduler={scheduler!r} is not a scheduler address ({exc})") from None
    if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1:
        raise ParameterError(f"workers={workers!r} must be an integer >= 1")
    import dask
    # one BLAS thread per worker; and no MALLOC_TRIM_THRESHOLD_ (Dask's default for its workers): with
    # it every array above 64 kB is mapped and unmapped afresh, and the analysis of a record runs 1.5-2x
    # slower than in a plain process (measured in benchmarks/batch.py)
    one = {"OPENBLAS_NUM_THREADS": 1, "OMP_NUM_THREADS": 1, "MKL_NUM_THREADS": 1}
    # worker-saturation inf: every worker holds its next inputs and never waits for the scheduler (in
    # this busy client process). The workers' own periodic duties (a stack profiler sampling every
    # 10 ms, an event-loop tick every 20 ms, system and memory monitors) made each analysis 16 % slower
    # than in a plain process (71.5 against 60.3 ms, measured one worker alone): they are for a
    # dashboard this cluster does not serve, so they run rarely or not at all
    quiet = {"distributed.worker.profile.enabled": False, "distributed.admin.tick.interval": "1s",
             "distributed.admin.system-monitor.interval": "2s", "distributed.worker.memory.monitor-interval": "1s"}
    with dask.config.set({"distributed.nanny.pre-spawn-environ": one,
                          "distributed.scheduler.worker-saturation": float("inf"), **quiet}):
        cluster = LocalCluster(n_workers=int(workers), threads_per_worker=1, processes=True, host="127.0.0.1",
                               dashboard_address=None)
    return Client(cluster), cluster
