"""FRF estimation: H1, H2 and Hv from random or impact excitation, with coherence and random error.

The cross-spectral sums come from the same blocked engine as vm.psd (so H1 and the coherence equal
what scipy.signal.csd/welch give for the same segments). Impact tests are cut into one record per
hit; a force window keeps the pulse and an exponential window (on force and response alike, so
the estimate is exactly the FRF of the system with every pole moved left by 1/tau) tames leakage;
fit_modes then removes that added damping exactly.
"""

from __future__ import annotations

import numpy as np

from ..core._validate import as_record
from ..core.errors import ParameterError, warn_quality
from ..core.record import Record
from ..core.results import FRF, form_of
from ..signal.segments import segment_sums
from ..signal.spectral import check_segment_params, get_window
from ._decay import clipped_mask

__all__ = ["estimate_frf", "impact_frf", "find_hits", "form_of"]

DOUBLE_HIT = 0.2   # a second pulse above 20 % of the first after it has ended is a double hit


def _io(rec: Record, input, outputs):
    if input is None:
        raise ParameterError("input is required: a channel name, or 'force' for the force channel(s)")
    ins = [input] if isinstance(input, (str, int)) else list(input)
    if ins == ["force"] and "force" not in rec.names:
        ins = [c.name for c in rec.channels if c.quantity == "force"]
        if not ins:
            raise ParameterError(f"input='force' but no channel of {rec.names} has quantity 'force'; name the "
                                 "input channel or read the file with its quantities")
    ii = [rec.index(c) for c in ins]
    for i in ii:
        c = rec.channels[i]
        if c.quantity not in ("force", "unknown", "voltage"):
            raise ParameterError(f"input channel {c.name!r} measures {c.quantity}, not force: an FRF divides "
                                 "response by force")
    if outputs is None:
        oo = [i for i in range(rec.n_channels) if i not in ii]
    else:
        oo = [rec.index(c) for c in ([outputs] if isinstance(outputs, (str, int)) else outputs)]
    if not oo:
        raise ParameterError("no output channel: the record holds only the input(s)")
    if set(oo) & set(ii):
        raise ParameterError("a channel cannot be both input and output")
    _check_inputs(rec, ii)
    return ii, oo


def _check_inputs(rec: Record, ii):
    """A force channel must excite: not dead (zero or constant), not NaN/inf; several inputs must not
    be copies of each other (the input matrix would be singular). Clipping is flagged by impact_frf."""
    from ..core._validate import clean_signal
    xs = []
    for i in ii:
        name = rec.channels[i].name
        if not np.any(rec.data[i]):
            raise ParameterError(f"input channel {name!r} is all zeros: a dead force channel (check the hammer or "
                                 "shaker cable); no FRF can be formed")
        x = clean_signal(rec, i, min_samples=16, what="input")   # NaN/inf and constant are refused here
        xs.append(x - x.mean())
    if len(xs) > 1:
        c = np.corrcoef(np.vstack(xs))
        off = np.abs(c[~np.eye(len(xs), dtype=bool)])
        if off.max() > 0.9999:
            raise ParameterError("two input channels are identical (correlation > 0.9999): the input cross-spectral "
                                 "matrix is singular; a MIMO FRF needs independent excitations")


def _h_from_sums(Gxx, Gyx, Gyy, estimator, n_in):
    """H (n_out, n_in, nf), coherence (n_out, nf) from averaged spectral sums."""
    n_out, nf = Gyy.shape
    if estimator == "H1":
        if n_in == 1:
            with np.errstate(invalid="ignore", divide="ignore"):
                H = (Gyx[:, 0] / Gxx[0, 0])[:, None]
        else:
            H = np.einsum("oif->fio", Gyx)  # (nf, n_in, n_out) for the solve
            Gxx_f = np.transpose(Gxx, (2, 1, 0))  # (nf, j, i): solve X^T
            # H Gxx = Gyx  ->  Gxx^T H^T = Gyx^T
            H = np.linalg.solve(Gxx_f, H)
            H = np.transpose(H, (2, 1, 0))
    else:
        if n_in != 1:
            raise ParameterError(f"estimator={estimator!r} needs a single input; with {n_in} inputs use 'H1'")
        gxx, gyx = Gxx[0, 0], Gyx[:, 0]
        if estimator == "H2":
            H = (Gyy / gyx.conj())[:, None]
        else:  # Hv: total least squares, equal noise on input and output
            d = Gyy - gxx.real
            root = np.sqrt(d ** 2 + 4 * np.abs(gyx) ** 2)
            # (d + root) / (2 conj(Gyx)), written without cancellation for d < 0: 2 Gyx / (root - d)
            with np.errstate(invalid="ignore", divide="ignore"):
                H = np.where(d >= 0, (d + root) / (2 * gyx.conj()), 2 * gyx / (root - d))[:, None]
    with np.errstate(invalid="ignore", divide="ignore"):
        if n_in == 1:
            coh = np.abs(Gyx[:, 0]) ** 2 / (Gxx[0, 0].real * Gyy)
        else:  # multiple coherence: Gyx Gxx^-1 Gxy / Gyy
            Gxx_f = np.transpose(Gxx, (2, 0, 1))
            g = np.transpose(Gyx, (2, 0, 1))  # (nf, n_out, n_in)
            sol = np.linalg.solve(Gxx_f, np.conj(np.transpose(g, (0, 2, 1))))  # Gxx^-1 Gxy
            coh = np.real(np.einsum("foi,fio->fo", g, sol)).T / Gyy
    coh = np.clip(np.where(np.isfinite(coh), coh.real, 0.0), 0.0, 1.0)
    # lines the input did not excite carry no information: NaN, not a number made of noise
    power_in = np.real(np.einsum("iif->f", Gxx))
    dead = power_in <= 1e-12 * power_in.max()
    if dead.any():
        H = H.copy()
        H[..., dead] = np.nan
        coh[:, dead] = 0.0
    return H, coh


def _random_error(coh, n_avg):
    with np.errstate(divide="ignore", invalid="ignore"):
        e = np.sqrt(1 - coh) / (np.sqrt(coh) * np.sqrt(2 * n_avg))
    return np.where(np.isfinite(e), e, np.inf)


def estimate_frf(rec, *, input="force", outputs=None, estimator: str = "H1", nperseg: int | None = None,
                 noverlap: int | None = None, window="hann", detrend="constant", fs: float | None = None,
                 progress=None) -> FRF:
    """FRFs from input (force) and output records by segment averaging.

    Parameters
    ----------
    rec : Record
        Force and responses.
    input : str, int or list
        The input (force) channel(s); "force" takes the channel whose quantity is force.
    outputs : str, int or list, optional
        Output channels (default every other channel).
    estimator : {"H1", "H2", "Hv"}
        H1 (noise on the output; MIMO by Gyx Gxx^-1), H2 (noise on the input) or Hv (both; one input).
    nperseg, noverlap : int, optional
        Segment length and overlap.
    window : str, tuple or array_like
        Window.
    detrend : {"constant", "linear", False}
        What each segment loses first.
    fs : float, optional
        Sampling rate for an array.
    progress : callable, optional
        ``progress(fraction)`` as blocks finish.

    Returns
    -------
    FRF
        Form from the output quantity, with ordinary (one input) or multiple coherence and the
        normalised random error sqrt(1 - coh) / (sqrt(coh) sqrt(2 n_avg)).

    Raises
    ------
    ParameterError
        For unknown channels, bad parameters or fewer than 2 averages.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> f = np.random.default_rng(1).normal(size=16384)
    >>> x = vm.synth.modal_response(f, fs=1024.0, fn=[50.0], zeta=[0.02], shapes=[[1.0]])
    >>> rec = vm.Record(np.vstack([f, x]), fs=1024.0, channels=[vm.Channel("force", "force", "N"),
    ...                                                          vm.Channel("x", "displacement", "m")])
    >>> frf = vm.estimate_frf(rec, nperseg=2048)
    >>> frf.form
    'receptance'
    """
    rec = as_record(rec, fs=fs)
    if estimator not in ("H1", "H2", "Hv"):
        raise ParameterError(f"estimator={estimator!r} must be 'H1', 'H2' or 'Hv'")
    ii, oo = _io(rec, input, outputs)
    sweep = _is_sweep(rec.data[ii[0]], rec.fs) if len(ii) == 1 else None
    if sweep is not None and nperseg is None:
        return _sweep_frf(rec, ii, oo, sweep)
    if sweep is not None:
        warn_quality(f"estimate_frf: the input is a swept sine ({sweep[0]:.4g} -> {sweep[1]:.4g} Hz): each of the "
                     f"nperseg={nperseg} segments sees a part of the sweep and the ring-down of the parts before, "
                     "which biases H (damping high, spurious peaks); leave nperseg unset for the one-block "
                     "estimate a sweep needs", stacklevel=2)
    nperseg, noverlap, nfft = check_segment_params(rec.n_samples, nperseg, noverlap, None, detrend, "mean",
                                            min(rec.n_samples // 4, 4096) or 2)
    win = get_window(window, nperseg)
    idx = ii + oo
    n_in, n_out = len(ii), len(oo)
    pairs = [(a, b) for a in range(n_in) for b in range(n_in)] + \
            [(n_in + o, a) for o in range(n_out) for a in range(n_in)]

    class _Src:  # the record seen by the engine
        fs, channels, n_samples, n_channels = rec.fs, rec.channels, rec.n_samples, rec.n_channels

        @staticmethod
        def read(a, b):
            return rec.data[:, a:b]
    autos, cross, nseg, _ = segment_sums(_Src, idx, nperseg=nperseg, noverlap=noverlap, nfft=nfft, win=win,
                                          detrend=detrend, pairs=pairs, progress=progress)
    if nseg < 2:
        raise ParameterError(f"nperseg={nperseg} gives {nseg} average: coherence and H need at least 2; "
                             "use a shorter nperseg or a longer record")
    nf = nfft // 2 + 1
    Gxx = cross[: n_in * n_in].reshape(n_in, n_in, nf) / nseg
    Gyx = cross[n_in * n_in:].reshape(n_out, n_in, nf) / nseg
    Gyy = autos[n_in:] / nseg
    H, coh = _h_from_sums(Gxx, Gyx, Gyy, estimator, n_in)
    outs = [rec.channels[i] for i in oo]
    forms = {form_of(c.quantity) for c in outs}
    form = forms.pop() if len(forms) == 1 else "unknown"
    err = np.broadcast_to(_random_error(coh, nseg)[:, None, :], H.shape).copy()
    unit = _frf_unit(outs, rec.channels[ii[0]])
    return FRF(np.fft.rfftfreq(nfft, 1 / rec.fs), H, form, coh, estimator, tuple(c.name for c in outs),
               tuple(rec.channels[i].name for i in ii), unit, err,
               {"window": window, "nperseg": nperseg, "noverlap": noverlap, "n_averages": nseg, "fs": rec.fs,
                "detrend": detrend})


SWEEP_SEGMENTS = 16     # the force's spectral centroid followed over this many blocks
SWEEP_RANK = 0.95       # a sweep's centroid moves monotonically: |Spearman rank correlation with time| above this
SWEEP_NARROW = 0.35     # and each block's spectral spread is below this share of the whole record's


def _is_sweep(force, fs: float):
    """(f_start, f_end) in Hz when the force is a swept sine, else None: over SWEEP_SEGMENTS blocks
    the force's spectral centroid moves monotonically (rank correlation with time above SWEEP_RANK)
    while each block is narrow-band (spread below SWEEP_NARROW of the whole record's). Random,
    periodic-chirp and impact forces have the same spectrum in every block."""
    from scipy.stats import spearmanr
    x = np.asarray(force, float)
    n = x.size // SWEEP_SEGMENTS
    if n < 64 or np.ptp(x) == 0:
        return None
    blocks = (x[: n * SWEEP_SEGMENTS] - np.mean(x)).reshape(SWEEP_SEGMENTS, n) * np.hanning(n)
    p = np.abs(np.fft.rfft(blocks, axis=1)) ** 2
    f = np.fft.rfftfreq(n, 1 / fs)
    tot = p.sum(axis=1)
    live = tot > 1e-3 * tot.max()
    if live.sum() < SWEEP_SEGMENTS // 2:
        return None
    c = (p[live] @ f) / tot[live]
    spread = np.sqrt(np.maximum((p[live] @ f ** 2) / tot[live] - c ** 2, 0.0))
    pa = p[live].sum(axis=0)
    ca = pa @ f / pa.sum()
    spread_all = np.sqrt(max(pa @ f ** 2 / pa.sum() - ca ** 2, 0.0))
    rho = spearmanr(np.arange(c.size), c)[0]
    if not (np.isfinite(rho) and abs(rho) > SWEEP_RANK and np.median(spread) < SWEEP_NARROW * spread_all):
        return None
    return float(c[0]), float(c[-1])


def _sweep_frf(rec, ii, oo, sweep):
    """A swept sine's FRF as one block: the ratio of the whole record's spectra, H = Y X* / |X|^2,
    rectangular window (the sweep starts and ends in the record). Lines outside the sweep's range (the
    force 30 dB under its peak power) are NaN. No averages: coherence and random error are
    not estimated (NaN), and the FRF carries the flag swept_sine."""
    from ..core._validate import clean_signal
    for o in oo:   # the outputs obey the rule the segment path applies: finite, not constant
        clean_signal(rec, o, min_samples=16, what="output")
    x = rec.data[ii[0]] - np.mean(rec.data[ii[0]])
    X = np.fft.rfft(x)
    Y = np.fft.rfft(rec.data[oo] - np.mean(rec.data[oo], axis=1, keepdims=True), axis=1)
    px = np.abs(X) ** 2
    k = np.flatnonzero(px > 1e-3 * px.max())   # the sweep's range: its ends' ripples dip inside it
    ok = np.zeros(px.size, bool)
    ok[k[0]:k[-1] + 1] = True
    ok &= px > 1e-12 * px.max()
    H = np.full((len(oo), 1, X.size), np.nan, complex)
    H[:, 0, ok] = Y[:, ok] * np.conj(X[ok]) / px[ok]
    outs = [rec.channels[i] for i in oo]
    forms = {form_of(c.quantity) for c in outs}
    nan = np.full((len(oo), X.size), np.nan)
    return FRF(np.fft.rfftfreq(x.size, 1 / rec.fs), H, forms.pop() if len(forms) == 1 else "unknown", nan, "H1",
               tuple(c.name for c in outs), (rec.channels[ii[0]].name,), _frf_unit(outs, rec.channels[ii[0]]),
               np.full(H.shape, np.nan),
               {"window": "boxcar", "nperseg": x.size, "noverlap": 0, "n_averages": 1, "fs": rec.fs,
                "sweep_hz": list(sweep), "flags": ("swept_sine",)})


MAX_BUSY = 0.05   # an impact record's force is near zero except in its pulses: above 5 % it is continuous


def find_hits(force, fs: float, *, threshold: float = 0.1, min_gap_s: float | None = None) -> np.ndarray:
    """Sample indices where hammer hits start: rising crossings of ``threshold`` x the largest peak.

    Parameters
    ----------
    force : array_like
        The force samples.
    fs : float
        Sampling rate in Hz.
    threshold : float
        Share of the largest peak a hit must cross.
    min_gap_s : float, optional
        Least time between two hits (default 0.1 s).

    Returns
    -------
    numpy.ndarray
        Start indices.

    Raises
    ------
    ParameterError
        For a constant or non-finite force.

    Examples
    --------
    >>> import numpy as np
    >>> import vibmeasure as vm
    >>> f = np.zeros(3000)
    >>> f[[500, 2000]] = 100.0
    >>> vm.find_hits(f, 1000.0).tolist()
    [500, 2000]
    """
    f = np.asarray(force, float)
    if not np.isfinite(f).all():
        raise ParameterError("the force channel has NaN/inf samples")
    if not 0 < threshold < 1:
        raise ParameterError(f"threshold={threshold} must be between 0 and 1 (fraction of the largest peak)")
    base = np.median(f)
    a = np.abs(f - base)
    peak = a.max()
    if peak == 0:
        raise ParameterError("the force channel is constant: no hit")
    above = a > threshold * peak
    starts = np.flatnonzero(above[1:] & ~above[:-1]) + 1
    if above[0]:
        starts = np.r_[0, starts]
    gap = int(round((0.1 if min_gap_s is None else min_gap_s) * fs))
    hits = []
    for s in starts:
        if not hits or s - hits[-1] >= gap:
            hits.append(s)
    return np.asarray(hits, int)


def _frf_unit(outs, force) -> str:
    """Unit of H: the outputs' common unit over the force's ('m/s^2/N'); '' when either is unknown."""
    units = {c.unit for c in outs}
    return f"{outs[0].unit}/{force.unit}" if len(units) == 1 and outs[0].unit and force.unit else ""


def impact_frf(rec, *, input="force", outputs=None, record_length: float | None = None,
               pretrigger: float = 0.005, exp_window="auto", force_window: bool = True, estimator: str = "H1",
               threshold: float = 0.1, fs: float | None = None) -> FRF:
    """FRFs from a hammer test: one record per hit, averaged (H1 by default).

    Each hit starts ``pretrigger`` s before the force crosses ``threshold`` of its peak. The force
    window keeps the pulse (zero beyond twice its duration); the exponential window exp(-t/tau) is
    applied to force and response, so each pole moves left by exactly 1/tau; the FRF carries tau and
    fit_modes removes it. Double hits and clipping are flagged (params["flags"], QualityWarning).

    Parameters
    ----------
    rec : Record
        Force and responses of all hits.
    input : str or int
        The force channel ("force": the channel whose quantity is force).
    outputs : str, int or list, optional
        Output channels (default every other channel).
    record_length : float, optional
        Seconds per hit (default up to the next hit, at most the shortest spacing).
    pretrigger : float
        Seconds kept before the trigger.
    exp_window : "auto", float or None
        "auto": 1 % at the record end; a number: tau in s; None: off.
    force_window : bool
        Zero the force beyond twice the pulse's duration.
    estimator : {"H1", "H2", "Hv"}
        As in ``estimate_frf``.
    threshold : float
        Share of the largest force peak a hit must cross.
    fs : float, optional
        Sampling rate for an array.

    Returns
    -------
    FRF

    Raises
    ------
    ParameterError
        For no hit, unknown channels or a record too short for one hit.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> hammer = vm.synth.hammer_test(fn=[21.3, 57.9], zeta=[0.01, 0.02], shapes=[[1.0, 0.5]], fs=1024.0, seed=1)
    >>> vm.impact_frf(hammer, input="hammer").params["n_averages"]
    3
    """
    rec = as_record(rec, fs=fs)
    ii, oo = _io(rec, input, outputs)
    if len(ii) != 1:
        raise ParameterError("impact_frf takes one force input (the hammer)")
    force = rec.data[ii[0]]
    hits = find_hits(force, rec.fs, threshold=threshold)
    pre = _check_impact(rec, force, hits, pretrigger, threshold)
    starts, n = _hit_records(rec, hits, pre, record_length)
    tau, ew = _exponential_window(n, pre, rec.fs, exp_window)
    sums, double, clipped = _hit_sums(rec, force, ii[0], oo, starts, n, pre, ew, force_window)
    flags = (["double_hit"] if double else []) + (["clipped"] if clipped else [])
    H, coh = _h_from_sums(sums[0][None, None].astype(complex), sums[1][:, None], sums[2], estimator, 1)
    navg = starts.size
    if navg < 2:
        coh = np.ones_like(coh)  # a single hit gives no coherence estimate
        flags.append("single_average")
    outs = [rec.channels[i] for i in oo]
    forms = {form_of(c.quantity) for c in outs}
    err = np.broadcast_to(_random_error(coh, navg)[:, None, :], H.shape).copy()
    frf = FRF(np.fft.rfftfreq(n, 1 / rec.fs), H, forms.pop() if len(forms) == 1 else "unknown", coh, estimator,
              tuple(c.name for c in outs), (rec.channels[ii[0]].name,), _frf_unit(outs, rec.channels[ii[0]]), err,
              {"window": "force+exponential" if tau else ("force" if force_window else "boxcar"), "nperseg": n,
               "n_averages": int(navg), "fs": rec.fs, "exp_window_tau_s": tau, "hits_s": (starts + pre) / rec.fs,
               "double_hits": double, "flags": tuple(flags)})
    if flags and flags != ["single_average"]:
        warn_quality(f"impact_frf: {', '.join(flags)}" + (f" (hits {double})" if double else ""), stacklevel=3)
    return frf


def _check_impact(rec, force, hits, pretrigger, threshold) -> int:
    """The pre-trigger in samples, after the checks: a number of seconds under half the record, and a
    force that is a train of short pulses (not continuous excitation)."""
    try:
        pretrigger = float(pretrigger)
    except (TypeError, ValueError):
        raise ParameterError(f"pretrigger={pretrigger!r} must be a number of seconds") from None
    if not (np.isfinite(pretrigger) and 0 <= pretrigger < rec.duration / 2):
        raise ParameterError(f"pretrigger={pretrigger!r} s must be >= 0 and shorter than half the record "
                             f"({rec.duration / 2:g} s)")
    busy = float(np.mean(np.abs(force - np.median(force)) > threshold * np.max(np.abs(force - np.median(force)))))
    if busy > MAX_BUSY:
        raise ParameterError(f"not an impact test: the force exceeds {threshold:.0%} of its peak in {busy:.0%} of the "
                             f"samples, where hammer pulses last a few ms per hit (at most {MAX_BUSY:.0%}); for "
                             "continuous (shaker, random) excitation use vm.estimate_frf")
    pre = int(round(pretrigger * rec.fs))
    return min(pre, int(hits[0]))  # a hit at the very start leaves less pre-trigger


def _hit_records(rec, hits, pre, record_length):
    """Start samples of the hits' records and their length n (default: the shortest spacing)."""
    spacing = np.diff(hits)
    if record_length is None:
        n = int(spacing.min()) if spacing.size else rec.n_samples - (hits[0] - pre)
    else:
        n = int(round(record_length * rec.fs))
    starts = hits - pre
    starts = starts[(starts >= 0) & (starts + n <= rec.n_samples)]
    if starts.size == 0:
        raise ParameterError(f"no hit has {n} samples after it (record_length={n / rec.fs:g} s): shorten it")
    if n < 16:
        raise ParameterError(f"record_length gives {n} samples per hit: too short")
    return starts, n


def _exponential_window(n, pre, fs, exp_window):
    """(tau, window): exp(-t/tau) from the hit on (1 % at the record end for "auto"), or none."""
    if exp_window is None:
        return None, np.ones(n)
    t = np.arange(n) / fs
    tau = (t[-1] / np.log(100.0)) if exp_window == "auto" else float(exp_window)
    if not np.isfinite(tau) or tau <= 0:
        raise ParameterError(f"exp_window={exp_window!r} must be 'auto', None or a time constant > 0 s")
    return tau, np.exp(-np.clip(t - pre / fs, 0, None) / tau)


def _hit_sums(rec, force, i_force, oo, starts, n, pre, ew, force_window):
    """Sums over the hits of |X|^2, Y conj(X) and |Y|^2 (force and exponential windows applied),
    the hits with a double hit, and whether any record is clipped."""
    nf = n // 2 + 1
    Sxx, Syx, Syy = np.zeros(nf), np.zeros((len(oo), nf), complex), np.zeros((len(oo), nf))
    double, clipped = [], False
    for k, s in enumerate(starts):
        fseg = force[s:s + n] - np.median(force[s:s + max(pre, 1)]) if pre > 0 else force[s:s + n].copy()
        a = np.abs(fseg)
        ip = int(np.argmax(a))
        low = a < 0.05 * a[ip]
        pe = ip + (int(np.argmax(low[ip:])) if low[ip:].any() else n - ip)  # pulse end
        ps = ip - (int(np.argmax(low[ip::-1])) if low[ip::-1].any() else ip)  # pulse start
        dur = max(pe - ps, 1)
        after = a[pe + dur:]
        if after.size and after.max() > DOUBLE_HIT * a[ip]:
            double.append(k)
        if clipped_mask(rec.data[i_force, s:s + n]).any() or any(clipped_mask(rec.data[o, s:s + n]).any() for o in oo):
            clipped = True
        if force_window:  # keep the pulse (and the pre-trigger), zero what follows: noise, not force
            fseg = fseg.copy()
            fseg[min(n, pe + dur):] = 0.0
        X = np.fft.rfft(fseg * ew)
        Sxx += np.abs(X) ** 2
        for j, o in enumerate(oo):
            Y = np.fft.rfft((rec.data[o, s:s + n] - np.mean(rec.data[o, s:s + max(pre, 1)])) * ew)
            Syx[j] += Y * X.conj()
            Syy[j] += np.abs(Y) ** 2
    return (Sxx, Syx, Syy), double, clipped
