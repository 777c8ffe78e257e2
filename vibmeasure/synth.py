"""Synthetic measurements with known answers: free decays (viscous and Coulomb), with noise,
clipping, DC offset and sensor drift.

Every generator returns a :class:`~vibmeasure.Record` whose ``meta["truth"]`` holds the
parameters used, so tests and demos can compare identification with the truth.
"""

from __future__ import annotations

import numpy as np

from .core import units as _units
from .core._validate import check_memory, positive
from .core.errors import ParameterError
from .core.record import Channel, Record
from .models.sdof import coulomb_response  # noqa: F401  (public here too: synth.coulomb_response)

__all__ = ["free_decay", "coulomb_decay", "coulomb_response", "noise_std_for_snr", "machine", "cage_pulsing", "fleet",
           "ambient", "base_excited"]

_ORDER = {"displacement": 0, "velocity": 1, "acceleration": 2}


def _modes(fn, zeta, amplitude, phase):
    fn = np.atleast_1d(np.asarray(fn, dtype=float))
    n = fn.size
    out = []
    for name, v in (("zeta", zeta), ("amplitude", amplitude), ("phase", phase)):
        a = np.atleast_1d(np.asarray(v, dtype=float))
        if a.size == 1:
            a = np.full(n, a[0])
        if a.size != n:
            raise ParameterError(f"{name} has {a.size} values for {n} modes (fn has {n})")
        out.append(a)
    zeta, amplitude, phase = out
    if np.any(~np.isfinite(fn)) or np.any(fn <= 0):
        raise ParameterError(f"fn={fn.tolist()} must be finite and > 0 Hz")
    if np.any(~np.isfinite(zeta)) or np.any(zeta < 0):
        raise ParameterError(f"zeta={zeta.tolist()} must be finite and >= 0")
    return fn, zeta, amplitude, phase


def _mode_signal(t, fn, zeta, amp, phase, order):
    """Displacement A e^{-s t} cos(wd t + phi) (or the overdamped release from rest at x0=A),
    differentiated ``order`` times, in closed form."""
    wn = 2 * np.pi * fn
    if zeta < 1:
        s = zeta * wn
        wd = wn * np.sqrt(1 - zeta ** 2)
        # d/dt of A e^{p t} (p = -s + i wd) is p times it: complex form keeps derivatives exact
        p = complex(-s, wd)
        return np.real(amp * p ** order * np.exp(1j * phase) * np.exp(p * t))
    # zeta >= 1: released from rest at x0 = amp (phase ignored)
    if zeta == 1:
        # x = A (1 + wn t) e^{-wn t}
        e = np.exp(-wn * t)
        if order == 0:
            return amp * (1 + wn * t) * e
        if order == 1:
            return -amp * wn ** 2 * t * e
        return -amp * wn ** 2 * (1 - wn * t) * e
    r = wn * np.sqrt(zeta ** 2 - 1)
    p1, p2 = -zeta * wn + r, -zeta * wn - r
    c1 = amp * (-p2) / (p1 - p2)
    c2 = amp * p1 / (p1 - p2)
    return c1 * p1 ** order * np.exp(p1 * t) + c2 * p2 ** order * np.exp(p2 * t)


def noise_std_for_snr(amplitude: float, snr_db: float) -> float:
    """Noise std s giving SNR = A^2 / (2 s^2) (the initial sinusoid power over noise power)."""
    return float(abs(amplitude) / np.sqrt(2 * 10 ** (snr_db / 10)))


def _finish(x, t, *, fs, quantity, unit, snr_db, noise_std, ref_amp, clip, dc_offset, drift, seed, name, truth):
    if quantity not in _ORDER:
        raise ParameterError(f"quantity={quantity!r} must be one of {tuple(_ORDER)}")
    unit = _units.SI_UNIT[quantity] if unit is None else _units.check_unit(quantity, unit)
    if snr_db is not None and noise_std is not None:
        raise ParameterError("give snr_db or noise_std, not both")
    rng = np.random.default_rng(seed)
    s = noise_std_for_snr(ref_amp, snr_db) if snr_db is not None else (noise_std or 0.0)
    x = x + dc_offset + drift * t
    if s > 0:
        x = x + rng.normal(0.0, s, x.size)
    if clip is not None:
        c = positive(clip, "clip")
        x = np.clip(x, -c, c)
    truth = dict(truth, noise_std=s, snr_db=snr_db, dc_offset=dc_offset, drift=drift, clip=clip, seed=seed)
    return Record(x, fs, (Channel(name, quantity, unit),), meta={"truth": truth},
                  history=(f"synth {truth['kind']}",))


def free_decay(*, fn, zeta, fs: float, duration: float, amplitude=1.0, phase=0.0, quantity: str = "displacement",
               unit: str | None = None, snr_db: float | None = None, noise_std: float | None = None,
               clip: float | None = None, dc_offset: float = 0.0, drift: float = 0.0, seed=None,
               name: str = "x") -> Record:
    """Free decay of one or several viscously damped modes.

    Each mode's displacement is ``amplitude * exp(-zeta wn t) cos(wd t + phase)`` (zeta < 1) or the
    release from rest at ``amplitude`` (zeta >= 1); ``quantity`` "velocity"/"acceleration" records
    its exact derivatives. ``snr_db`` sets white noise with SNR = A^2/(2 s^2), A the largest
    initial envelope of the recorded quantity; ``clip`` clips at +-clip; ``dc_offset`` and
    ``drift`` (units per second) model the sensor.
    """
    fs = positive(fs, "fs")
    duration = positive(duration, "duration")
    fn, zeta, amplitude, phase = _modes(fn, zeta, amplitude, phase)
    if quantity not in _ORDER:
        raise ParameterError(f"quantity={quantity!r} must be one of {tuple(_ORDER)}")
    n = int(round(duration * fs))
    if n < 2:
        raise ParameterError(f"duration={duration} s at fs={fs} Hz gives {n} samples; at least 2 are needed")
    t = np.arange(n) / fs
    order = _ORDER[quantity]
    x = np.zeros(n)
    env = []
    for f, z, a, ph in zip(fn, zeta, amplitude, phase):
        x += _mode_signal(t, f, z, a, ph, order)
        env.append(abs(a) * (2 * np.pi * f) ** order)
    truth = {"kind": "free_decay", "fn": fn.tolist(), "zeta": zeta.tolist(), "amplitude": amplitude.tolist(),
             "phase": phase.tolist(), "quantity": quantity}
    return _finish(x, t, fs=fs, quantity=quantity, unit=unit, snr_db=snr_db, noise_std=noise_std,
                   ref_amp=max(env), clip=clip, dc_offset=dc_offset, drift=drift, seed=seed, name=name, truth=truth)


def coulomb_decay(*, fn: float, friction_decay: float, fs: float, duration: float, amplitude: float = 1.0,
                  quantity: str = "displacement", unit: str | None = None, snr_db: float | None = None,
                  noise_std: float | None = None, seed=None, name: str = "x") -> Record:
    """Free decay of a mass-spring system with dry (Coulomb) friction, released from rest.

    The amplitude falls by ``friction_decay`` (= 4 F/k) every cycle, linearly in time, at the
    undamped frequency ``fn``; the mass sticks once the amplitude is below F/k.
    """
    fn = positive(fn, "fn")
    fs = positive(fs, "fs")
    duration = positive(duration, "duration")
    dec = positive(friction_decay, "friction_decay")
    if quantity not in _ORDER:
        raise ParameterError(f"quantity={quantity!r} must be one of {tuple(_ORDER)}")
    n = int(round(duration * fs))
    t = np.arange(n) / fs
    x = coulomb_response(t, fn=fn, friction_decay=dec, amplitude=float(amplitude), order=_ORDER[quantity])
    wn = 2 * np.pi * fn
    order = _ORDER[quantity]
    truth = {"kind": "coulomb_decay", "fn": fn, "friction_decay": dec, "amplitude": float(amplitude),
             "quantity": quantity}
    return _finish(x, t, fs=fs, quantity=quantity, unit=unit, snr_db=snr_db, noise_std=noise_std,
                   ref_amp=abs(amplitude) * wn ** order, clip=None, dc_offset=0.0, drift=0.0, seed=seed,
                   name=name, truth=truth)


def _modal_args(fn, zeta, shapes, input_dof):
    fn = np.atleast_1d(np.asarray(fn, float))
    zeta = np.broadcast_to(np.atleast_1d(np.asarray(zeta, float)), fn.shape).copy()
    phi = np.asarray(shapes, float)
    if phi.ndim != 2 or phi.shape[1] != fn.size:
        raise ParameterError(f"shapes must be (n_dof, n_modes={fn.size}) mass-normalised mode shapes, got {phi.shape}")
    if not 0 <= input_dof < phi.shape[0]:
        raise ParameterError(f"input_dof={input_dof} is not a dof of the {phi.shape[0]}-dof shapes")
    if np.any(fn <= 0) or np.any(zeta < 0) or np.any(zeta >= 1):
        raise ParameterError("fn must be > 0 and 0 <= zeta < 1 for every mode")
    return fn, zeta, phi


def modal_frf(freq, *, fn, zeta, shapes, input_dof: int = 0, form: str = "receptance"):
    """Analytic FRFs of a proportionally damped system from its modes (a closed-form oracle).

    H_p,in(w) = sum_r phi_pr phi_in,r / (w_r^2 - w^2 + 2 i zeta_r w_r w) (receptance), times i w or
    -w^2 for mobility or accelerance. ``shapes`` (n_dof, n_modes) mass-normalised.
    """
    from .core.results import FRF
    freq = np.asarray(freq, float)
    fn, zeta, phi = _modal_args(fn, zeta, shapes, input_dof)
    w = 2 * np.pi * freq
    wr = 2 * np.pi * fn
    den = wr[:, None] ** 2 - w[None] ** 2 + 2j * zeta[:, None] * wr[:, None] * w[None]  # (modes, nf)
    h = np.einsum("pr,r,rf->pf", phi, phi[input_dof], 1 / den)
    k = {"receptance": 0, "mobility": 1, "accelerance": 2}[form]
    h = h * (1j * w) ** k
    return FRF(freq, h[:, None, :], form, estimator="analytic",
               outputs=tuple(f"dof{p}" for p in range(phi.shape[0])), inputs=(f"dof{input_dof}",))


def modal_response(force, *, fs: float, fn, zeta, shapes, input_dof: int = 0, quantity: str = "displacement"):
    """Responses (n_dof, n) of a proportionally damped system to a force sampled at ``fs``.

    Each mode is discretised exactly for a force held between samples (zero-order hold), so the
    discrete poles are exp(lambda_r / fs) exactly; outputs sum phi_pr q_r (or its derivatives).
    """
    from scipy.signal import cont2discrete, lfilter
    force = np.asarray(force, float)
    fn, zeta, phi = _modal_args(fn, zeta, shapes, input_dof)
    order = _ORDER.get(quantity)
    if order is None:
        raise ParameterError(f"quantity={quantity!r} must be one of {tuple(_ORDER)}")
    out = np.zeros((phi.shape[0], force.size))
    for r in range(fn.size):
        wr = 2 * np.pi * fn[r]
        num = [1.0] + [0.0] * order
        b, a, _ = cont2discrete((num, [1.0, 2 * zeta[r] * wr, wr ** 2]), 1 / fs, method="zoh")
        q = lfilter(np.ravel(b), a, phi[input_dof, r] * force)
        out += np.outer(phi[:, r], q)
    return out


def hammer_test(*, fn, zeta, shapes, fs: float, hits=(0.2, 2.2, 4.2), duration: float | None = None,
                peak_force: float = 100.0, width: float = 0.003, double_at: float | None = None,
                input_dof: int = 0, quantity: str = "acceleration", noise: float = 1e-4, force_noise: float = 0.05,
                seed=None) -> Record:
    """A hammer test: half-sine force pulses (``peak_force`` N, ``width`` s) at the ``hits`` times
    (s) on ``input_dof`` and the responses of every dof of a proportionally damped system, each
    mode discretised exactly. ``double_at`` adds a second, weaker pulse (a double hit). Response
    noise is ``noise`` times each channel's std; the force gets ``force_noise`` N of noise.
    Channels: ``hammer`` (force, N) and ``a0``, ``a1``, ... (``quantity`` in SI units).
    """
    fs = positive(fs, "fs")
    hits = np.atleast_1d(np.asarray(hits, float))
    if hits.size < 1 or not np.all(np.isfinite(hits)) or np.any(hits < 0):
        raise ParameterError(f"hits={hits.tolist()!r} must be one or more times >= 0 s")
    width = positive(width, "width")
    if width * fs < 3:
        raise ParameterError(f"width={width} s is shorter than 3 samples at fs={fs} Hz: the pulse cannot be sampled")
    peak_force = positive(peak_force, "peak_force")
    noise, force_noise = positive(noise, "noise", allow_zero=True), positive(force_noise, "force_noise", allow_zero=True)
    T = float(hits.max() + 2.0) if duration is None else positive(duration, "duration")
    if hits.max() + width > T:
        raise ParameterError(f"duration={T:g} s ends before the last hit (at {hits.max():g} s) is over")
    if double_at is not None:
        double_at = positive(double_at, "double_at", allow_zero=True)
        if double_at + width > T:
            raise ParameterError(f"double_at={double_at:g} s is after the record's end ({T:g} s)")
    n = int(round(T * fs))
    t = np.arange(n) / fs
    f = np.zeros(n)
    pulses = [(h, peak_force) for h in hits] + ([] if double_at is None else [(float(double_at), 0.6 * peak_force)])
    for h, a in pulses:
        f += np.where((t >= h) & (t < h + width), np.sin(np.pi * (t - h) / width), 0.0) * a
    y = modal_response(f, fs=fs, fn=fn, zeta=zeta, shapes=shapes, input_dof=input_dof, quantity=quantity)
    rng = np.random.default_rng(seed)
    y += noise * y.std(axis=1, keepdims=True) * rng.normal(size=y.shape)
    f = f + force_noise * rng.normal(size=n)
    unit = {"displacement": "m", "velocity": "m/s", "acceleration": "m/s^2"}[quantity]
    chans = [Channel("hammer", "force", "N")] + [Channel(f"a{i}", quantity, unit) for i in range(y.shape[0])]
    return Record(np.vstack([f, y]), fs=fs, channels=chans)


_FAULTS = ("none", "unbalance", "misalignment", "looseness", "bearing_outer_race", "bearing_inner_race",
           "bearing_ball", "gear_mesh", "resonance")


def _impact_train(n, fs, times, resonance_hz, amp=None):
    """Unit-RMS response of a resonance (zeta 0.05) to impacts at the given times, each placed at its
    exact time by a band-limited fractional delay (a Kaiser-windowed sinc of 64 taps), as an
    anti-aliased measurement would see it. Rounded to samples, a train with 400.67 samples per period
    (a shaft's at 1797 rpm and 12 kHz) repeats its rounding every third impact, and its envelope has
    lines at thirds of the shaft rate that no machine makes (healthy machines were called inner race)."""
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
            seed=None, unit: str = "g", tach: int = 0) -> Record:
    """Accelerometer record of a rotating machine, healthy or with one fault, for tests and demos.

    Every machine has a small residual 1X and broadband noise. Faults: unbalance (strong 1X),
    misalignment (strong 2X beside 1X), looseness (many harmonics and 0.5X sub-harmonics), bearing
    defects (impacts at BPFO/BPFI/BSF with 1 % slip jitter exciting a structural resonance; inner
    race and ball faults amplitude-modulated at 1X and FTF), gear mesh (teeth x 1X with 1X
    sidebands), resonance (a structural mode 6 % above 1X amplifying 1X and the broadband forces). ``severity`` scales the fault, ``snr_db`` is the fault signal's power over the noise.
    Nuisances that are no fault (stress cases for the diagnosis): ``cage_modulation`` (0..1) modulates
    the broadband noise at the cage rate FTF and its harmonics, as an uneven cage or load does on a
    healthy bearing; ``shaft_impacts`` (relative to the fault signal's RMS, or to 0.3 g without a
    fault) adds one impact per revolution exciting the resonance (a rub): its envelope is a comb of
    shaft harmonics. The fault-free part is in g; meta holds rpm and the truth.

    ``rpm=(start, end)`` runs the shaft up (or down) linearly over the record: every shaft-, gear- and
    bearing-rate event then follows the shaft angle, while the structural resonances stay put in Hz;
    meta["rpm"] is the mean speed. ``tach=N`` adds a channel "tach" with N pulses (0 -> 5 V) per
    revolution, as a tachometer or encoder gives.
    """
    from .models.bearing import BEARINGS, Bearing
    if fault not in _FAULTS:
        raise ParameterError(f"fault={fault!r} must be one of {_FAULTS}")
    fs, duration = positive(fs, "fs"), positive(duration, "duration")
    ramp = isinstance(rpm, (tuple, list, np.ndarray))
    if ramp:
        if len(rpm) != 2:
            raise ParameterError(f"rpm={rpm!r} must be one speed or a (start, end) pair for a linear run-up")
        rpm0, rpm1 = positive(rpm[0], "rpm[0]"), positive(rpm[1], "rpm[1]")
        rpm = (rpm0 + rpm1) / 2
    else:
        rpm = positive(rpm, "rpm")
    if isinstance(tach, bool) or not isinstance(tach, (int, np.integer)) or tach < 0:
        raise ParameterError(f"tach={tach!r} must be a whole number of pulses per revolution (0: no tachometer)")
    rng = np.random.default_rng(seed)
    n = int(round(fs * duration))
    t = np.arange(n) / fs
    f1 = rpm / 60.0
    # shaft angle in revolutions; at constant speed every phase below is computed as before (same samples)
    theta = (rpm0 * t + (rpm1 - rpm0) * t ** 2 / (2 * duration)) / 60.0 if ramp else None

    def shaft_phase(k):
        return 2 * np.pi * k * theta if ramp else 2 * np.pi * k * f1 * t

    def at_angle(revs):
        """Times at which the shaft reaches the given angles (revolutions)."""
        return np.interp(revs, theta, t) if ramp else np.asarray(revs) / f1
    b = bearing if isinstance(bearing, Bearing) else BEARINGS["6205-2RS"] if bearing is None else BEARINGS[bearing]
    # residual unbalance, healthy level: 0.02 g at 1797 rpm (0.74 mm/s RMS). A rotor balanced to a quality
    # grade (ISO 21940-11: eccentricity x angular speed fixed) has an unbalance force, and below its first
    # critical speed an acceleration, that grow with the speed: its 1X velocity is the same at every
    # speed. Fixed in g, a healthy machine read 4.45, 2.21, 1.47 and 1.11 mm/s RMS at 300, 600, 900 and
    # 1200 rpm, above half ISO 10816's A/B boundary (where shaft-order faults begin to count), and
    # diagnose called each unbalance (3 seeds each); now 0.74-0.84 mm/s at every speed
    speed = (rpm0 + (rpm1 - rpm0) * t / duration) if ramp else rpm
    base = 0.02 * (speed / 1797.0) * np.sin(shaft_phase(1) + rng.uniform(0, 2 * np.pi))
    sig = np.zeros(n)
    ph = lambda: rng.uniform(0, 2 * np.pi)  # noqa: E731
    if fault == "unbalance":
        sig = 0.25 * np.sin(shaft_phase(1) + ph())
    elif fault == "misalignment":
        sig = 0.08 * np.sin(shaft_phase(1) + ph()) + 0.5 * np.sin(shaft_phase(2) + ph()) \
            + 0.15 * np.sin(shaft_phase(3) + ph())
    elif fault == "looseness":
        for k, a in [(0.5, 0.08), (1, 0.1), (1.5, 0.06), (2, 0.1), (3, 0.1), (4, 0.1), (5, 0.08), (6, 0.08),
                     (7, 0.06), (8, 0.06)]:
            sig += a * np.sin(shaft_phase(k) + ph())
    elif fault.startswith("bearing"):
        fr = b.frequencies(f1)
        # a ball defect strikes the inner and the outer race once per ball spin each: 2 x BSF
        ff = {"bearing_outer_race": fr["BPFO"], "bearing_inner_race": fr["BPFI"], "bearing_ball": fr["2xBSF"]}[fault]
        if ramp:   # the same events at equal steps of shaft angle (revolutions per impact: f1 / ff)
            step, end = f1 / ff, theta[-1]
        else:
            step, end = 1.0 / ff, duration
        times = []
        tk = rng.uniform(0, step)
        while tk < end:
            times.append(tk)
            tk += step * (1 + 0.01 * rng.normal())  # rolling elements slip: 1 % jitter
        revs = np.asarray(times) if ramp else None
        times = at_angle(revs) if ramp else np.asarray(times)
        amp = np.ones_like(times)
        if fault == "bearing_inner_race":    # the defect turns with the shaft
            amp = 1 + 0.8 * np.cos(2 * np.pi * revs if ramp else 2 * np.pi * f1 * times)
        elif fault == "bearing_ball":        # the ball travels with the cage
            amp = 1 + 0.8 * np.cos(2 * np.pi * fr["FTF"] / f1 * revs if ramp else 2 * np.pi * fr["FTF"] * times)
        sig = 0.3 * _impact_train(n, fs, times, resonance_hz, amp)  # resonance with zeta 0.05
    elif fault == "gear_mesh":
        fm = gear_teeth * f1
        mesh = (lambda k: 2 * np.pi * k * gear_teeth * theta) if ramp else (lambda k: 2 * np.pi * k * fm * t)
        sig = 0.3 * (1 + 0.5 * np.cos(shaft_phase(1))) * np.sin(mesh(1) + ph()) \
            + 0.1 * np.sin(mesh(2) + ph())
    elif fault == "resonance":
        # a structural mode (zeta 0.04) 6 % above 1X: the running speed's force and the broadband
        # forces both come out amplified, the latter as a hump in the noise floor
        from scipy.signal import cont2discrete, lfilter
        wr = 2 * np.pi * 1.06 * f1
        bz, az, _ = cont2discrete(([wr ** 2], [1.0, 2 * 0.04 * wr, wr ** 2]), 1 / fs, method="zoh")
        drive = 0.02 * np.sin(shaft_phase(1) + ph()) + 0.05 * rng.normal(size=n)
        sig = lfilter(np.ravel(bz), az, drive) * 2.0
    sig = severity * sig
    p_sig = np.mean(sig ** 2) if fault != "none" else np.mean((0.3 * np.ones(1)) ** 2) / 2
    noise = rng.normal(0, np.sqrt(p_sig / 10 ** (snr_db / 10)), n)
    cage_modulation = positive(cage_modulation, "cage_modulation", allow_zero=True)
    if cage_modulation > 1:
        raise ParameterError(f"{cage_modulation=} must be between 0 and 1 (modulation depth)")
    if cage_modulation:
        ftf = b.frequencies(f1)["FTF"]
        th = (2 * np.pi * ftf / f1 * theta if ramp else 2 * np.pi * ftf * t) + rng.uniform(0, 2 * np.pi)
        noise *= 1 + cage_modulation * (np.cos(th) + 0.5 * np.cos(2 * th) + 0.3 * np.cos(3 * th)) / 1.8
    shaft_impacts = positive(shaft_impacts, "shaft_impacts", allow_zero=True)
    if shaft_impacts:
        marks = (at_angle(np.arange(rng.uniform(0, 1), theta[-1], 1.0)) if ramp
                 else np.arange(rng.uniform(0, 1 / f1), duration, 1 / f1))
        sig = sig + shaft_impacts * np.sqrt(2 * p_sig) * _impact_train(n, fs, marks, resonance_hz)
    x = base + sig + noise
    from .core.record import Channel as _Ch
    truth = {"kind": "machine", "fault": fault, "rpm": rpm, "severity": severity, "snr_db": snr_db}
    channels = (_Ch("acc", "acceleration", unit),)
    if ramp:
        truth["rpm_range"] = (rpm0, rpm1)
    if tach:
        ang = theta if ramp else f1 * t
        x = np.vstack([x, 5.0 * (np.mod(ang * tach, 1.0) < 0.25)])
        channels += (_Ch("tach", "unknown", "V"),)
    return Record(x, fs, channels, meta={"rpm": rpm, "truth": truth}, history=(f"synth machine {fault}",))


def cage_pulsing(*, fs: float, duration: float, rpm: float = 1797.0, bearing="6205-2RS", width: float = 1 / 15,
                 band=(2500.0, 4500.0), seed=None) -> np.ndarray:
    """Unit-RMS noise in ``band`` (Hz) whose level pulses once per turn of the bearing's cage: the
    Gaussian pulse exp(-(2 pi t / width)^2 / 2) over the turn's phase t (-0.5..0.5), four times the
    floor at its peak. Its envelope is a comb of FTF harmonics falling as exp(-(k width)^2 / 2), 0.83 at
    the 9th and 0.49 at the 18th for the default width: a cage comb of many harmonics, which carries
    lines where BPFO (n_balls x FTF) and, on most geometries, BPFI or 2 x BSF fall. Added to a machine
    (``machine``), a stress case for the diagnosis: an uneven cage or load on a healthy bearing."""
    from .models.bearing import bearing_from
    from scipy.signal import butter, sosfiltfilt
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


def fleet(folder=None, *, n_measurements: int = 52, start: str = "2026-01-05", interval_days: float = 7.0,
          fault_onset: int = 26, fs: float = 12800.0, duration: float = 1.0, seed: int = 0):
    """A small synthetic fleet measured over time, for tests, the sample data and the demo.

    Four assets, one point each, measured every ``interval_days``: ``pump-1`` and ``pump-2``
    healthy (rpm wandering by 1 %); ``pump-3`` whose bearing (6205-2RS) grows an outer-race defect from
    measurement ``fault_onset`` on (BPFO impacts rising from nothing to twice the healthy RMS); and
    ``frame-1``, a structure rung down at each visit, whose stiffness falls by up to 6 % from
    ``fault_onset`` on (fn from 24 Hz down to about 23.3 Hz, noise 40 dB).

    Returns a list of dicts (``record``, ``asset``, ``point``, ``time`` ISO 8601, ``rpm``, ``bearing``,
    ``truth``). With ``folder`` each record is also written there as HDF5, with the manifests
    ``machines.csv`` (task diagnose/spectrum) and ``structures.csv`` (task ringdown+compare) for
    ``vm.batch`` / ``vibmeasure batch``.
    """
    import datetime as _dt
    from pathlib import Path
    from .core._validate import positive
    from .models.bearing import BEARINGS
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
        from .io import write
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


def ambient(model, *, fs: float, duration: float, outputs=None, inputs=None, quantity: str = "acceleration",
            noise: float = 0.05, force_std: float = 1.0, seed=None) -> Record:
    """Response of an MDOF model (``vm.models.MDOF``) to broadband random forces: operational (ambient)
    vibration with known modes, for output-only modal analysis.

    Independent white Gaussian forces (std ``force_std`` N, held between samples) act at the dofs
    ``inputs`` (default all); the ``outputs`` dofs (default all) are recorded as ``quantity``. The
    state-space model is diagonalised and each complex mode discretised exactly for the held force,
    so the record's discrete poles are exp(lambda / fs) exactly. A warm-up of five time constants of
    the slowest-decaying mode is simulated and dropped, so the record is stationary from its start.
    ``outputs`` may also be a matrix (n_sensors, n_dof): each row a sensor reading a combination of
    dofs (a sensor between two masses, or a second sensor on one dof). ``noise`` is the output noise std as a fraction of each output's RMS (0.05: 5 %).
    ``meta["truth"]`` holds fn, zeta and the mode shapes at the outputs (the model's ``modes()``).
    """
    from scipy.signal import lfilter
    from .models.mdof import MDOF
    if not isinstance(model, MDOF):
        raise ParameterError(f"model must be a vm.models.MDOF, got {type(model).__name__}")
    fs, duration = positive(fs, "fs"), positive(duration, "duration")
    noise, force_std = positive(noise, "noise", allow_zero=True), positive(force_std, "force_std")
    if quantity not in _ORDER:
        raise ParameterError(f"quantity={quantity!r} must be one of {tuple(_ORDER)}")
    n = model.n_dof
    ins = list(range(n)) if inputs is None else [int(i) for i in np.atleast_1d(inputs)]
    if not ins or any(not 0 <= i < n for i in ins):
        raise ParameterError(f"inputs={ins} must name dofs 0..{n - 1} of the {n}-dof model")
    S, names = _sensors(outputs, n)
    truth = model.modes()
    if np.any(truth.fn >= fs / 2):
        raise ParameterError(f"fs={fs:g} Hz: the model's highest mode ({truth.fn.max():.4g} Hz) is above fs/2")
    if not np.all(truth.zeta > 0):
        raise ParameterError("the model needs damping (C, rayleigh or modal_zeta): an undamped model never "
                             "reaches a stationary response")
    Minv = np.linalg.inv(model.M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ model.K, -Minv @ model.C]])
    B = np.vstack([np.zeros((n, n)), Minv])[:, ins]
    lam, V = np.linalg.eig(A)
    G = np.linalg.solve(V, B)                      # modal input matrix (2n, n_in)
    mu = np.exp(lam / fs)
    gain = (mu - 1) / lam                          # exact for a force held over one sample
    n_keep = int(round(fs * duration))
    n_warm = int(np.ceil(5 / np.min(-lam.real) * fs))
    rng = np.random.default_rng(seed)
    F = rng.normal(0.0, force_std, (len(ins), n_warm + n_keep))
    Z = np.empty((2 * n, F.shape[1]), complex)
    for r in range(2 * n):
        # z_r[k] after the force held over samples 0..k-1 (state at sample k)
        Z[r] = lfilter([0.0, gain[r]], [1.0, -mu[r]], G[r] @ F)
    X = np.real(V @ Z)
    disp, vel = X[:n], X[n:]
    if quantity == "displacement":
        Y = disp
    elif quantity == "velocity":
        Y = vel
    else:
        Fd = np.zeros((n, F.shape[1]))
        Fd[ins] = F
        Y = Minv @ (Fd - model.C @ vel - model.K @ disp)
    Y = S @ Y[:, n_warm:]
    if noise > 0:
        Y = Y + rng.normal(size=Y.shape) * (noise * np.std(Y, axis=1, keepdims=True))
    unit = _units.SI_UNIT[quantity]
    shapes = S @ truth.shapes if truth.shapes is not None else None
    meta_truth = {"kind": "ambient", "fn": truth.fn.tolist(), "zeta": truth.zeta.tolist(),
                  "shapes": None if shapes is None else np.real_if_close(shapes).tolist(), "outputs": S.tolist(),
                  "inputs": ins, "noise": noise, "force_std": force_std, "seed": seed, "quantity": quantity}
    chans = tuple(Channel(nm, quantity, unit) for nm in names)
    return Record(Y, fs, chans, meta={"truth": meta_truth}, history=(f"synth ambient {n}-dof",))


def _sensors(outputs, n):
    """Sensor matrix (n_out, n_dof) and channel names from dof indices or a matrix."""
    if outputs is None:
        return np.eye(n), [f"dof{i}" for i in range(n)]
    a = np.asarray(outputs)
    if a.ndim == 2:
        S = a.astype(float)
        if S.shape[1] != n or not np.all(np.isfinite(S)) or not np.all(np.any(S != 0, axis=1)):
            raise ParameterError(f"outputs as a matrix must be (n_sensors, {n}) with a finite non-zero row per "
                                 f"sensor, got shape {S.shape}")
        return S, [f"s{i}" for i in range(S.shape[0])]
    idx = [int(o) for o in np.atleast_1d(a)]
    if not idx or any(not 0 <= i < n for i in idx) or len(set(idx)) != len(idx):
        raise ParameterError(f"outputs={idx} must name distinct dofs 0..{n - 1} of the {n}-dof model (a "
                             "matrix of sensor rows allows combinations)")
    return np.eye(n)[idx], [f"dof{i}" for i in idx]


def base_excited(model, *, fs: float, duration: float, bandwidth: float | None = None, noise: float = 0.0,
                 seed=None) -> Record:
    """A base-excited SDOF (``vm.models.SDOF``) measured at its base and on its mass: random base
    acceleration (Gaussian, flat up to ``bandwidth`` Hz, default fs/4) and the mass's absolute
    acceleration. The record is one period of a periodic random signal built in the frequency
    domain, and the response is the model's complex transmissibility applied line by line: the exact
    steady state, with no discretisation error. Channels "base" and "top" (m/s^2); ``noise`` is the
    sensor noise std as a fraction of each channel's RMS."""
    from .models.sdof import SDOF
    if not isinstance(model, SDOF):
        raise ParameterError(f"model must be a vm.models.SDOF, got {type(model).__name__}")
    fs, duration = positive(fs, "fs"), positive(duration, "duration")
    bw = fs / 4 if bandwidth is None else positive(bandwidth, "bandwidth")
    if bw >= fs / 2:
        raise ParameterError(f"bandwidth={bw:g} Hz must be below fs/2 = {fs / 2:g} Hz")
    rng = np.random.default_rng(seed)
    n = int(round(fs * duration))
    f = np.fft.rfftfreq(n, 1 / fs)
    B = (rng.normal(size=f.size) + 1j * rng.normal(size=f.size)) * (f <= bw) * (f > 0)
    w = 2 * np.pi * f
    k_c = model.k * (1 + 1j * model.loss_factor) + 1j * w * model.c
    T = k_c / (k_c - model.m * w ** 2)
    X = np.vstack([np.fft.irfft(B, n), np.fft.irfft(B * T, n)])
    X = X / np.std(X[0])
    if noise:
        X = X + rng.normal(size=X.shape) * (positive(noise, "noise") * np.std(X, axis=1, keepdims=True))
    truth = {"kind": "base_excited", "fn": model.fn, "zeta": model.zeta, "bandwidth": bw, "noise": noise, "seed": seed}
    return Record(X, fs, (Channel("base", "acceleration", "m/s^2"), Channel("top", "acceleration", "m/s^2")),
                  meta={"truth": truth}, history=("synth base_excited",))
