"""Free decays, viscous and Coulomb, with noise, clipping, DC offset and sensor drift."""

from __future__ import annotations

import numpy as np

from ..core import units as _units
from ..core._validate import positive
from ..core.errors import ParameterError
from ..core.record import Channel, Record
from ..models.sdof import coulomb_response

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
    """Noise std s giving SNR = A^2 / (2 s^2) (the initial sinusoid's power over the noise power).

    Parameters
    ----------
    amplitude : float
        The sinusoid's amplitude A.
    snr_db : float
        The signal-to-noise ratio in dB.

    Returns
    -------
    float

    Raises
    ------
    ParameterError
        For an amplitude that is not positive.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> round(vm.synth.noise_std_for_snr(1.0, 40.0), 5)
    0.00707
    """
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
    """Free decay of one or several viscously damped modes, with the sensor's imperfections.

    Each mode's displacement is ``amplitude * exp(-zeta wn t) cos(wd t + phase)`` (zeta < 1) or the
    release from rest at ``amplitude`` (zeta >= 1); velocity and acceleration are its exact
    derivatives. ``meta["truth"]`` holds the parameters.

    Parameters
    ----------
    fn, zeta : float or array_like
        Natural frequencies (Hz, undamped) and damping ratios.
    fs : float
        Sampling rate in Hz.
    duration : float
        Length in s.
    amplitude, phase : float or array_like
        Initial amplitude and phase (radians) per mode.
    quantity : {"displacement", "velocity", "acceleration"}
        What is recorded.
    unit : str, optional
        The unit label.
    snr_db : float, optional
        White noise with SNR = A^2 / (2 s^2), A the largest initial envelope.
    noise_std : float, optional
        Noise std instead of ``snr_db``.
    clip : float, optional
        Clip at +-clip.
    dc_offset : float
        Sensor offset.
    drift : float
        Sensor drift per second.
    seed : int, optional
        Random seed.
    name : str
        Channel name.

    Returns
    -------
    Record

    Raises
    ------
    ParameterError
        For values out of range or mismatched lengths.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> rec = vm.synth.free_decay(fn=[21.3, 57.9], zeta=[0.01, 0.02], fs=2000.0, duration=5.0, snr_db=40, seed=1)
    >>> rec.meta["truth"]["fn"]
    [21.3, 57.9]
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

    The amplitude falls by ``friction_decay`` (= 4 F/k) every cycle, linearly in time, at the undamped
    frequency; the mass sticks once the amplitude is below F/k.

    Parameters
    ----------
    fn : float
        Undamped natural frequency in Hz.
    friction_decay : float
        Amplitude lost per cycle (4 F/k).
    fs : float
        Sampling rate in Hz.
    duration : float
        Length in s.
    amplitude : float
        Release amplitude.
    quantity : {"displacement", "velocity", "acceleration"}
        What is recorded.
    unit : str, optional
        The unit label.
    snr_db, noise_std : float, optional
        Noise, as for ``free_decay``.
    seed : int, optional
        Random seed.
    name : str
        Channel name.

    Returns
    -------
    Record

    Raises
    ------
    ParameterError
        For values out of range.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> rec = vm.synth.coulomb_decay(fn=4.2, friction_decay=4e-4, amplitude=5e-3, fs=500.0, duration=6.0)
    >>> rec.fs
    500.0
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
