"""One report section per kind of result (ring-down, FRF and modes, diagnosis, comparison, fleet,
error), each a dict of tables, inline SVG figures and flags with advice, for the template."""

from __future__ import annotations

import io as _io

import numpy as np

from ..core.results import FLAG_TEXT
from ..core.results._common import shown_flags
from ..core.labels import label
from ..core.rounding import band, plain, with_std

FLAG_ADVICE = {
    "few_cycles": "record a longer decay, or excite harder so more cycles stand above the noise",
    "noise_floor": "nothing to do: the fit used the part of the record that carries the decay",
    "resolution_limited": "record longer (finer lines) or sample faster, or use the time-domain fit (vm.ringdown)",
    "clipped": "lower the sensor gain or the excitation: clipped samples carry no information",
    "close_modes": "treat fn and zeta of these modes with care; more outputs or a longer record separate them",
    "several_modes": "give band= around one mode, or use vm.ringdown, which fits every mode at once",
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
    "unit_doubtful": "check the channel's unit and quantity (an accelerometer's g or m/s^2 declared as mm/s?) and "
                     "analyse again",
    "gear_not_impulsive": "the gear's sidebands are those of random tooth errors, run-out or eccentricity, not of "
                          "a local tooth fault: trend NA4 (vm.trend) to see a gear wear; record with a tachometer "
                          "(tach=) so the synchronous average is sharp",
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
    "speed_corrected": "check the declared speed (a nameplate's is the synchronous one), or give tach=",
    "speed_unchecked": "give tach= (or --tach), or check that the sensor sees the shaft the speed is declared for",
    "speed_inconsistent": "check the sampling rate and the speed's unit (rpm for Hz, pulses per revolution)",
    "speed_contradicted": "give the measured speed (rpm=, tach= or rpm_profile=) and run again",
    "speed_unconfirmed": "check the speed and fs (rpm for Hz, pulses per revolution, the sampling rate), or give tach=",
    "speed_doubtful": "check the speed and fs (a factor 2 or 4: rpm for Hz, pulses per revolution, the sampling "
                      "rate), or give tach=; declare gear= for a gearbox",
    "speed_disagrees_file": "check which speed is right and give it (rpm=, or tach=)",
    "half_order_ambiguous": "check the speed and fs; look for looseness (rub, a loose foot) on site",
    "gear_not_seen": "check the speed, the tooth count and that the sensor sees the gear",
    "gear_elsewhere": "declare gear= (with mating_shaft_ratio=) for the stage the sensor is on",
    "band_unconfirmed": "analyse without band=, or give a band around the bearing's resonance",
    "ball_slip_edge": "confirm with a longer or a later record before acting on the ball call",
    "bearing_call_unstable": "measure again, longer (a minute or more) or under another load, before acting on "
                             "the candidate",
    "channels_restricted": "name every channel on the machine to have a fault another sensor sees looked for",
    "unit_converted": "nothing to do: the levels are converted; a proximity probe's displacement is judged by "
                      "ISO 20816 / 7919",
    "unit_unknown": "give unit= (e.g. 'g', 'm/s^2', 'mm/s') for the ISO level and the shaft-order faults",
}


# how each estimator's method name reads in a table caption
METHOD_TEXT = {"ml": "maximum likelihood", "fit_modes": "LSCF + maximum likelihood", "oma_ssi": "covariance SSI",
               "oma_fdd": "enhanced FDD", "halfpower": "half-power bandwidth", "circle": "circle fit",
               "baseline": "baseline"}


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
    if isinstance(v, (float, np.floating, int, np.integer)) and not isinstance(v, bool):
        return plain(v, digits)
    return str(v)


def _pm(value, std) -> list:
    """A value and its std as two cells, rounded by the one rule (core.rounding.with_std)."""
    return list(with_std(value, std))


def _flags(flags, mode_flags=None) -> list[dict]:
    """Each flag shown (``shown_flags``: the same list the result's plot shows) with its text and advice."""
    return [{"flag": f, "text": FLAG_TEXT.get(f, f), "advice": FLAG_ADVICE.get(f, "see the documentation of the flag")}
            for f in shown_flags(flags, mode_flags)]


def _mode_table(est, caption):
    rows = []
    for i in range(est.n_modes):
        rows.append([i + 1, *_pm(est.fn[i], est.fn_std[i]), *_pm(est.zeta[i], est.zeta_std[i]),
                     ", ".join(est.mode_flags[i]) if est.mode_flags else ""])
    return {"caption": caption, "header": ["mode", "fn [Hz]", "± std", "zeta [-]", "± std", "flags"], "rows": rows}


# --- sections -------------------------------------------------------------------------------------
def ringdown_section(rec, est, name):
    """A ring-down (or any time-domain damping) estimate: its modes, flags, the record with the fitted
    decay (when ``rec`` is given) and the strongest mode's backbone."""
    from .. import plot
    how = METHOD_TEXT.get(est.method, est.method)
    sec = {"kind": "ringdown", "title": f"Ring-down: {name}", "tables": [_mode_table(est, "Natural frequencies and "
                                                                                       f"damping ({how})")],
           "flags": _flags(est.flags, est.mode_flags), "figures": []}
    k = int(np.argmax(est.amplitude)) if est.amplitude is not None and est.n_modes else 0
    fn_k, zeta_k = with_std(est.fn[k], est.fn_std[k])[0], with_std(est.zeta[k], est.zeta_std[k])[0]
    sec["verdict"], sec["verdict_class"] = f"fn {fn_k} Hz, zeta {zeta_k}", "ok"
    sec["verdict_text"] = f"(strongest of {est.n_modes} mode(s); channel {est.extras.get('channel', '')})"
    if rec is not None and est.method == "ml":
        sec["figures"].append({"svg": _svg(plot.plot_ringdown(rec, est)),
                               "caption": "record, fitted decay and envelope; residual below"})
    bb = est.extras.get("backbone")
    if bb is not None and len(bb) and k in set(bb["mode"]):
        b = bb[bb["mode"] == k]
        b = b.iloc[np.unique(np.linspace(0, len(b) - 1, min(len(b), 12)).round().astype(int))]  # 12 rows at most
        sec["tables"].append({"caption": f"Backbone of the {est.fn[k]:.4g} Hz mode (fn and zeta versus amplitude)",
                              "header": ["amplitude", "fn [Hz]", "± std", "zeta", "± std"],
                              "rows": [[_fmt(r.amplitude, 4), *_pm(r.fn_hz, r.fn_std_hz), *_pm(r.zeta, r.zeta_std)]
                                       for r in b.itertuples()]})
        sec["tables"].append(_backbone_model_table(est.extras.get("backbone_model", {}).get(k), est.unit))
        sec["figures"].append({"svg": _svg(plot.plot_backbone(est, mode=k)),
                               "caption": "damping and frequency versus amplitude"})
    return sec


_MODEL_ROWS = (("natural frequency at zero amplitude fn0 [Hz]", "fn0_hz", "fn0_std_hz"),
               ("cubic stiffness k3/k [1/{u}^2]", "k3_over_k", "k3_over_k_std"),
               ("viscous damping ratio zeta_v [-]", "zeta_viscous", "zeta_viscous_std"),
               ("friction term [{u}]", "friction_term", "friction_term_std"),
               ("quadratic damping term [1/{u}]", "quadratic_term", "quadratic_term_std"))


def _backbone_model_table(model, unit: str = "") -> dict:
    """The weakly nonlinear model fitted to the backbone, or, when it fails its goodness-of-fit test,
    a table that says so and why: the windows then stand alone and no model number is printed."""
    head = ["parameter", "value", "± std"]
    if not model:
        return {"caption": "No backbone model: too few windows", "header": head, "rows": []}
    if not model.get("fits", False):
        return {"caption": "No weakly nonlinear model (Duffing stiffness; viscous, friction and quadratic damping) "
                           f"describes these windows: {model.get('reason') or 'lack of fit'}. Quote the windows "
                           "above with their amplitudes, not a model parameter.", "header": head, "rows": []}
    return {"caption": "Weakly nonlinear model of the backbone (fits the windows within their std)", "header": head,
            "rows": [[what.format(u=unit or "amplitude unit"), *_pm(model[key], model[std])]
                     for what, key, std in _MODEL_ROWS]}


def modes_section(frf, est, name):
    """Modes from FRFs (fit_modes) or from the outputs alone (oma_ssi, oma_fdd): the modes, the poles
    refused, the FRF with the synthesis (when ``frf`` is given) and the stabilisation diagram."""
    from .. import plot
    how = METHOD_TEXT.get(est.method, est.method)
    sec = {"kind": "modes", "title": f"{'FRF and modes' if frf is not None else 'Modes'}: {name}",
           "tables": [_mode_table(est, f"Modes ({how})")],
           "flags": _flags(est.flags, est.mode_flags), "figures": []}
    rej = est.extras.get("rejected_modes") or []
    if rej:
        sec["tables"].append({"caption": "Poles the data does not support (not reported as modes)",
                              "header": ["fn [Hz]", "zeta", "reason"],
                              "rows": [[_fmt(d["fn_hz"], 6), _fmt(d["zeta"], 3), d["reason"]] for d in rej]})
    sec["verdict"], sec["verdict_class"] = f"{est.n_modes} mode(s)", "ok"
    sec["verdict_text"] = "in " + band(*est.extras["band_hz"]) + " Hz" if est.extras.get("band_hz") else ""
    if frf is not None:
        sec["figures"].append({"svg": _svg(plot.plot_frf(frf, est=est)),
                               "caption": "FRF magnitude, phase and coherence with the modal synthesis"})
    if est.method == "oma_fdd":
        sec["figures"].append({"svg": _svg(plot.plot_singular_values(est)),
                               "caption": "singular values of the outputs' spectral matrix"})
    elif est.method in ("fit_modes", "oma_ssi"):
        sec["figures"].append({"svg": _svg(plot.plot_stabilisation(est, frf=frf)), "caption": "stabilisation diagram"})
    return sec


def diagnosis_section(rec, diag, name):
    from .. import plot
    sev = diag.severity or {}
    # a "none" that is probably wrong (an unexplained candidate, a weak fault it could not name) is
    # worth a look, not a green light
    if diag.top in ("none", "undetermined"):
        cls = "ok" if diag.top == "none" and diag.confidence >= 0.5 else "watch"
    else:
        cls = "alarm" if diag.confidence >= 0.9 else "watch"
    sec = {"kind": "diagnosis", "title": f"Machine diagnosis: {name}", "tables": [], "figures": [],
           "flags": _flags([f for f in diag.flags if f in FLAG_ADVICE]),
           "verdict": label(diag.top), "verdict_class": cls,
           "verdict_text": f"(confidence {diag.confidence:.2f}) {diag.reason}"}
    rows = []
    for r in diag.faults.to_dict(orient="records"):
        rows.append([label(r.get("fault")), _fmt(r.get("expected_hz"), 5), _fmt(r.get("found_hz"), 5),
                     _fmt(r.get("evidence_db"), 3), _fmt(r.get("confidence"), 2), _fmt(r.get("log10_p"), 3),
                     r.get("note") or ""])
    sec["tables"].append({"caption": "Evidence per fault family", "header": ["fault", "expected [Hz]", "found [Hz]",
                                                                            "evidence [dB]", "score",
                                                                            "log10 p", "note"], "rows": rows})
    sec["tables"].append({"caption": "ISO 10816-3 severity", "header": ["velocity RMS [mm/s]", "band [Hz]", "group",
                                                                       "foundation", "zone"],
                          "rows": [[_fmt(sev.get("velocity_rms_mm_s"), 3),
                                    band(*sev["band_hz"]) if sev.get("band_hz") else "",
                                    sev.get("group"), sev.get("foundation"), sev.get("zone")]]})
    if rec is not None:
        sec["figures"].append({"svg": _svg(plot.plot_diagnosis(rec, diag)),
                               "caption": "spectrum, envelope spectrum with the fault comb, kurtogram, severity"})
    return sec


def comparison_section(cmp, name):
    from .. import plot
    sec = {"kind": "compare", "title": f"Comparison: {name}", "figures": [], "flags": [],
           "verdict": cmp.verdict, "verdict_class": cmp.verdict, "verdict_text": cmp.reason,
           "tables": [{"caption": "Measured versus predicted", "header": ["fn measured [Hz]", "fn predicted [Hz]",
                                                                         "deviation [%]", "in std", "verdict"],
                       "rows": [[_fmt(r["fn_measured_hz"], 6), _fmt(r["fn_predicted_hz"], 6),
                                 _fmt(r["fn_dev_pct"], 3), _fmt(r["fn_dev_std"], 3), r["verdict"]] for r in cmp.rows]}]}
    sec["figures"].append({"svg": _svg(plot.plot_comparison(cmp)),
                           "caption": "frequency deviation per mode and the tolerance"})
    return sec


def fleet_section(store, name):
    from .. import plot
    from ..monitor.trend import trend
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
                          "rows": [[r.asset, r.point, label(r.metric), with_std(r.baseline_mean, r.baseline_std)[0]
                                    if np.isfinite(r.baseline_std) else _fmt(r.baseline_mean, 4), _fmt(r.last, 4),
                                    _fmt(r.alarm_limit, 4), r.verdict, r.reason] for r in tr.itertuples()]})
    # the trended metrics (a baseline to draw against) that are not ok
    for r in tr[(tr["verdict"] != "ok") & tr["baseline_mean"].notna()].head(4).itertuples():
        fig = plot.plot_trend(store, asset=r.asset, point=r.point, metric=r.metric, task=r.task)
        sec["figures"].append({"svg": _svg(fig), "caption": f"{r.asset}/{r.point}: {label(r.metric)}"})
    return sec


def error_section(name, exc):
    return {"kind": "error", "title": f"Input: {name}", "error": f"{type(exc).__name__}: {str(exc)[:500]}", "tables": [],
            "figures": [], "flags": []}
