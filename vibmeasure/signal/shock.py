"""Shock response spectra (SRS) and measured transmissibility.

``srs``: the peak response of a bank of base-excited SDOF oscillators to a measured base
acceleration, by the ramp-invariant recursive filter (Smallwood 1981; ISO 18431-4): each
oscillator's response is exact at the samples for a base acceleration linear between them (and
zero before the record).
Every oscillator runs on the record's own samples. Where it has fewer than 32 samples a cycle (above
fs/32) the true extreme may lie between samples: the state at a sample follows from two outputs, and
the exact response of the piecewise-linear input is evaluated at 32 points a cycle over the steps
next to samples that come within cos(pi / P) of the sampled extreme (only there can it be beaten);
each extreme is then refined by a parabola through its neighbours.

``transmissibility``: |top / base| measured by the H1 estimator with its coherence, compared with
a model's transmissibility where one is given.
"""

from __future__ import annotations


import numpy as np

from ..core import units as _units
from ..core._validate import as_record, clean_signal, positive, response_channel
from ..core.errors import ParameterError
from ..core.record import Record
from ..core.results import ShockSpectrum, Transmissibility

__all__ = ["srs", "ShockSpectrum", "srs_coefficients", "smallwood_coefficients", "transmissibility", "Transmissibility"]

KINDS = ("maximax", "primary", "residual")
OUTPUTS = ("acceleration", "pseudo_velocity", "relative_displacement")
PTS_PER_CYCLE = 32   # an oscillator's response is sampled at least this finely (peak error < 0.5 %, then refined)
# a sine's samples come within cos(pi / P) of its peak; the response is not one pure sine (damping, the
# input changing within the step), so steps next to samples down to 90 % of that are searched too
REACH_MARGIN = 0.9




def srs_coefficients(fn, zeta: float, fs: float, output: str = "acceleration"):
    """Ramp-invariant filter coefficients (b, a), arrays (n_fn, 3), of the base-excited SDOF: the
    response at the samples is exact for a base acceleration linear between samples.

    State: the relative displacement z = x - y and its rate, z'' + 2 zeta wn z' + wn^2 z = -y''.
    Over one step with the input a straight line, x[k+1] = Phi x[k] + (G0 - G1) u[k] + G1 u[k+1]
    (Phi, G0, G1 from one matrix exponential), so H(z) = C (zI - Phi)^-1 (G1 z + G0 - G1) with
    C = [1, 0] (relative displacement) or [-wn^2, -2 zeta wn] (absolute acceleration). For the
    absolute acceleration these are Smallwood's closed-form coefficients (ISO 18431-4; tested). As a
    filter, the input is taken as zero before the record and ramping to its first sample."""
    from scipy.linalg import expm
    fn = np.atleast_1d(np.asarray(fn, float))
    T = 1.0 / fs
    w = 2 * np.pi * fn
    M = np.zeros((fn.size, 4, 4))
    M[:, 0, 1] = 1.0
    M[:, 1, 0] = -w * w
    M[:, 1, 1] = -2 * zeta * w
    M[:, 1, 2] = -1.0           # input: base acceleration, with the sign of the equation
    M[:, 2, 3] = 1.0 / T        # the input's slope over the step
    E = expm(M * T)
    Phi, G0, G1 = E[:, :2, :2], E[:, :2, 2], E[:, :2, 3]
    G2 = G0 - G1
    tr = Phi[:, 0, 0] + Phi[:, 1, 1]
    det = Phi[:, 0, 0] * Phi[:, 1, 1] - Phi[:, 0, 1] * Phi[:, 1, 0]
    P = Phi - tr[:, None, None] * np.eye(2)
    if output == "acceleration":
        C = np.stack([-w * w, -2 * zeta * w], axis=1)
    else:
        C = np.tile([1.0, 0.0], (fn.size, 1))
    PG1 = np.einsum("kij,kj->ki", P, G1)
    PG2 = np.einsum("kij,kj->ki", P, G2)
    B = np.stack([np.sum(C * G1, 1), np.sum(C * (G2 + PG1), 1), np.sum(C * PG2, 1)], axis=1)
    A = np.stack([np.ones_like(tr), -tr, det], axis=1)
    return B, A


def smallwood_coefficients(fn, zeta: float, fs: float):
    """Smallwood's (1981) absolute-acceleration recursion coefficients (b, a), for comparison."""
    w = 2 * np.pi * np.atleast_1d(np.asarray(fn, float))
    T = 1.0 / fs
    E = np.exp(-zeta * w * T)
    K = w * np.sqrt(1 - zeta ** 2) * T
    C, S = E * np.cos(K), E * np.sin(K)
    Sp = S / K
    return (np.stack([1 - Sp, 2 * (Sp - C), E ** 2 - Sp], axis=1),
            np.stack([np.ones_like(C), -2 * C, E ** 2], axis=1))


def _fn_grid(fn, fs, octave):
    if fn is None:
        hi = fs / 4
        lo = max(fs / 2 ** 14, 1.0) if hi > 1.0 else hi / 100
        n = int(np.floor(np.log2(hi / lo) / octave)) + 1
        return lo * 2 ** (octave * np.arange(n))
    f = np.atleast_1d(np.asarray(fn, float))
    if f.ndim != 1 or f.size == 0 or not np.all(np.isfinite(f)) or np.any(f <= 0):
        raise ParameterError(f"fn must be positive finite natural frequencies (Hz), got {fn!r}")
    if np.any(f >= fs / 2):
        raise ParameterError(f"fn reaches {f.max():g} Hz; natural frequencies must stay below fs/2 = {fs / 2:g} Hz "
                             "(better below fs/10 for the input's own content)")
    return np.sort(f)


def _damping(zeta, Q):
    if Q is not None:
        if zeta is not None:
            raise ParameterError("give zeta or Q, not both (Q = 1 / (2 zeta))")
        return 1.0 / (2.0 * positive(Q, "Q"))
    z = 0.05 if zeta is None else positive(zeta, "zeta", allow_zero=True)
    if z >= 1:
        raise ParameterError(f"zeta={z} must be below 1 (an oscillator)")
    return z


def _as_acceleration(rec: Record, idx: int, what: str):
    """The input as base acceleration in m/s^2: acceleration channels are converted (g, in/s^2);
    velocity or displacement inputs are refused with the conversion to use."""
    ch = rec.channels[idx]
    if ch.quantity in ("velocity", "displacement"):
        raise ParameterError(f"{what}: channel {ch.name!r} is a {ch.quantity} ({ch.unit}); the shock response spectrum "
                             "needs the base acceleration: convert it first (vm.differentiate(rec) once for "
                             "velocity, twice for displacement)")
    if ch.quantity not in ("acceleration", "unknown", ""):
        raise ParameterError(f"{what}: channel {ch.name!r} is a {ch.quantity}; the shock response spectrum needs the "
                             "base acceleration")
    x = clean_signal(rec, idx, what=what)
    if ch.quantity == "acceleration" and ch.unit:
        return _units.convert(x, ch.unit, "m/s^2"), ch.unit
    return x, ch.unit or ""


def _extremes(y):
    """Largest positive and negative values of y, each refined by a parabola through its samples."""
    out = []
    for i, sign in ((int(np.argmax(y)), 1.0), (int(np.argmin(y)), -1.0)):
        top = sign * y[i]
        if 0 < i < y.size - 1:
            a, c = sign * y[i - 1], sign * y[i + 1]
            den = a - 2 * top + c
            if den < 0:
                top -= (c - a) ** 2 / (8 * den)
        out.append(max(top, 0.0))
    return out


def _step_maps(f, zeta, fs, output, J):
    """C and, per fraction tau = j T / J of a step (j = 1 .. J, the last the whole step), the row vectors
    giving the output at k T + tau from the state at k T, the input u_k and the increment u_k+1 - u_k
    (the input linear over the step, as the filter takes it)."""
    from scipy.linalg import expm
    T = 1.0 / fs
    w = 2 * np.pi * f
    M = np.zeros((4, 4))
    M[0, 1], M[1, 0], M[1, 1], M[1, 2], M[2, 3] = 1.0, -w * w, -2 * zeta * w, -1.0, 1.0 / T
    C = np.array([-w * w, -2 * zeta * w]) if output == "acceleration" else np.array([1.0, 0.0])
    E = expm(M[None] * (np.arange(1, J + 1) * T / J)[:, None, None])
    return C, C @ E[:, :2, :2], E[:, :2, 2] @ C, E[:, :2, 3] @ C     # (2,), (J, 2), (J,), (J,)


def _between_samples(y, u, maps, per, lo, hi):
    """Extremes of the response between the samples of y[lo:hi], the exact response of the filter's
    input (linear between samples), where an oscillator has fewer than PTS_PER_CYCLE samples a cycle.
    Only intervals next to a sample within cos(pi / P) (P samples a cycle), less a margin, of the
    sampled extreme can hold the true one; each is evaluated at PTS_PER_CYCLE points a cycle and the
    best refined by a parabola (as an oscillator that is sampled finely enough)."""
    out = []
    seg = y[lo:hi]
    reach = np.cos(np.pi / per) * REACH_MARGIN
    for sign, best in ((1.0, float(seg.max())), (-1.0, -float(seg.min()))):
        # no signed copy of the record: compare the samples with the signed limit directly
        k = lo + np.flatnonzero(seg >= best * reach if sign > 0 else seg <= -best * reach)
        k = np.unique(np.concatenate([k - 1, k]))
        k = k[(k >= lo) & (k + 1 < min(hi, y.size))]
        if k.size:
            out.append(max(best, _interval_max(sign, y, u, k, maps)))
        else:
            out.append(best)
    return [max(v, 0.0) for v in out]


def _interval_max(sign, y, u, k, maps):
    """The largest of sign * response over the steps after samples k (sorted), from the states there:
    J points a step, in time order along each run of consecutive steps, the best refined by a parabola
    through its neighbours (across a sample as well: a step's first point is that sample)."""
    C, CP, Cg0, Cg1 = maps
    # the state at sample k from y_k and y_k+1: [C; C Phi] s_k = [y_k; y_k+1 - C G0 u_k - C G1 (u_k+1 - u_k)]
    du = u[k + 1] - u[k]
    s = np.linalg.solve(np.vstack([C, CP[-1]]), np.vstack([y[k], y[k + 1] - Cg0[-1] * u[k] - Cg1[-1] * du]))
    fine = CP[:-1] @ s + Cg0[:-1, None] * u[k] + Cg1[:-1, None] * du    # (J - 1, K) between the samples
    steps = np.vstack([y[k], fine]) * sign                              # (J, K): from each sample on
    pieces = []
    for run in np.split(np.arange(k.size), np.flatnonzero(np.diff(k) != 1) + 1):
        pieces += [steps[:, run].ravel(order="F"), [sign * y[k[run[-1]] + 1], -np.inf]]
    seq = np.concatenate(pieces)
    j = int(np.argmax(seq))
    top = float(seq[j])
    if 0 < j < seq.size - 1 and np.isfinite(seq[j - 1]) and np.isfinite(seq[j + 1]):
        a, c = seq[j - 1], seq[j + 1]
        den = a - 2 * top + c
        if den < 0:
            top -= (c - a) ** 2 / (8 * den)
    return top


def _oscillator(x_ext, n, B, A, f, zeta, fs, output, tail, k_end):
    """Primary and residual extremes (positive, negative) of one oscillator: the ramp-invariant filter
    on the record's own samples (exact there), then between the samples where they are too coarse."""
    from scipy.signal import lfilter
    n_tail = int(np.ceil(tail * fs)) + 2
    u = x_ext[:n + n_tail]
    y = lfilter(B, A, u)
    per = fs / f
    if per >= PTS_PER_CYCLE:
        return _extremes(y[:k_end + 1]), _extremes(y[k_end:])
    maps = _step_maps(f, zeta, fs, output, int(np.ceil(PTS_PER_CYCLE / per)))
    return _between_samples(y, u, maps, per, 0, k_end + 1), _between_samples(y, u, maps, per, k_end, y.size)


def srs(rec, *, fn=None, zeta: float | None = None, Q: float | None = None, kind: str = "maximax",
        output: str = "acceleration", channel=None, octave: float = 1 / 12, pulse_end: float | None = None,
        fs: float | None = None) -> ShockSpectrum:
    """Shock response spectrum of a base acceleration record.

    Each oscillator is the ramp-invariant recursive filter (Smallwood), exact at the samples for an
    input linear between them; oscillators above fs/32 run on a finer interpolated input, and peaks are
    refined between samples. All three kinds are computed and kept in ``values``.

    Parameters
    ----------
    rec : Record or array_like
        Base acceleration (g or in/s^2 are converted); velocity or displacement is refused.
    fn : array_like, optional
        Natural frequencies in Hz; default 1/``octave`` per octave from max(fs/16384, 1 Hz) to fs/4.
    zeta : float, optional
        Damping ratio of the oscillators (default 0.05).
    Q : float, optional
        Quality factor Q = 1/(2 zeta), instead of ``zeta``.
    kind : {"maximax", "primary", "residual"}
        The kind the command line shows first: largest peak at any time, during the pulse, or after it.
    output : {"acceleration", "pseudo_velocity", "relative_displacement"}
        Response quantity: absolute acceleration (input's unit), wn z (m/s) or z (m).
    channel : str or int, optional
        The acceleration channel (default the first that is not a force).
    octave : float
        Spacing of the default natural frequencies, in octaves.
    pulse_end : float, optional
        End of the pulse in s (primary before, residual after; default the record's end).
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    ShockSpectrum
        ``fn``, ``values`` (dict kind -> array), ``unit``, ``zeta``, ``input_peak``.

    Raises
    ------
    ParameterError
        For velocity or displacement input, both zeta and Q, or natural frequencies outside (0, fs/2).

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> t = np.arange(1000) / 20000.0
    >>> pulse = np.where(t < 0.002, 50.0 * np.sin(np.pi * t / 0.002), 0.0)
    >>> sp = vm.srs(vm.Record.from_array(pulse, fs=20000.0, unit="g"), Q=10)
    >>> bool(sp.values["maximax"].max() > 50.0)
    True
    """
    rec = as_record(rec, fs=fs)
    if kind not in KINDS:
        raise ParameterError(f"kind={kind!r} must be one of {KINDS}")
    if output not in OUTPUTS:
        raise ParameterError(f"output={output!r} must be one of {OUTPUTS}")
    octave = positive(octave, "octave")
    idx = response_channel(rec, channel)
    x, unit = _as_acceleration(rec, idx, "srs")
    z = _damping(zeta, Q)
    f = _fn_grid(fn, rec.fs, octave)
    filt = "acceleration" if output == "acceleration" else "relative_displacement"
    k_end = x.size - 1 if pulse_end is None else int(round(positive(pulse_end, "pulse_end") * rec.fs))
    if k_end > x.size - 1:
        raise ParameterError(f"pulse_end={pulse_end} s is after the record's end ({(x.size - 1) / rec.fs:g} s)")
    prim, resid = np.zeros((2, f.size)), np.zeros((2, f.size))
    B, A = srs_coefficients(f, z, rec.fs, filt)
    # the free vibration's positive and negative extrema follow each other half a damped period apart,
    # so both are within its first damped period (1/fd, fd = fn sqrt(1 - zeta^2)), plus margin
    tails = 1.25 / (f * np.sqrt(1.0 - z * z))
    x_ext = np.concatenate([x, np.zeros(int(np.ceil(tails.max() * rec.fs)) + 2)])
    for k, fk in enumerate(f):
        prim[:, k], resid[:, k] = _oscillator(x_ext, x.size, B[k], A[k], fk, z, rec.fs, filt, tails[k], k_end)
    scale = np.ones_like(f)
    known = bool(unit) and _units.quantity_of(unit) == "acceleration"
    out_unit = "m/s^2"
    if output == "pseudo_velocity":
        scale, out_unit = 2 * np.pi * f, "m/s"
    elif output == "relative_displacement":
        out_unit = "m"
    if not known:   # an input of unknown unit: the spectrum is in that unit (per s, s^2), not SI
        out_unit = ""
    elif output == "acceleration":
        scale = scale * _units.convert(1.0, "m/s^2", unit)
        out_unit = unit
    prim, resid = prim * scale, resid * scale
    values = {"maximax": np.maximum(prim.max(axis=0), resid.max(axis=0)), "primary": prim.max(axis=0),
              "residual": resid.max(axis=0)}
    values = {kind: values[kind], **{k: v for k, v in values.items() if k != kind}}
    extras = {"primary_positive": prim[0], "primary_negative": prim[1], "residual_positive": resid[0],
              "residual_negative": resid[1], "method": "ramp-invariant recursive filter (exact for a piecewise-linear input)",
              "points_per_cycle": PTS_PER_CYCLE, "q": 1 / (2 * z) if z > 0 else np.inf}
    peak_in = float(np.max(np.abs(x)))
    if known:
        peak_in = float(_units.convert(peak_in, "m/s^2", unit))
    return ShockSpectrum(f, values, output, out_unit, z, rec.channels[idx].name, peak_in, rec.duration, extras)


# --- transmissibility ---------------------------------------------------------------------------


def transmissibility(rec, *, base, top, model=None, nperseg: int | None = None, min_coherence: float = 0.95,
                     fs: float | None = None) -> Transmissibility:
    """Measured transmissibility from base and top responses, with coherence, against a model.

    H1 = G_base,top / G_base,base; base and top must be the same quantity (the ratio is then the same for
    acceleration, velocity or displacement).

    Parameters
    ----------
    rec : Record
        The record holding both channels.
    base, top : str or int
        The base (input) and top (output) channels.
    model : object, optional
        Anything with ``transmissibility(freq)`` (e.g. ``vm.models.SDOF``): its |T| is kept and the
        largest deviation |measured / model - 1| where coherence exceeds ``min_coherence`` and the base
        is excited goes to ``extras["max_deviation"]``.
    nperseg : int, optional
        Segment length of the cross-spectra.
    min_coherence : float
        Lines below it are left out of the comparison.
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    Transmissibility
        ``freq``, ``t`` (complex), ``coherence``, ``isolation_hz`` and ``extras``.

    Raises
    ------
    ParameterError
        For unknown channels or base and top of different quantities.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> iso = vm.models.SDOF(m=1.0, k=3948.0, zeta=0.05)
    >>> rec = vm.synth.base_excited(iso, fs=500.0, duration=60.0, seed=1)
    >>> tr = vm.transmissibility(rec, base="base", top="top", model=iso)
    >>> bool(abs(tr.isolation_hz - 10.0 * 2 ** 0.5) < 1.0)
    True
    """
    from scipy.signal import csd, welch
    rec = as_record(rec, fs=fs)
    ib, it = rec.index(base), rec.index(top)
    if ib == it:
        raise ParameterError(f"base={base!r} and top={top!r} name the same channel")
    qb, qt = rec.channels[ib].quantity, rec.channels[it].quantity
    if qb != qt and "unknown" not in (qb, qt):
        raise ParameterError(f"base is a {qb} and top a {qt}: transmissibility is a ratio of the same quantity "
                             "(convert one first: vm.integrate / vm.differentiate)")
    xb, xt = clean_signal(rec, ib, what="base"), clean_signal(rec, it, what="top")
    ub, ut = rec.channels[ib].unit, rec.channels[it].unit
    if ub and ut and ub != ut:
        xt = _units.convert(xt, ut, ub)
    n = xb.size
    if nperseg is None:
        nper = int(min(2 ** int(np.log2(max(n // 16, 64))), 2 ** 16, n // 2))
    elif isinstance(nperseg, bool) or not isinstance(nperseg, (int, np.integer)) or not 16 <= nperseg <= n // 2:
        raise ParameterError(f"nperseg={nperseg!r} must be an integer from 16 to half the record ({n // 2})")
    else:
        nper = int(nperseg)
    min_coherence = positive(min_coherence, "min_coherence")
    if min_coherence >= 1:
        raise ParameterError(f"min_coherence={min_coherence} must be between 0 and 1")
    f, Gbb = welch(xb, fs=rec.fs, nperseg=nper)
    _, Gtt = welch(xt, fs=rec.fs, nperseg=nper)
    _, Gbt = csd(xb, xt, fs=rec.fs, nperseg=nper)
    with np.errstate(invalid="ignore", divide="ignore"):
        T = Gbt / Gbb
        coh = np.abs(Gbt) ** 2 / (Gbb * Gtt)
    ok = f > 0
    f, T, coh, Gbb = f[ok], T[ok], np.nan_to_num(coh[ok]), Gbb[ok]
    extras = {"nperseg": nper, "min_coherence": float(min_coherence)}
    above = np.abs(T) >= 1
    # compared where the base is excited (PSD within 30 dB of its median: outside, the window's
    # leakage makes a coherent-looking but meaningless ratio) and coherence exceeds min_coherence
    good = (coh > min_coherence) & (Gbb >= 1e-3 * np.median(Gbb))
    extras["compared"] = good
    if above.any() and not above[-1]:
        k = int(np.flatnonzero(above)[-1])
        extras["isolation_hz"] = float(f[k] + (f[k + 1] - f[k]) * (abs(T[k]) - 1) / (abs(T[k]) - abs(T[k + 1])))
    model_T = None
    if model is not None:
        if not hasattr(model, "transmissibility"):
            raise ParameterError(f"model must have a transmissibility(freq) method (vm.models.SDOF), got "
                                 f"{type(model).__name__}")
        model_T = np.abs(np.asarray(model.transmissibility(f), float))
        dev = np.abs(np.abs(T) / model_T - 1)
        extras["max_deviation"] = float(dev[good].max()) if good.any() else np.nan
        extras["lines_compared"] = int(good.sum())
        fn_model = getattr(model, "fn", None)
        if fn_model is not None:
            extras["model_isolation_hz"] = float(np.sqrt(2) * fn_model)
            extras["isolation_rule"] = "isolation (|T| < 1) where r = f/fn > sqrt(2)"
    return Transmissibility(f, T, coh, rec.names[ib], rec.names[it], model_T, extras)
