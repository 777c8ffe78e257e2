"""Modal FRFs, responses to a force, hammer tests, ambient and base-excited responses of models."""

from __future__ import annotations

import numpy as np

from ..core import units as _units
from ..core._validate import positive
from ..core.errors import ParameterError
from ..core.record import Channel, Record
from .decay import _ORDER


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
    -w^2 for mobility or accelerance.

    Parameters
    ----------
    freq : array_like
        Frequency lines in Hz.
    fn, zeta : array_like
        The modes.
    shapes : array_like
        Mass-normalised shapes (n_dof, n_modes).
    input_dof : int
        The driven dof.
    form : {"receptance", "mobility", "accelerance"}
        The FRF form.

    Returns
    -------
    FRF

    Raises
    ------
    ParameterError
        For shapes that do not match the modes.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> h = vm.synth.modal_frf(np.linspace(1, 100, 100), fn=[30.0], zeta=[0.02], shapes=[[1.0]])
    >>> h.h.shape
    (1, 1, 100)
    """
    from ..core.results import FRF
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
    """Responses of a proportionally damped system to a force sampled at ``fs``.

    Each mode is discretised exactly for a force held between samples (zero-order hold), so the
    discrete poles are exp(lambda_r / fs) exactly.

    Parameters
    ----------
    force : array_like
        Force samples in N.
    fs : float
        Sampling rate in Hz.
    fn, zeta : array_like
        The modes.
    shapes : array_like
        Mass-normalised shapes (n_dof, n_modes).
    input_dof : int
        The driven dof.
    quantity : {"displacement", "velocity", "acceleration"}
        What is returned.

    Returns
    -------
    numpy.ndarray
        (n_dof, n_samples).

    Raises
    ------
    ParameterError
        For shapes that do not match the modes.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> vm.synth.modal_response(np.ones(100), fs=1000.0, fn=[10.0], zeta=[0.02], shapes=[[1.0], [0.5]]).shape
    (2, 100)
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
    """A hammer test: half-sine force pulses at the ``hits`` times and the responses of every dof.

    Parameters
    ----------
    fn, zeta : array_like
        The modes.
    shapes : array_like
        Mass-normalised shapes (n_dof, n_modes).
    fs : float
        Sampling rate in Hz.
    hits : sequence of float
        Times of the hits in s.
    duration : float, optional
        Length in s (default 2 s after the last hit).
    peak_force : float
        Peak force in N.
    width : float
        Pulse width in s.
    double_at : float, optional
        Delay of a second, weaker pulse after each hit (a double hit).
    input_dof : int
        The hit dof.
    quantity : {"displacement", "velocity", "acceleration"}
        What the responses record.
    noise : float
        Response noise as a share of each channel's std.
    force_noise : float
        Force noise std in N.
    seed : int, optional
        Random seed.

    Returns
    -------
    Record
        Channels ``hammer`` (force, N) and ``a0``, ``a1``, ...

    Raises
    ------
    ParameterError
        For hits outside the record or shapes that do not match.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> vm.synth.hammer_test(fn=[21.3], zeta=[0.01], shapes=[[1.0]], fs=1024.0, seed=1).names
    ['hammer', 'a0']
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


def ambient(model, *, fs: float, duration: float, outputs=None, inputs=None, quantity: str = "acceleration",
            noise: float = 0.05, force_std: float = 1.0, seed=None) -> Record:
    """Response of an MDOF model to broadband random forces: operational vibration with known modes.

    Independent white Gaussian forces (held between samples) act at ``inputs``; each complex mode is
    discretised exactly, and a warm-up of five time constants is dropped, so the record is stationary.
    ``meta["truth"]`` holds fn, zeta and the shapes at the outputs.

    Parameters
    ----------
    model : MDOF
        The structure.
    fs : float
        Sampling rate in Hz.
    duration : float
        Length in s.
    outputs : sequence of int or array_like, optional
        Recorded dofs (default all), or a (n_sensors, n_dof) matrix of sensor combinations.
    inputs : sequence of int, optional
        Excited dofs (default all).
    quantity : {"displacement", "velocity", "acceleration"}
        What is recorded.
    noise : float
        Output noise std as a share of each output's RMS.
    force_std : float
        Std of each force in N.
    seed : int, optional
        Random seed.

    Returns
    -------
    Record

    Raises
    ------
    ParameterError
        For an unknown dof or values out of range.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> chain = vm.models.MDOF(np.eye(2), np.array([[2e4, -1e4], [-1e4, 1e4]]), modal_zeta=[0.02, 0.02])
    >>> vm.synth.ambient(chain, fs=100.0, duration=60.0, seed=1).n_channels
    2
    """
    from scipy.signal import lfilter

    from ..models.mdof import MDOF
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
    """A base-excited SDOF measured at its base and on its mass.

    Random base acceleration (flat up to ``bandwidth``) as one period of a periodic random signal, and
    the mass's absolute acceleration from the model's complex transmissibility line by line: the exact
    steady state. Channels "base" and "top" (m/s^2).

    Parameters
    ----------
    model : SDOF
        The isolator.
    fs : float
        Sampling rate in Hz.
    duration : float
        Length in s.
    bandwidth : float, optional
        Highest excited frequency (default fs/4).
    noise : float
        Sensor noise std as a share of each channel's RMS.
    seed : int, optional
        Random seed.

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
    >>> vm.synth.base_excited(vm.models.SDOF(m=1.0, k=3948.0, zeta=0.05), fs=500.0, duration=10.0, seed=1).names
    ['base', 'top']
    """
    from ..models.sdof import SDOF
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
