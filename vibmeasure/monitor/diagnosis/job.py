"""Step 1, prepare: the record's channels checked, repaired and converted, the machine described, all
held in one frozen ``Job`` that every later step reads."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...core import units as _units
from ...core._threads import each_in_threads
from ...core._validate import clean_signal, positive, response_channel
from ...core.errors import ParameterError
from ...models.bearing import Bearing, Gear, bearing_from
from ..bearing import WHITENING
from .iso import ISO_10816_3

MAX_RPM = 120000.0
MIN_REVOLUTIONS = 20   # revolutions a record must span for the order resolution
TYPICAL_FTF_ORDER = 0.38  # the cage turns at about this share of the shaft speed (0.35-0.44 in vm.BEARINGS)


@dataclass(frozen=True)
class Job:
    """What diagnose works on, checked: the primary channel (speed, severity, shaft orders), the
    channels searched for bearing faults, and the machine's description. Frozen: a step that changes
    it (order tracking, the supply's lines removed) makes a new one with ``dataclasses.replace``;
    ``flags`` is the record's one list of findings, which every step appends to in order."""
    fs: float
    rpm: float
    primary: str
    a: np.ndarray
    signals: dict
    bearing: Bearing | None
    gear: Gear | None
    group: int
    foundation: str
    band: tuple | None
    flags: list
    prewhitening: tuple = ("cepstral",)
    mains: tuple = (50.0, 60.0)  # the line frequencies whose lines are electrical (``_at_mains``)
    quality: dict = field(default_factory=dict)   # channel -> damage found in its samples (``_damage``)
    converted: dict = field(default_factory=dict)  # channel -> the velocity or displacement unit it was read in
    file_rpm: float | None = None   # the speed the file states, when a declared rpm overrides it
    at_other_speeds: list = field(default_factory=list)  # {rpm, why, where, found: {family: p}} per speed tried
    cut_retest: dict = field(default_factory=dict)   # the bearing call's test on the record cut short (``stability``)
    unit_share: float | None = None  # a velocity/displacement label's high-band share (``_unit_plausibility``)
    found_gear: tuple | None = None  # (Gear, its shaft's Hz): a pair the spectrum shows, none declared (``gearbox``)


# --- prepare ---------------------------------------------------------------------------------------

def _accel(rec, i, flags, quality, block):
    """Channel i as float64, in m/s^2 when its unit is known (``_in_acceleration``), with its isolated
    spikes repaired (``signal.quality``); ``quality`` (channel -> findings) collects what the samples
    show of the recording chain's damage: spikes, dropouts, saturation, transients (judged on blocks of
    ``block`` samples: (as recorded, whitened), ``_damage``)."""
    x = clean_signal(rec, i, min_samples=256)
    ch = rec.channels[i]
    # a velocity or displacement is differentiated first: the damage rules judge an acceleration
    x = _damage(_in_acceleration(x, rec.fs, ch, flags), rec.fs, ch.name, flags, quality, block)
    if not np.ptp(x) > 0:
        raise ParameterError(f"channel {ch.name!r} is constant once the recording chain's damage is repaired "
                             f"({_quality_note({ch.name: quality[ch.name]})}): there is no vibration to analyse")
    from ...core._validate import check_range
    check_range(x, what=f"channel {ch.name!r}")
    return x


def _accel_alone(rec, i, block) -> tuple:
    """(samples, flags, findings) of channel i as ``_accel`` gives them, with flags and findings of its own."""
    flags: list = []
    quality: dict = {}
    return _accel(rec, i, flags, quality, block), flags, quality


def _take(prepared: tuple, flags: list, quality: dict) -> None:
    """One channel's flags (each once) and findings added to the record's."""
    _, own_flags, own_quality = prepared
    for f in own_flags:
        if f not in flags:
            flags.append(f)
    quality.update(own_quality)


DIFFERENTIATIONS = {"acceleration": 0, "velocity": 1, "displacement": 2}


def _in_acceleration(x, fs, ch, flags):
    """The samples in m/s^2: an acceleration converted, a velocity or a displacement differentiated once
    or twice (``signal.preprocess.derivative``, the record continued past its ends) so that the
    envelope and the ISO velocity both see what the sensor measured (flag ``unit_converted``). Every
    other unit (volts, none) is analysed as it stands, with the flag ``unit_unknown``: the lines'
    frequencies stand, their levels do not."""
    k = DIFFERENTIATIONS.get(ch.quantity) if ch.unit else None
    if k is None:
        if "unit_unknown" not in flags:
            flags.append("unit_unknown")
        return x
    x = _units.convert(x, ch.unit, _units.SI_UNIT[ch.quantity])
    if k:
        from ...signal.preprocess import derivative
        x = derivative(x, fs, k)
        if "unit_converted" not in flags:
            flags.append("unit_converted")
    return x


def _damage(x, fs, name, flags, quality, block):
    """The channel with its isolated spikes and its dropouts filled in (``quality.fill``: a spike is no
    vibration, a spike train makes a comb in the envelope spectrum, and runs of zeros gate the
    envelope), and its transients gated out (``quality.transients``, ``quality.gate``: a burst or a
    sensor's settling is no steady running, and it buries the envelope spectrum), first those the RMS
    rule finds in windows of ``block[0]`` samples, then those the whitened signal shows in windows of
    ``block[1]``, then single impacts (``quality.isolated_events``) in windows of an eighth of
    ``block[0]``; all are reported.
    Saturation is only reported: filling the clipped samples made one more wrong call on the robustness
    variants (CWRU B021_3 clipped at 3 x the RMS)."""
    from ...signal import quality as q
    found = {}
    idx = q.isolated_spikes(x)
    if idx.size:
        x = q.fill(x, idx)
        found["spikes_removed"] = int(idx.size)
        grid = q.spike_grid(idx)
        if grid is not None:   # a spike every P samples: the repairs' own errors make a comb at fs / P
            found["spike_interval_samples"] = grid[1]
    runs = q.flat_runs(x, fs)
    if runs:
        x = q.fill(x, np.concatenate([np.arange(s, e) for s, e in runs]))
        found["dropouts"] = len(runs)
        found["dropout_seconds"] = float(sum(e - s for s, e in runs) / fs)
    runs = q.transients(x, block[0])
    if runs:
        x = q.gate(x, runs, max(1, block[0] // 8))
    # the whitened signal both rules below judge (while x stands), where the first judges it at all
    xw = q.whitened(x) if x.size >= 8 * block[1] and np.ptp(x) > 0 else None
    hidden = q.transients(x, block[1], whiten=True, whitened_x=xw)   # once the loud ones are out (TRANSIENT_LEVEL)
    if hidden:
        x = q.gate(x, hidden, max(1, block[0] // 8))
        runs = _merged(runs + hidden)
        xw = None
    # a single impact (a knock) rings for milliseconds: judged in quarter-turn windows (quality.EVENT_LEVEL)
    knocks = q.isolated_events(x, max(16, block[0] // 8), whitened_x=xw)
    if knocks:
        x = q.gate(x, knocks, max(1, block[0] // 64))
        runs = _merged(runs + knocks)
    if runs:
        found["transients"] = len(runs)
        found["transient_seconds"] = float(sum(e - s for s, e in runs) / fs)
        found["transient_share"] = float(sum(e - s for s, e in runs) / x.size)
    share = q.clipped_share(x)
    if share > 0:
        found["saturated_share"] = share
    if found:
        quality[name] = found
        for flag, key in (("spikes_removed", "spikes_removed"), ("dropouts", "dropouts"),
                          ("transients_gated", "transients"), ("saturated", "saturated_share")):
            if key in found and flag not in flags:
                flags.append(flag)
    return x


def _merged(runs) -> list:
    """(start, stop) runs with the ones that overlap or touch joined, in order."""
    out: list = []
    for s, e in sorted(runs):
        if out and s <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], e))
        else:
            out.append((s, e))
    return out


def _quality_note(quality: dict) -> str:
    """One sentence per channel on the damage found in its samples, for the reason and the warning."""
    out = []
    for name, f in quality.items():
        parts = []
        if "spikes_removed" in f:
            n = f["spikes_removed"]
            parts.append(f"{n} isolated spike{'s' * (n > 1)} (single samples, or pairs, far from their neighbours) filled in"
                         + (f", one every {f['spike_interval_samples']} samples (its comb in the envelope "
                            "spectrum is not taken for a bearing's)" if "spike_interval_samples" in f else ""))
        if "dropouts" in f:
            parts.append(f"{f['dropouts']} dropout{'s' * (f['dropouts'] > 1)} (runs of equal samples, "
                         f"{f['dropout_seconds']:.3g} s in all, filled in)")
        if "transients" in f:
            parts.append(f"{f['transients']} transient{'s' * (f['transients'] > 1)} (a burst far above the "
                         f"record's level, a single impact, or a settling or step of its mean; "
                         f"{f['transient_seconds']:.3g} s in "
                         "all, gated out)")
        if "saturated_share" in f:
            parts.append(f"saturated: {100 * f['saturated_share']:.2g} % of the samples sit at its extremes")
        out.append(f"channel {name!r}: " + ", ".join(parts))
    return "; ".join(out)


def _prepare(rec, rpm, bearing, gear, machine_group, foundation, channel, channels, band, prewhitening,
             line_frequency, skip=()) -> Job:
    """``skip``: channels that are no vibration (a tachometer), left out unless named."""
    named = None
    if channels is not None:
        # the channels a user names are the only ones searched; the first of them is the primary
        # (speed, severity, shaft orders) unless ``channel`` names another
        named = [rec.index(c) for c in ([channels] if isinstance(channels, (str, int)) else channels)]
        if not named:
            raise ParameterError("channels=[] names no channel: give at least one, or leave it out for all")
        if channel is None:
            channel = named[0]
    if channel is None and skip:
        left = [i for i, c in enumerate(rec.channels) if i not in skip and c.quantity != "force"]
        if not left:
            raise ParameterError(f"the record's only channels {rec.names} are the tachometer or forces: "
                                 "it needs a vibration channel")
        channel = left[0]
    idx = response_channel(rec, channel)
    file_rpm = _file_rpm(rec) if rpm is not None else None
    if rpm is None:
        rpm = rec.meta.get("rpm")
        if rpm is None:
            raise ParameterError("rpm is required (the declared shaft speed), e.g. diagnose(rec, rpm=1797)")
    rpm = positive(rpm, "rpm")
    if rpm > MAX_RPM:
        raise ParameterError(f"rpm={rpm:g} exceeds {MAX_RPM:g} rpm: no rotating machine this tool covers runs that fast")
    f1 = rpm / 60.0
    T = rec.n_samples / rec.fs
    if T * f1 < MIN_REVOLUTIONS:
        raise ParameterError(f"the record spans {T * f1:.1f} shaft revolutions ({T:.3g} s at {rpm:g} rpm); at least "
                             f"{MIN_REVOLUTIONS} are needed for the order resolution (record {MIN_REVOLUTIONS / f1:.3g} s "
                             "or more)")
    group = 2 if machine_group is None else machine_group
    found = "rigid" if foundation is None else foundation
    if (group, found) not in ISO_10816_3:
        raise ParameterError(f"machine_group={machine_group!r}, foundation={foundation!r}: group 1 or 2, "
                             "foundation 'rigid' or 'flexible'")
    bearing = bearing_from(bearing)
    if gear is not None and not isinstance(gear, Gear):
        gear = Gear(gear)
    _check_nyquist(rec.fs, f1, bearing, gear)
    flags: list = []
    quality: dict = {}
    # transients are judged on blocks of two revolutions, and in the whitened signal on blocks of two
    # turns of the cage (quality.TRANSIENT_LEVEL: a ball defect passes the load zone once a turn)
    ftf = bearing.frequencies(f1)["FTF"] if bearing is not None else TYPICAL_FTF_ORDER * f1
    block = (max(64, int(round(2 * rec.fs / f1))), max(64, int(round(2 * rec.fs / ftf))))
    if named is None:
        chosen = [i for i, c in enumerate(rec.channels) if c.quantity not in ("force", "time") and i not in skip]
        if idx not in chosen:
            chosen.insert(0, idx)
    else:
        chosen = list(dict.fromkeys(named))
    # each channel prepared apart (in threads), its flags and findings taken in the serial order: the
    # primary's first, then the others'
    order = [idx] + [i for i in chosen if i != idx]
    prepared = dict(zip(order, each_in_threads(lambda i: _accel_alone(rec, i, block), order)))
    _take(prepared[idx], flags, quality)
    if named is not None:
        vibration = [i for i, c in enumerate(rec.channels) if c.quantity not in ("force", "time") and i not in skip]
        if set(vibration) - set(chosen):   # a channel left out may be the one that sees the fault
            flags.append("channels_restricted")
    for i in order[1:]:
        _take(prepared[i], flags, quality)
    signals = {rec.channels[i].name: prepared[i][0] for i in chosen}
    if band is not None:
        from ...core._validate import check_band
        band = check_band(band, rec.fs)
    whitening = _check_prewhitening(prewhitening)
    mains = (50.0, 60.0) if line_frequency is None else (_check_line_frequency(line_frequency, rec.fs),)
    converted = {rec.channels[i].name: rec.channels[i].unit for i in chosen
                 if rec.channels[i].unit and DIFFERENTIATIONS.get(rec.channels[i].quantity, 0)}
    unit_share = _unit_plausibility(rec, converted, flags)
    return Job(rec.fs, rpm, rec.channels[idx].name, prepared[idx][0], signals, bearing, gear, group, found, band, flags,
               prewhitening=whitening, mains=mains, quality=quality, converted=converted, file_rpm=file_rpm,
               unit_share=unit_share)


UNIT_DOUBT_SHARE = 0.75   # power above 1 kHz over power in 10-1000 Hz that no velocity channel reaches


def _unit_plausibility(rec, converted: dict, flags: list) -> float | None:
    """Whether channels declared velocity or displacement hold what such sensors measure. A velocity
    (a velocity pickup, or an integrated acceleration) carries its power in the ISO band, 10-1000 Hz;
    an acceleration labelled mm/s carries most of it above 1 kHz (bearing resonances). The share
    power(1 kHz - 0.45 fs) / power(10-1000 Hz) of the record's least high-frequency converted channel:
    on the 53 development records integrated to velocity it is 0.45 at most, on their raw
    accelerations 1.06 at least (a displacement's, 0.02 at most). From UNIT_DOUBT_SHARE on, the flag
    ``unit_doubtful`` (the ``doubts.unit_label`` step holds the answer). None when nothing was
    converted or the record does not reach 1.2 kHz."""
    if not converted or rec.fs < 2.4e3 * 1.1:
        return None
    from scipy.signal import welch
    shares = []
    for name in converted:
        x = np.asarray(rec.channel(name), float)
        f, p = welch(x - x.mean(), fs=rec.fs, nperseg=min(8192, x.size))
        lo = float(p[(f >= 10) & (f <= 1000)].sum())
        shares.append(float(p[(f > 1000) & (f <= 0.45 * rec.fs)].sum()) / max(lo, 1e-300))
    share = min(shares)
    if share >= UNIT_DOUBT_SHARE and "unit_doubtful" not in flags:
        flags.append("unit_doubtful")
    return share


def _file_rpm(rec) -> float | None:
    """The shaft speed the file itself states (``meta["rpm"]``: CWRU's RPM, MFPT's bearing.rate), when it
    is a positive number; None otherwise."""
    v = rec.meta.get("rpm")
    try:
        v = float(v)
    except (TypeError, ValueError):
        return None
    return v if np.isfinite(v) and v > 0 else None


def _check_prewhitening(value) -> tuple:
    items = (value,) if isinstance(value, str) else tuple(value) if isinstance(value, (list, tuple)) else None
    if not items or any(v not in WHITENING for v in items):
        raise ParameterError(f"prewhitening={value!r} must name one or more of {WHITENING}")
    return items


def _check_line_frequency(value, fs: float) -> float:
    """The supply frequency in Hz; twice it must lie below Nyquist for the electrical check."""
    if isinstance(value, (bool, str)):
        raise ParameterError(f"line_frequency={value!r} must be the supply's frequency in Hz, a number "
                             "(50 or 60 on public grids)")
    lf = positive(value, "line_frequency")
    if 2 * lf >= fs / 2:
        raise ParameterError(f"line_frequency={lf:g} Hz: twice it ({2 * lf:g} Hz) must lie below the Nyquist "
                             f"frequency ({fs / 2:g} Hz) for the electrical check")
    return lf


def _check_nyquist(fs, f1, bearing, gear):
    if bearing is not None:
        for name, f in bearing.frequencies(f1).items():
            if name != "FTF" and 3 * f >= fs / 2:
                raise ParameterError(f"fs={fs:g} Hz is too low for the bearing lines: the third harmonic of {name} "
                                     f"({3 * f:.1f} Hz) lies above the Nyquist frequency {fs / 2:g} Hz")
    if gear is not None and (gear.teeth + 2) * f1 >= fs / 2:
        raise ParameterError(f"fs={fs:g} Hz is too low for the gear mesh ({gear.teeth * f1:.1f} Hz) and its sidebands")
