"""Self-contained HTML reports (vm.report; the module is reporting.py so that importing it never hides
the function vm.report): what an engineer hands to colleagues.

One file, no network assets: CSS inline, every figure an inline SVG drawn by plot.py (the same
picture a user makes in Python), readable on a phone and printable. Sections follow what the inputs
hold: a ring-down, an FRF with its modes, a machine diagnosis, a comparison with a model or a
baseline, and fleet trends from a :class:`vibmeasure.Store`. Every quality flag is explained in
plain words with what to do about it. Provenance (software version, method and parameters, input
file hashes) closes the report. The HTML comes from a Jinja2 template (templates/report.html.j2).
"""

from __future__ import annotations

import datetime as _dt
import io as _io
import platform
from pathlib import Path

import numpy as np

from .core.errors import ParameterError, VibMeasureError
from .core.results import FLAG_TEXT
from .io._common import file_sha256

__all__ = ["report", "FLAG_ADVICE"]

FLAG_ADVICE = {
    "few_cycles": "record a longer decay, or excite harder so more cycles stand above the noise",
    "noise_floor": "nothing to do: the fit used the part of the record that carries the decay",
    "resolution_limited": "record longer (finer lines) or sample faster, or use the time-domain fit (vm.ringdown)",
    "clipped": "lower the sensor gain or the excitation: clipped samples carry no information",
    "close_modes": "treat fn and zeta of these modes with care; more outputs or a longer record separate them",
    "overdamped": "no natural frequency can be measured; check the sensor and the excitation",
    "coulomb_friction": "describe the damping by the friction decay per cycle, not by a viscous zeta",
    "amplitude_dependent": "quote zeta with its amplitude (see the backbone table), not as one number",
    "amplitude_dependent_frequency": "quote fn with its amplitude (see the backbone); a model needs a nonlinear "
                                     "stiffness term",
    "colored_noise": "the std was scaled up; filter or average to lower the noise near the mode",
    "low_snr": "excite harder or average more records",
    "start_detected": "check that the decay start found is after the excitation ended",
    "low_coherence": "average more hits or shaker records; check for noise, nonlinearity or a loose sensor",
    "double_hit": "repeat the hit: a double hit corrupts the force spectrum",
    "not_impact": "use estimate_frf for shaker (continuous) excitation",
    "bearing_not_checked": "give the bearing (catalogue name or geometry) so bearing faults are searched",
    "band_limited": "record a wider band (sample faster, open the anti-alias filter): bearing impacts ring in "
                    "resonances well above the shaft harmonics",
    "speed_varies": "record a tachometer or encoder with the vibration (tach=, --tach) or give the speed profile "
                    "(rpm_profile=), or measure at a steady speed",
    "order_tracked": "frequencies are orders x the mean speed; check the tachometer's pulses per revolution",
    "spikes_removed": "check the cabling, connectors and converter: glitches that come at regular intervals become "
                      "a comb in the envelope spectrum",
    "dropouts": "check the acquisition chain (buffer overruns, a link that drops out) and record again",
    "saturated": "lower the sensor gain or choose a larger range: clipped samples carry no information",
}


def _svg(fig) -> str:
    import matplotlib.pyplot as plt
    buf = _io.StringIO()
    try:
        fig.savefig(buf, format="svg", bbox_inches="tight")
    finally:
        plt.close(fig)
    s = buf.getvalue()
    return s[s.index("<svg"):]


def _fmt(v, digits=5):
    if v is None:
        return ""
    if isinstance(v, (float, np.floating)):
        if not np.isfinite(v):
            return "n/a"
        return f"{v:.{digits}g}"
    return str(v)


def _flags(flags) -> list[dict]:
    out, seen = [], set()
    for f in flags:
        if f in seen or f in ("noise_floor",):
            continue
        seen.add(f)
        out.append({"flag": f, "text": FLAG_TEXT.get(f, f),
                    "advice": FLAG_ADVICE.get(f, "see the documentation of the flag")})
    return out


def _mode_table(est, caption):
    rows = []
    for i in range(est.n_modes):
        rows.append([i + 1, _fmt(est.fn[i], 7), _fmt(est.fn_std[i], 2), _fmt(est.zeta[i], 4), _fmt(est.zeta_std[i], 2),
                     ", ".join(est.mode_flags[i]) if est.mode_flags else ""])
    return {"caption": caption, "header": ["mode", "fn [Hz]", "± std", "zeta [-]", "± std", "flags"], "rows": rows}


# --- sections -------------------------------------------------------------------------------------
def ringdown_section(rec, est, name):
    from . import plot
    mf = [f for m in est.mode_flags for f in m] if est.mode_flags else []
    sec = {"kind": "ringdown", "title": f"Ring-down: {name}", "tables": [_mode_table(est, "Natural frequencies and "
                                                                                       "damping (maximum likelihood)")],
           "flags": _flags(list(est.flags) + mf), "figures": []}
    k = int(np.argmax(est.amplitude)) if est.amplitude is not None and est.n_modes else 0
    sec["verdict"], sec["verdict_class"] = f"fn {est.fn[k]:.5g} Hz, zeta {est.zeta[k]:.4g}", "ok"
    sec["verdict_text"] = f"(strongest of {est.n_modes} mode(s); channel {est.extras.get('channel', '')})"
    ax, _ = plot.plot_ringdown(rec, est)
    sec["figures"].append({"svg": _svg(ax.figure), "caption": "record, fitted decay and envelope; residual below"})
    bb = est.extras.get("backbone")
    if bb is not None and len(bb) and k in set(bb["mode"]):
        b = bb[bb["mode"] == k]
        b = b.iloc[np.unique(np.linspace(0, len(b) - 1, min(len(b), 12)).round().astype(int))]  # 12 rows at most
        sec["tables"].append({"caption": f"Backbone of the {est.fn[k]:.4g} Hz mode (fn and zeta versus amplitude)",
                              "header": ["amplitude", "fn [Hz]", "± std", "zeta", "± std"],
                              "rows": [[_fmt(r.amplitude, 4), _fmt(r.fn_hz, 6), _fmt(r.fn_std_hz, 2), _fmt(r.zeta, 4),
                                        _fmt(r.zeta_std, 2)] for r in b.itertuples()]})
        axes = plot.plot_backbone(est, mode=k)
        sec["figures"].append({"svg": _svg(axes[0].figure), "caption": "damping and frequency versus amplitude"})
    return sec


def modes_section(frf, est, name):
    from . import plot
    mf = [f for m in est.mode_flags for f in m] if est.mode_flags else []
    sec = {"kind": "modes", "title": f"FRF and modes: {name}", "tables": [_mode_table(est, "Modes (LSCF + maximum "
                                                                                         "likelihood)")],
           "flags": _flags(list(est.flags) + mf), "figures": []}
    rej = est.extras.get("rejected_modes") or []
    if rej:
        sec["tables"].append({"caption": "Poles the data does not support (not reported as modes)",
                              "header": ["fn [Hz]", "zeta", "reason"],
                              "rows": [[_fmt(d["fn_hz"], 6), _fmt(d["zeta"], 3), d["reason"]] for d in rej]})
    sec["verdict"], sec["verdict_class"] = f"{est.n_modes} mode(s)", "ok"
    sec["verdict_text"] = "in " + "-".join(f"{b:g}" for b in est.extras.get("band_hz", [])) + " Hz"
    axes = plot.plot_frf(frf, est=est)
    sec["figures"].append({"svg": _svg(axes[0].figure), "caption": "FRF magnitude, phase and coherence with the "
                                                                   "modal synthesis"})
    ax = plot.plot_stabilisation(est, frf=frf)
    sec["figures"].append({"svg": _svg(ax.figure), "caption": "stabilisation diagram"})
    return sec


def diagnosis_section(rec, diag, name):
    from . import plot
    sev = diag.severity or {}
    # a "none" that is probably wrong (an unexplained candidate, a weak fault it could not name) is
    # worth a look, not a green light
    if diag.top == "none":
        cls = "ok" if diag.confidence >= 0.5 else "watch"
    else:
        cls = "alarm" if diag.confidence >= 0.9 else "watch"
    sec = {"kind": "diagnosis", "title": f"Machine diagnosis: {name}", "tables": [], "figures": [],
           "flags": _flags([f for f in diag.flags if f in FLAG_ADVICE]),
           "verdict": diag.top.replace("_", " "), "verdict_class": cls,
           "verdict_text": f"(confidence {diag.confidence:.2f}) {diag.reason}"}
    rows = []
    for r in diag.faults.to_dict(orient="records"):
        rows.append([r.get("fault"), _fmt(r.get("expected_hz"), 5), _fmt(r.get("found_hz"), 5),
                     _fmt(r.get("evidence_db"), 3), _fmt(r.get("confidence"), 2), _fmt(r.get("log10_p"), 3),
                     r.get("note") or ""])
    sec["tables"].append({"caption": "Evidence per fault family", "header": ["fault", "expected [Hz]", "found [Hz]",
                                                                            "evidence [dB]", "score",
                                                                            "log10 p", "note"], "rows": rows})
    sec["tables"].append({"caption": "ISO 10816-3 severity", "header": ["velocity RMS [mm/s]", "band [Hz]", "group",
                                                                       "foundation", "zone"],
                          "rows": [[_fmt(sev.get("velocity_rms_mm_s"), 3), "-".join(_fmt(b) for b in
                                                                                   sev.get("band_hz", [])),
                                    sev.get("group"), sev.get("foundation"), sev.get("zone")]]})
    axes = plot.plot_diagnosis(rec, diag)
    sec["figures"].append({"svg": _svg(np.ravel(axes)[0].figure), "caption": "spectrum, envelope spectrum with the "
                                                                             "fault comb, kurtogram, severity"})
    return sec


def comparison_section(cmp, name):
    from . import plot
    sec = {"kind": "compare", "title": f"Comparison: {name}", "figures": [], "flags": [],
           "verdict": cmp.verdict, "verdict_class": cmp.verdict, "verdict_text": cmp.reason,
           "tables": [{"caption": "Measured versus predicted", "header": ["fn measured [Hz]", "fn predicted [Hz]",
                                                                         "deviation [%]", "in std", "verdict"],
                       "rows": [[_fmt(r["fn_measured_hz"], 6), _fmt(r["fn_predicted_hz"], 6),
                                 _fmt(r["fn_dev_pct"], 3), _fmt(r["fn_dev_std"], 3), r["verdict"]] for r in cmp.rows]}]}
    ax = plot.plot_comparison(cmp)
    sec["figures"].append({"svg": _svg(ax.figure), "caption": "frequency deviation per mode and the tolerance"})
    return sec


def fleet_section(store, name):
    from . import plot
    from .monitor.trend import trend
    tr = trend(store)
    assets = tr.attrs.get("assets", {})
    worst = "alarm" if "alarm" in assets.values() else "watch" if "watch" in assets.values() else "ok"
    sec = {"kind": "fleet", "title": f"Fleet trends: {name}", "figures": [], "flags": [],
           "verdict": worst if len(tr) else "no trend yet", "verdict_class": worst if len(tr) else "watch",
           "verdict_text": ", ".join(f"{a}: {v}" for a, v in assets.items()) or
                           "fewer measurements than the baseline needs", "tables": []}
    sec["tables"].append({"caption": "Verdict per asset, point and metric", "header": ["asset", "point", "metric",
                                                                                       "baseline", "last", "alarm limit",
                                                                                       "verdict", "reason"],
                          "rows": [[r.asset, r.point, r.metric, _fmt(r.baseline_mean, 4), _fmt(r.last, 4),
                                    _fmt(r.alarm_limit, 4), r.verdict, r.reason] for r in tr.itertuples()]})
    for r in tr[tr["verdict"] != "ok"].head(4).itertuples():
        ax = plot.plot_trend(store, asset=r.asset, point=r.point, metric=r.metric, task=r.task)
        sec["figures"].append({"svg": _svg(ax.figure), "caption": f"{r.asset}/{r.point}: {r.metric}"})
    return sec


def error_section(name, exc):
    return {"kind": "error", "title": f"Input: {name}", "error": f"{type(exc).__name__}: {exc}", "tables": [],
            "figures": [], "flags": []}


# --- analysing an input by what it holds ----------------------------------------------------------
def analyse_input(path, *, rpm=None, bearing=None, band=None, model=None):
    """Sections for one file: an FRF/modes section when it has a force channel, a diagnosis when a
    shaft speed is known (``rpm`` or the file's rpm), else a ring-down; plus a comparison when a model
    (TOML) is given. Returns (sections, provenance row)."""
    import warnings
    from . import io
    from .identify.frf import estimate_frf, impact_frf
    from .identify.modal import fit_modes
    from .identify.ringdown import ringdown
    from .monitor.compare import compare
    from .monitor.machinery import diagnose
    name = Path(path).name
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rec = io.read(path)
        forces = [c.name for c in rec.channels if c.quantity == "force"]
        speed = rpm if rpm is not None else rec.meta.get("rpm")
        secs, method = [], ""
        if forces:
            try:
                frf = impact_frf(rec, input=forces[0])
                how = "impact_frf"
            except VibMeasureError:
                frf, how = estimate_frf(rec, input=forces[0]), "estimate_frf"
            b = band or (max(1.0, 4 * float(frf.freq[1])), 0.4 * rec.fs)
            est = fit_modes(frf, band=tuple(b))
            secs.append(modes_section(frf, est, name))
            method = f"{how} (input {forces[0]}) + fit_modes band {b[0]:.4g}-{b[1]:.4g} Hz"
        elif speed:
            diag = diagnose(rec, rpm=float(speed), bearing=bearing)
            secs.append(diagnosis_section(rec, diag, name))
            method = f"diagnose rpm {float(speed):.6g}, bearing {bearing or 'not given'}"
            est = None
        else:
            est = ringdown(rec, band=band)
            secs.append(ringdown_section(rec, est, name))
            method = "ringdown (maximum likelihood)" + (f", band {band}" if band else "")
        if model is not None and est is not None:
            from .models.loader import load
            what = f"{name} vs {Path(model).name}"
            try:  # a bad model is listed; the analysis of the record still stands
                secs.append(comparison_section(compare(est, load(model)), what))
                method += f"; compare with {Path(model).name}"
            except (VibMeasureError, OSError, ValueError) as exc:
                secs.append(error_section(f"comparison {what}", exc))
    return secs, {"input": name, "sha256": file_sha256(path), "method": method}


def report(inputs=(), out="report.html", *, store=None, title: str = "Vibration measurement report", rpm=None,
           bearing=None, band=None, model=None, summary=None) -> Path:
    """Write a self-contained HTML report of ``inputs`` (files) and, with ``store``, the fleet trends;
    returns its path. A file that cannot be analysed is listed with its error and the others are still
    reported. Written atomically: never a half-written report."""
    import jinja2
    import scipy
    from . import __version__
    from .io._common import atomic_path
    from .plot import file_backend
    out = Path(out)
    if not out.parent.exists():
        raise ParameterError(f"out={str(out)!r}: folder {str(out.parent)!r} does not exist")
    if isinstance(inputs, (str, Path)):
        inputs = [inputs]
    file_backend()
    sections, prov = [], []
    for p in inputs:
        try:
            secs, row = analyse_input(p, rpm=rpm, bearing=bearing, band=band, model=model)
            sections += secs
            prov.append(row)
        except (VibMeasureError, OSError, ValueError) as exc:
            sections.append(error_section(Path(p).name, exc))
            prov.append({"input": Path(p).name, "sha256": file_sha256(p) if Path(p).is_file() else "(missing)",
                         "method": "not analysed"})
    if store is not None:
        try:
            sections.append(fleet_section(store, Path(store).name if not hasattr(store, "path") else store.path.name))
            prov.append({"input": Path(store if not hasattr(store, "path") else store.path).name,
                         "sha256": file_sha256(store if not hasattr(store, "path") else store.path), "method": "trend"})
        except (VibMeasureError, OSError, ValueError) as exc:
            sections.append(error_section(str(store), exc))
    if not sections:
        raise ParameterError("nothing to report: give input files and/or a store")
    env = jinja2.Environment(loader=jinja2.PackageLoader("vibmeasure", "templates"),
                             autoescape=jinja2.select_autoescape(["html", "j2"]))
    html = env.get_template("report.html.j2").render(
        title=title, version=__version__, created=_dt.datetime.now().strftime("%Y-%m-%d %H:%M"),
        sections=sections, provenance=prov, summary=summary or [], python=platform.python_version(),
        numpy=np.__version__, scipy=scipy.__version__)
    with atomic_path(out) as tmp:
        tmp.write_text(html, encoding="utf-8")
    return out


def demo(out_dir="vibmeasure-demo", *, progress=None) -> dict:
    """The main job a newcomer runs: synthesise the demo inputs (if absent) with vm.synth, analyse
    them, write ``out_dir/report.html`` and ``out_dir/results.h5`` (a Store with the fleet history).
    Returns a short summary (paths, key numbers, seconds). ``progress(message)`` follows the steps."""
    import time
    from . import io, synth
    from .monitor.batch import batch
    t0 = time.perf_counter()
    say = progress if callable(progress) else (lambda msg: None)
    out = Path(out_dir)
    inp = out / "inputs"
    inp.mkdir(parents=True, exist_ok=True)
    files = {"ringdown": inp / "ringdown_beam.h5", "hammer": inp / "hammer_test.h5", "machine": inp / "pump_bearing.h5"}
    if not files["ringdown"].exists():
        say("synthesising a ring-down (beam, 23.7 Hz, zeta 0.012, 40 dB)")
        io.write(files["ringdown"], synth.free_decay(fn=23.7, zeta=0.012, fs=2000.0, duration=8.0, snr_db=40,
                                                     amplitude=5e-4, seed=1, quantity="acceleration", unit="m/s^2"))
    if not files["hammer"].exists():
        say("synthesising a hammer test (3 modes, 2 outputs)")
        fs, n = 2048.0, 8192
        f = np.zeros(n)
        f[100:103] = np.sin(np.pi * (np.arange(3) + 0.5) / 3) * 300.0  # a 1.5 ms half-sine hit: flat to ~500 Hz
        resp = synth.modal_response(f, fs=fs, fn=[31.0, 87.0, 165.0], zeta=[0.02, 0.015, 0.01],
                                    shapes=[[1.0, 0.8, 0.5], [0.6, -0.7, 0.9]], quantity="acceleration")
        rng = np.random.default_rng(3)
        resp += 0.002 * np.abs(resp).max() * rng.standard_normal(resp.shape)
        from .core.record import Channel, Record
        io.write(files["hammer"], Record(np.vstack([f + 0.05 * rng.standard_normal(n), resp]), fs,
                                         [Channel("hammer", "force", "N"), Channel("acc1", "acceleration", "m/s^2"),
                                          Channel("acc2", "acceleration", "m/s^2")]))
    if not files["machine"].exists():
        say("synthesising a pump with an outer-race bearing fault")
        io.write(files["machine"], synth.machine(fault="bearing_outer_race", rpm=1480.0, fs=12800.0, duration=2.0,
                                                 severity=0.6, seed=4))
    fleet_dir = inp / "fleet"
    if not (fleet_dir / "machines.csv").exists():
        say("synthesising a small fleet (4 assets, 20 weekly measurements)")
        synth.fleet(fleet_dir, n_measurements=20, fault_onset=10)
    store = out / "results.h5"
    say("analysing the fleet into results.h5")
    batch(task="diagnose+spectrum", store=store, manifest=fleet_dir / "machines.csv")
    batch(task="ringdown+compare", store=store, manifest=fleet_dir / "structures.csv")
    say("writing report.html")
    path = report([files["ringdown"], files["hammer"], files["machine"]], out / "report.html", store=store,
                  title="vibmeasure demo report", rpm=None, bearing="6205-2RS",
                  summary=["a ring-down of a beam (maximum-likelihood fn and zeta with their std)",
                           "a hammer test on a 3-mode structure (FRFs, stabilisation, modes)",
                           "a pump with an outer-race bearing defect (envelope analysis, ISO severity)",
                           "a fleet of 4 assets over 20 weeks (trends, limits, verdicts)"])
    return {"report": path, "store": store, "seconds": time.perf_counter() - t0,
            "size_bytes": path.stat().st_size}
