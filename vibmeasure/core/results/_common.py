"""What every result shares: the sentence for each quality flag, and the one conversion to JSON."""

from __future__ import annotations

import math
from typing import Mapping

import numpy as np

from ..errors import ParameterError

# Every quality flag a result may carry, with the sentence a report prints for it.
FLAG_TEXT = {
    "few_cycles": "fewer than 5 cycles of decay above the noise: damping is poorly determined",
    "noise_floor": "the decay reached the noise floor before the record ended; the fit stops there",
    "resolution_limited": "sampling or frequency resolution too coarse for a sound estimate",
    "clipped": "clipped samples (3 or more in a row at the extreme) were excluded",
    "close_modes": "another mode lies within a few half-power bandwidths: estimates interact",
    "unresolved_close_modes": "a resonance holds two or more modes closer than the frequency resolution separates; "
                              "they are left out: see extras['unresolved_close_modes_hz']",
    "methods_disagree": "two identification methods run on the same data give this mode's fn or zeta further apart "
                        "than three of their combined stds: at least one is biased",
    "not_confirmed": "the other identification method run on the same data does not find this mode",
    "several_modes": "the analysed band holds more than one decaying mode: the decrement mixes them",
    "overdamped": "no oscillation: the system is critically or over damped (zeta >= 1); no frequency",
    "coulomb_friction": "the envelope decays linearly, as with dry (Coulomb) friction: viscous zeta does "
                        "not describe it; see friction decay per cycle",
    "amplitude_dependent": "damping changes with amplitude (nonlinear damping); zeta is an average",
    "amplitude_dependent_frequency": "the natural frequency changes with amplitude (nonlinear stiffness); fn is "
                                     "an average: see extras['backbone'] and extras['backbone_model']",
    "colored_noise": "the noise near this mode is stronger than the broadband level: std scaled up",
    "low_snr": "the mode is weak compared with the noise",
    "start_detected": "the decay starts after the beginning of the record (trigger/impact found)",
    "one_cycle": "only one whole cycle: no spread between cycles, so no std",
    "amplitude_varies": "the amplitude changes by more than 5 % from cycle to cycle: not a steady state, the "
                        "loop's area mixes amplitudes",
    "not_harmonic": "the motion is not one sinusoid (harmonics above 5 %): the equivalent viscous c assumes "
                    "harmonic motion and holds only as an energy equivalent",
    # machine diagnosis
    "gear_not_impulsive": "the gear's wide sidebands stand, but its synchronous residual is not impulsive as a "
                          "local tooth fault makes it (FM4 under 4, no higher than random tooth errors of the same "
                          "sideband spectrum give, or no average possible): the gear call is held or dropped",
    "unit_doubtful": "a channel declared velocity or displacement carries most of its power above 1 kHz, as an "
                     "acceleration does: the unit conversion, the levels and the ISO zone are in doubt",
    "bearing_not_checked": "no bearing given: bearing faults were not searched",
    "band_limited": "a channel measures only up to a filter's edge, too low to demodulate above the shaft "
                    "harmonics: the bearing evidence is weak",
    "speed_varies": "the 1X line moves over the record and the speed was not measured: where the 1X follows "
                    "a curve the speed is estimated from it and the record analysed in orders; else the lines "
                    "smear and no shaft-order fault is called",
    "order_tracked": "the speed varies: the record was resampled at equal steps of shaft angle and analysed in "
                     "orders",
    "spikes_removed": "isolated spikes (single samples, or two, far from their neighbours, which no accelerometer "
                      "behind an anti-alias filter makes) were replaced by their AR interpolation",
    "dropouts": "runs of equal samples (a converter or link that held or zeroed its output): the vibration "
                "there is lost; they were filled by AR interpolation for the envelope analysis",
    "saturated": "runs of samples sit at the record's extremes: the sensor or converter saturated, the level "
                 "reads low and the clipping adds harmonics",
    "speed_corrected": "the 1X line (or a gear mesh over its teeth) stands more than 1 % from the declared speed: "
                       "the measured speed is used",
    "speed_unchecked": "no 1X line, mesh or tachometer checked the declared speed: it is used as declared",
    "speed_inconsistent": "the lines fit the declared speed only at another sampling rate (or a tachometer disagrees "
                          "with the declared speed): the time base is in doubt, the ISO zone withdrawn",
    "speed_contradicted": "a shaft comb or the bearing's own lines stand where another speed puts them: no "
                          "shaft-order or bearing fault was looked for at the declared speed",
    "speed_unconfirmed": "no 1X line confirms the declared speed, and the record shows lines of another (a shaft "
                         "comb at a multiple, or a 2X without its 1X): the answer is held",
    "speed_doubtful": "the record's lines (a gear mesh, a line at half the speed, a rival bearing comb) put the "
                      "shaft at another speed, often 2 or 4 x off: the answer is held",
    "speed_disagrees_file": "the declared speed differs from the one the file states and no line settles which is "
                            "right: the answer is held",
    "half_order_ambiguous": "lines at 0.5X and 1.5X stand about as high as the 1X: a loose machine's "
                            "sub-harmonics, or a speed (or sampling rate) off by a factor 2",
    "gear_not_seen": "no mesh line stands at the declared teeth x the speed used: the gear was not checked",
    "gear_elsewhere": "a gear pair's mesh stands whose shafts are not the one measured (another stage): its "
                      "lines were not set apart",
    "band_unconfirmed": "a fault or candidate only the band given shows, against the record's own bands: the "
                        "band may miss the bearing's resonance",
    "ball_slip_edge": "the smeared ball comb fits best at the edge of the slip searched: it would fit better "
                      "outside the range the model allows; the call is held",
    "bearing_call_unstable": "the bearing family called is not called on the record cut 1-2 % short: its comb rests "
                             "on where the record ends, not on the bearing; no bearing fault is named",
    "channels_restricted": "only the channels named were searched for bearing faults",
    "unit_converted": "a channel in velocity or displacement units was differentiated to acceleration",
    "unit_unknown": "a channel's unit is unknown: no ISO level, and shaft-order faults are not called",
}


def _arr(x, n, name, fill=np.nan):
    if x is None:
        return np.full(n, fill)
    a = np.atleast_1d(np.asarray(x, dtype=float))
    if a.shape != (n,):
        raise ParameterError(f"{name} must have one value per mode ({n}), got shape {a.shape}")
    return a


def _num(x):
    x = float(x)
    return None if not np.isfinite(x) else x


_PLAIN = (str, int, bool, type(None))


# flags that describe how a fit was made, not a doubt about its answer: neither shown nor warned about
INFORMATIONAL_FLAGS = frozenset({"noise_floor"})


def shown_flags(flags, mode_flags=None) -> list:
    """The flags a picture, a table and a report show for one result: the record's then each mode's,
    once each, in order, without the informational ones (one list, so a plot and its table agree)."""
    out = []
    for f in [*flags, *(f for m in (mode_flags or ()) for f in m)]:
        if f not in out and f not in INFORMATIONAL_FLAGS:
            out.append(f)
    return out


def jsonable(obj):
    """obj with numpy scalars and arrays, tuples, NaN and inf turned into what ``json.dumps`` writes
    (lists, floats, None): the one conversion every ``to_dict`` and the CLI's ``--json`` use."""
    t = type(obj)
    if t in _PLAIN:   # the common leaves first: no abstract-class checks (a batch converts ~10^5 values)
        return obj
    if t is float:
        return obj if math.isfinite(obj) else None
    if t is dict:
        return {str(k): jsonable(v) for k, v in obj.items()}
    if t is list or t is tuple:
        return [jsonable(v) for v in obj]
    if hasattr(obj, "to_dict") and hasattr(obj, "columns"):  # a pandas DataFrame: its rows
        return [jsonable(r) for r in obj.to_dict(orient="records")]
    if isinstance(obj, Mapping):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return [jsonable(v) for v in obj.tolist()]
    if isinstance(obj, (float, np.floating)):
        return _num(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (np.bool_,)):
        return bool(obj)
    return obj
