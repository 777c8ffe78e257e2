"""Accelerometer records of rotating machines, healthy or with one fault, and cage pulsing."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core._validate import check_memory, positive
from ..core.errors import ParameterError
from ..core.record import Channel, Record

_FAULTS = ("none", "unbalance", "misalignment", "looseness", "bearing_outer_race", "bearing_inner_race",
           "bearing_ball", "gear_mesh", "resonance")


def _impact_train(n, fs, times, resonance_hz, amp=None):
    """Unit-RMS response of a resonance (zeta 0.05) to impacts at the given times, each placed at its
    exact time by a band-limited fractional delay (a Kaiser-windowed sinc of 64 taps), as an
    anti-aliased measurement would see it. Rounded to samples, a train with 400.67 samples per period
    (a shaft's at 1797 rpm and 12 kHz) repeats its rounding every third impact, and its envelope has
    lines at thirds of the shaft rate that no machine makes (a healthy machine with a rub then reads as
    an inner race)."""
    wr = 2 * np.pi * resonance_hz
    tau = 1 / (0.05 * wr)
    t = np.asarray(times, dtype=float) * fs
    w = np.ones(t.size) if amp is None else np.asarray(amp, dtype=float)
    i0 = np.floor(t).astype(int)
    m = np.arange(-_HALF_TAPS + 1, _HALF_TAPS + 1)
    x = m[None, :] - (t - i0)[:, None]               # distance of each tap from the impact, in samples
    taps = np.sinc(x) * np.i0(_KAISER_BETA * np.sqrt(np.clip(1 - (x / _HALF_TAPS) ** 2, 0, 1))) / np.i0(_KAISER_BETA)
    idx = i0[:, None] + m[None, :]
    ok = (idx >= 0) & (idx < n)
    imp = np.zeros(n)
    np.add.at(imp, idx[ok], (w[:, None] * taps)[ok])
    tt = np.arange(int(8 * tau * fs)) / fs
    out = np.convolve(imp, np.exp(-tt / tau) * np.sin(wr * tt))[:n]
    return out / max(np.std(out), 1e-300)


_HALF_TAPS = 32      # fractional-delay kernel: 64 taps
_KAISER_BETA = 12.0  # its window: the delay is exact to 1e-3 up to 0.45 fs, like an anti-alias filter


def machine(*, fault: str = "none", rpm=1797.0, fs: float = 12000.0, duration: float = 10.0,
            severity: float = 1.0, snr_db: float = 20.0, bearing=None, gear_teeth: int = 32,
            resonance_hz: float = 3500.0, cage_modulation: float = 0.0, shaft_impacts: float = 0.0,
            mesh: float = 0.0, tooth_error: float = 0.0, mating_teeth: int = 0, seed=None, unit: str = "g", tach: int = 0) -> Record:
    """Accelerometer record of a rotating machine, healthy or with one fault, for tests and demos.

    Every machine has a small residual 1X and broadband noise. Faults: unbalance (strong 1X),
    misalignment (2X beside 1X), looseness (harmonics and 0.5X sub-harmonics), bearing defects
    (impacts at BPFO/BPFI/2 x BSF with 1 % slip jitter ringing a resonance; inner race and ball faults
    modulated at 1X and FTF), gear mesh (a local tooth fault: the mesh of ``gear_teeth`` x 1X modulated by a
    short pulse once a turn, sidebands at +-1X, 2X, 3X ...), resonance (a mode 6 % above 1X). Any machine
    may carry a healthy mesh (``mesh``): its line and harmonics with modest +-1X sidebands.
    ``meta`` holds rpm and the truth.

    Parameters
    ----------
    fault : str
        "none", "unbalance", "misalignment", "looseness", "bearing_outer_race", "bearing_inner_race",
        "bearing_ball", "gear_mesh" or "resonance".
    rpm : float or tuple of float
        Shaft speed, or (start, end) for a linear run-up (events follow the shaft angle).
    fs : float
        Sampling rate in Hz.
    duration : float
        Length in s.
    severity : float
        Scales the fault.
    snr_db : float
        The fault's power over the noise.
    bearing : str or Bearing, optional
        The bearing (default 6205-2RS).
    gear_teeth : int
        Teeth of the gear (gear_mesh).
    resonance_hz : float
        The structural resonance the impacts ring.
    cage_modulation : float
        0..1: the noise modulated at the cage rate (a stress case: no fault).
    shaft_impacts : float
        One impact per revolution (a rub), relative to the fault's RMS.
    mesh : float
        Amplitude (g) of a healthy gear mesh of ``gear_teeth`` x 1X: harmonics at 1/3 and 1/6 of it,
        +-1X sidebands at 8 % (eccentricity, runout), a 1 % wander of its amplitude.
    tooth_error : float
        RMS of the gears' random tooth-to-tooth errors (pitch, profile, stiffness), relative, in the healthy
        mesh and in a gear_mesh fault's: each tooth modulates the mesh's amplitude by its error and its
        phase by twice it, as every real gear's teeth do (AGMA and ISO 1328 accuracy grades bound them).
        0 (default): identical teeth.
    mating_teeth : int
        Teeth of the mating gear (0: none): its shaft turns at gear_teeth / mating_teeth of this one's; its
        run-out (+-1 x its speed at 5 %) and tooth errors modulate the mesh too.
    seed : int, optional
        Random seed.
    unit : str
        The acceleration's unit.
    tach : int
        Add a channel "tach" with this many pulses per revolution (0: none).

    Returns
    -------
    Record

    Raises
    ------
    ParameterError
        For an unknown fault or values out of range.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> rec = vm.synth.machine(fault="bearing_outer_race", rpm=1797, duration=2.0, seed=1)
    >>> rec.meta["rpm"], rec.names
    (1797.0, ['acc'])
    """
    from ..models.bearing import BEARINGS, Bearing
    if fault not in _FAULTS:
        raise ParameterError(f"fault={fault!r} must be one of {_FAULTS}")
    fs, duration = positive(fs, "fs"), positive(duration, "duration")
    shaft = _shaft(rpm, fs, duration)
    if isinstance(tach, bool) or not isinstance(tach, (int, np.integer)) or tach < 0:
        raise ParameterError(f"tach={tach!r} must be a whole number of pulses per revolution (0: no tachometer)")
    rng = np.random.default_rng(seed)
    b = bearing if isinstance(bearing, Bearing) else BEARINGS["6205-2RS"] if bearing is None else BEARINGS[bearing]
    base = _residual_unbalance(shaft, rng)
    if isinstance(tooth_error, bool) or not isinstance(tooth_error, (int, float, np.number)) \
            or not (np.isfinite(tooth_error) and 0 <= tooth_error <= 0.5):
        raise ParameterError(f"tooth_error={tooth_error!r} must be a relative RMS error in [0, 0.5]")
    if isinstance(mating_teeth, bool) or not isinstance(mating_teeth, (int, np.integer)) or mating_teeth < 0 \
            or 0 < mating_teeth < 5:
        raise ParameterError(f"mating_teeth={mating_teeth!r} must be a whole number of teeth >= 5 (0: no mating gear)")
    gear = (gear_teeth, tooth_error, int(mating_teeth))
    sig = severity * _fault_signal(fault, shaft, rng, b, gear, resonance_hz)
    p_sig = np.mean(sig ** 2) if fault != "none" else np.mean((0.3 * np.ones(1)) ** 2) / 2
    noise = rng.normal(0, np.sqrt(p_sig / 10 ** (snr_db / 10)), shaft.n)
    noise = _cage_modulated(noise, cage_modulation, shaft, rng, b)
    sig = _with_shaft_impacts(sig, shaft_impacts, shaft, rng, p_sig, resonance_hz)
    if mesh < 0 or not np.isfinite(mesh):
        raise ParameterError(f"mesh={mesh!r} must be an amplitude in g >= 0")
    if mesh:
        sig = sig + mesh * _healthy_mesh(shaft, rng, *gear)
    return _machine_record(base + sig + noise, shaft, fault, severity, snr_db, unit, tach)


@dataclass(frozen=True)
class _Shaft:
    """The shaft's motion over the record: mean speed, and for a linear run-up its angle (revolutions)
    at every sample; at constant speed every phase is computed from f1 t."""
    fs: float
    duration: float
    n: int
    t: np.ndarray
    rpm: float
    rpm0: float
    rpm1: float
    ramp: bool
    theta: np.ndarray | None

    @property
    def f1(self) -> float:
        return self.rpm / 60.0

    def phase(self, k):
        return 2 * np.pi * k * self.theta if self.ramp else 2 * np.pi * k * self.f1 * self.t

    def at_angle(self, revs):
        """Times at which the shaft reaches the given angles (revolutions)."""
        return np.interp(revs, self.theta, self.t) if self.ramp else np.asarray(revs) / self.f1


def _shaft(rpm, fs: float, duration: float) -> _Shaft:
    ramp = isinstance(rpm, (tuple, list, np.ndarray))
    rpm0 = rpm1 = None
    if ramp:
        if len(rpm) != 2:
            raise ParameterError(f"rpm={rpm!r} must be one speed or a (start, end) pair for a linear run-up")
        rpm0, rpm1 = positive(rpm[0], "rpm[0]"), positive(rpm[1], "rpm[1]")
        rpm = (rpm0 + rpm1) / 2
    else:
        rpm = positive(rpm, "rpm")
    n = int(round(fs * duration))
    t = np.arange(n) / fs
    theta = (rpm0 * t + (rpm1 - rpm0) * t ** 2 / (2 * duration)) / 60.0 if ramp else None
    return _Shaft(fs, duration, n, t, rpm, rpm0, rpm1, ramp, theta)


def _residual_unbalance(shaft: _Shaft, rng) -> np.ndarray:
    """A healthy rotor's 1X: balanced to a quality grade (ISO 21940-11: eccentricity x angular speed
    fixed), its unbalance force and, below its first critical speed, its acceleration grow with the
    speed, so its 1X velocity is the same at every speed: 0.02 g at 1797 rpm, 0.74 mm/s RMS (a 1X
    fixed in g would read above half ISO 10816's A/B boundary at 300-1200 rpm)."""
    speed = (shaft.rpm0 + (shaft.rpm1 - shaft.rpm0) * shaft.t / shaft.duration) if shaft.ramp else shaft.rpm
    return 0.02 * (speed / 1797.0) * np.sin(shaft.phase(1) + rng.uniform(0, 2 * np.pi))


def _healthy_mesh(shaft: _Shaft, rng, teeth: int, tooth_error: float = 0.0, mating_teeth: int = 0) -> np.ndarray:
    """A healthy mesh of unit amplitude: teeth x 1X with its 2nd and 3rd harmonics, +-1X sidebands at
    8 % (a gear's eccentricity and runout), and a slow 1 % wander of its amplitude (the load). With
    ``tooth_error``, each tooth's random error (Gaussian, interpolated across the tooth) modulates the
    amplitude by itself and the phase by twice itself: sidebands at every shaft order, none impulsive.
    With ``mating_teeth``, the mating gear's run-out and tooth errors modulate it at its shaft's orders."""
    revs = shaft.theta if shaft.ramp else shaft.f1 * shaft.t
    am = 1 + 0.08 * np.cos(2 * np.pi * revs + rng.uniform(0, 2 * np.pi)) \
        + 0.01 * np.sin(2 * np.pi * 0.37 * shaft.t + rng.uniform(0, 2 * np.pi))
    pm = np.zeros_like(revs)
    gears = [(teeth, revs)]
    if mating_teeth:
        revs2 = revs * teeth / mating_teeth
        am = am + 0.05 * np.cos(2 * np.pi * revs2 + rng.uniform(0, 2 * np.pi))
        gears.append((mating_teeth, revs2))
    for z, turns in gears if tooth_error else ():
        e = rng.normal(0.0, tooth_error, z)
        x = (turns % 1.0) * z
        i = np.floor(x).astype(int) % z
        err = e[i] + (e[(i + 1) % z] - e[i]) * (x - np.floor(x))
        am, pm = am + err, pm + 2 * err
    # a recorder's anti-alias filter passes about 0.45 fs: a harmonic (with its sidebands) above it is
    # not recorded, where sampled as it is it would fold onto the lower harmonics' sidebands (a 40-tooth
    # mesh at 3600 rpm and 12 kHz: its third harmonic, 7.2 kHz, on the second's, 4.8 kHz, mirrored)
    top = 0.45 * shaft.fs / (teeth * max(shaft.rpm, shaft.rpm0 or 0.0, shaft.rpm1 or 0.0) / 60.0)
    return am * sum(a * np.sin(2 * np.pi * k * teeth * revs + k * pm + rng.uniform(0, 2 * np.pi))
                    for k, a in ((1, 1.0), (2, 1 / 3), (3, 1 / 6)) if k <= top or k == 1)


def _fault_signal(fault, shaft: _Shaft, rng, b, gear, resonance_hz) -> np.ndarray:
    """The fault's own vibration (before ``severity``), in g."""
    def ph():
        return rng.uniform(0, 2 * np.pi)
    sig = np.zeros(shaft.n)
    if fault == "unbalance":
        sig = 0.25 * np.sin(shaft.phase(1) + ph())
    elif fault == "misalignment":
        sig = 0.08 * np.sin(shaft.phase(1) + ph()) + 0.5 * np.sin(shaft.phase(2) + ph()) \
            + 0.15 * np.sin(shaft.phase(3) + ph())
    elif fault == "looseness":
        for k, a in [(0.5, 0.08), (1, 0.1), (1.5, 0.06), (2, 0.1), (3, 0.1), (4, 0.1), (5, 0.08), (6, 0.08),
                     (7, 0.06), (8, 0.06)]:
            sig += a * np.sin(shaft.phase(k) + ph())
    elif fault.startswith("bearing"):
        sig = _bearing_impacts(fault, shaft, rng, b, resonance_hz)
    elif fault == "gear_mesh":
        # a local tooth fault: once a turn, while the damaged tooth and its neighbours mesh (a pulse
        # of about 3 of the turn's gear_teeth meshes), the mesh force changes: a pulse on its amplitude
        revs = shaft.theta if shaft.ramp else shaft.f1 * shaft.t
        frac = (revs + rng.uniform()) % 1.0 - 0.5
        pulse = np.exp(-0.5 * (frac * gear[0] / 1.5) ** 2)
        sig = 0.3 * (1 + pulse) * _healthy_mesh(shaft, rng, *gear)
    elif fault == "resonance":
        # a structural mode (zeta 0.04) 6 % above 1X: the running speed's force and the broadband
        # forces both come out amplified, the latter as a hump in the noise floor
        from scipy.signal import cont2discrete, lfilter
        wr = 2 * np.pi * 1.06 * shaft.f1
        bz, az, _ = cont2discrete(([wr ** 2], [1.0, 2 * 0.04 * wr, wr ** 2]), 1 / shaft.fs, method="zoh")
        drive = 0.02 * np.sin(shaft.phase(1) + ph()) + 0.05 * rng.normal(size=shaft.n)
        sig = lfilter(np.ravel(bz), az, drive) * 2.0
    return sig


def _bearing_impacts(fault, shaft: _Shaft, rng, b, resonance_hz) -> np.ndarray:
    """Impacts at the defect's rate with 1 % slip jitter, ringing a resonance (zeta 0.05); an inner
    race's amplitude-modulated by the shaft's turn, a ball's by the cage's."""
    f1 = shaft.f1
    fr = b.frequencies(f1)
    # a ball defect strikes the inner and the outer race once per ball spin each: 2 x BSF
    ff = {"bearing_outer_race": fr["BPFO"], "bearing_inner_race": fr["BPFI"], "bearing_ball": fr["2xBSF"]}[fault]
    if shaft.ramp:   # the same events at equal steps of shaft angle (revolutions per impact: f1 / ff)
        step, end = f1 / ff, shaft.theta[-1]
    else:
        step, end = 1.0 / ff, shaft.duration
    times = []
    tk = rng.uniform(0, step)
    while tk < end:
        times.append(tk)
        tk += step * (1 + 0.01 * rng.normal())  # rolling elements slip: 1 % jitter
    revs = np.asarray(times) if shaft.ramp else None
    times = shaft.at_angle(revs) if shaft.ramp else np.asarray(times)
    amp = np.ones_like(times)
    if fault == "bearing_inner_race":    # the defect turns with the shaft
        amp = 1 + 0.8 * np.cos(2 * np.pi * revs if shaft.ramp else 2 * np.pi * f1 * times)
    elif fault == "bearing_ball":        # the ball travels with the cage
        amp = 1 + 0.8 * np.cos(2 * np.pi * fr["FTF"] / f1 * revs if shaft.ramp else 2 * np.pi * fr["FTF"] * times)
    return 0.3 * _impact_train(shaft.n, shaft.fs, times, resonance_hz, amp)


def _cage_modulated(noise, cage_modulation, shaft: _Shaft, rng, b) -> np.ndarray:
    """The broadband noise modulated at the cage rate FTF and its harmonics (depth 0..1), as an uneven
    cage or load does on a healthy bearing."""
    cage_modulation = positive(cage_modulation, "cage_modulation", allow_zero=True)
    if cage_modulation > 1:
        raise ParameterError(f"{cage_modulation=} must be between 0 and 1 (modulation depth)")
    if not cage_modulation:
        return noise
    ftf = b.frequencies(shaft.f1)["FTF"]
    th = (2 * np.pi * ftf / shaft.f1 * shaft.theta if shaft.ramp else 2 * np.pi * ftf * shaft.t) \
        + rng.uniform(0, 2 * np.pi)
    return noise * (1 + cage_modulation * (np.cos(th) + 0.5 * np.cos(2 * th) + 0.3 * np.cos(3 * th)) / 1.8)


def _with_shaft_impacts(sig, shaft_impacts, shaft: _Shaft, rng, p_sig, resonance_hz) -> np.ndarray:
    """One impact per revolution ringing the resonance (a rub), relative to the fault's RMS."""
    shaft_impacts = positive(shaft_impacts, "shaft_impacts", allow_zero=True)
    if not shaft_impacts:
        return sig
    marks = (shaft.at_angle(np.arange(rng.uniform(0, 1), shaft.theta[-1], 1.0)) if shaft.ramp
             else np.arange(rng.uniform(0, 1 / shaft.f1), shaft.duration, 1 / shaft.f1))
    return sig + shaft_impacts * np.sqrt(2 * p_sig) * _impact_train(shaft.n, shaft.fs, marks, resonance_hz)


def _machine_record(x, shaft: _Shaft, fault, severity, snr_db, unit, tach) -> Record:
    """The record, with a tachometer channel of ``tach`` pulses (0 -> 5 V) per revolution when asked."""
    truth = {"kind": "machine", "fault": fault, "rpm": shaft.rpm, "severity": severity, "snr_db": snr_db}
    channels = (Channel("acc", "acceleration", unit),)
    if shaft.ramp:
        truth["rpm_range"] = (shaft.rpm0, shaft.rpm1)
    if tach:
        ang = shaft.theta if shaft.ramp else shaft.f1 * shaft.t
        x = np.vstack([x, 5.0 * (np.mod(ang * tach, 1.0) < 0.25)])
        channels += (Channel("tach", "unknown", "V"),)
    return Record(x, shaft.fs, channels, meta={"rpm": shaft.rpm, "truth": truth},
                  history=(f"synth machine {fault}",))


def cage_pulsing(*, fs: float, duration: float, rpm: float = 1797.0, bearing="6205-2RS", width: float = 1 / 15,
                 band=(2500.0, 4500.0), seed=None) -> np.ndarray:
    """Unit-RMS noise in a band whose level pulses once per turn of the bearing's cage.

    The Gaussian pulse exp(-(2 pi t / width)^2 / 2) over the turn's phase t (-0.5..0.5), four times
    the floor at its peak: its envelope is a comb of FTF harmonics (0.83 at the 9th and 0.49 at the 18th
    for the default width), which carries lines where BPFO and, on most geometries, BPFI or 2 x BSF
    fall. Added to a machine, a stress case for the diagnosis: an uneven cage on a healthy bearing.

    Parameters
    ----------
    fs : float
        Sampling rate in Hz.
    duration : float
        Length in s.
    rpm : float
        Shaft speed.
    bearing : str or Bearing
        The bearing.
    width : float
        Pulse width as a share of a cage turn.
    band : tuple of float
        (lo, hi) Hz of the noise.
    seed : int, optional
        Random seed.

    Returns
    -------
    numpy.ndarray

    Raises
    ------
    ParameterError
        For a band outside (0, fs/2), a record shorter than one cage turn, or a bad seed.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> x = vm.synth.cage_pulsing(fs=12000.0, duration=2.0, seed=1)
    >>> round(float(x.std()), 2)
    1.0
    """
    from scipy.signal import butter, sosfiltfilt

    from ..models.bearing import bearing_from
    fs, duration, rpm = positive(fs, "fs"), positive(duration, "duration"), positive(rpm, "rpm")
    try:
        width = float(width)
    except (TypeError, ValueError):
        width = np.nan
    if not 0 < width <= 0.5:
        raise ParameterError(f"width={width!r} must be in (0, 0.5]: the pulse's width, 2 pi x its standard "
                             "deviation in cage turns")
    try:
        lo, hi = (float(v) for v in band)
    except (TypeError, ValueError):
        lo = hi = np.nan
    if not 0 < lo < hi < fs / 2:
        raise ParameterError(f"band={band!r} must be (low, high) Hz with 0 < low < high < fs/2 = {fs / 2:g}")
    n = int(round(fs * duration))
    b = bearing_from(bearing)
    if b is None:
        raise ParameterError("bearing is required: a vm.Bearing or a catalogue name (vm.BEARINGS)")
    ftf = b.frequencies(rpm / 60)["FTF"]
    if duration * ftf < 1 or n < 256:
        raise ParameterError(f"duration={duration!r} s must hold at least one turn of the cage ({1 / ftf:.3g} s at "
                             f"{rpm:g} rpm) and 256 samples")
    check_memory(64.0 * n, "cage_pulsing", n)   # about eight float arrays of the record's length
    try:
        rng = np.random.default_rng(seed)
    except (TypeError, ValueError):
        raise ParameterError(f"seed={seed!r} must be None or a non-negative integer") from None
    turns = (ftf * np.arange(n) / fs + rng.uniform()) % 1.0 - 0.5
    pulse = np.exp(-0.5 * (turns * 2 * np.pi / width) ** 2)
    noise = sosfiltfilt(butter(4, [lo, hi], "bandpass", fs=fs, output="sos"), rng.standard_normal(n))
    x = noise * (1 + 4 * pulse)
    return x / max(np.std(x), 1e-300)
