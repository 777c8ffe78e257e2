"""Step: the supply's lines (mains pickup, the motor's electromagnetic force) found and fitted, so that
shaft-order faults are judged without them (``supply_lines``)."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .lines import LINE_DB, _refine

# Mains pickup (a ground loop, a cable beside a motor lead) puts a comb at the line frequency and its
# harmonics into many recordings. Taken for a shaft, a 50 Hz comb at 0.3 x the record's RMS contradicted
# every declared speed of synthetic bearing faults at 1797, 2100 and 2250 rpm (12 / 12 records said
# "none", nothing checked). A line within MAINS_TOL (the grid holds about +-0.2 Hz) plus half a line of
# 50 or 60 Hz (or of the declared ``line_frequency``), or of twice that (the motor's electromagnetic
# force), is not taken for a 1X, nor for a shaft that contradicts the declared speed; a shaft turning at
# exactly the line frequency then relies on the declared speed.
MAINS_TOL = 0.004


def _at_mains(fc: float, df: float, mains=(50.0, 60.0)) -> bool:
    """Whether a line at fc stands at a line frequency or twice it (see MAINS_TOL)."""
    return any(abs(fc - k * m) <= MAINS_TOL * k * m + 0.5 * df for m in mains for k in (1, 2))


# The supply's lines are looked for up to the top of the ISO velocity band.
MAINS_TOP_HZ = 1000.0
MAINS_DRIFT = 2e-4   # the supply's frequency wanders about this share within a record (0.01 Hz at 50 Hz)


def _mains_lines(f, A, f1, mains) -> tuple[list, list]:
    """The lines the supply put into the spectrum A (Hann): (their frequencies, the shaft orders beside
    them to be fitted with them, ``_supply_part``).

    For each line frequency m in ``mains``, a line standing LINE_DB above the floor beside it (3-200
    lines off) within MAINS_TOL (plus half a line) of one of the harmonics k0 x m, k0 = 1-3, fixes the
    supply's actual frequency m' (the grid drifts, its harmonics with it); the comb is the line nearest
    each harmonic k x m' up to MAINS_TOP_HZ, within 0.75 line plus MAINS_DRIFT. A line closer to k x m'
    than to every shaft order and half order, and further from the order than its uncertainty
    (``_electrical``), is the supply's own. One closer to a shaft order is the supply's and the shaft's
    both: the supply's harmonic and that order are fitted together when they are half a line apart or
    more (closer, the line is left to the shaft). A comb holds a line at m' or 2 m', and two lines of
    the supply's own or one at m' or 2 m'; of the combs, the one with the most lines of its own.
    (Without the line at m' or 2 m', lines of the CWRU rig at 150.4, 551.5 and 701.9 Hz made a 50.13 Hz
    comb on its 60 Hz supply.)

    A supply frequency that is a shaft order (or half order) j x f1 to within a quarter of a line times
    j (f1, measured from the 1X line, is known to about a quarter of a line), plus a quarter of a line
    over k0 (m' comes from the k0-th harmonic), makes no comb: its lines are the shaft's as much. (A
    healthy synthetic machine with strong shaft-rate impacts at 1797 rpm, its 1X measured 0.15 line low,
    had its 4X-32X taken for a 59.9 Hz supply's comb, and 2X alone was left for misalignment.)

    Mains pickup is no vibration of the shaft, and the motor's electromagnetic force at twice the line
    frequency is none either. Taken for the shaft's, a 50 or 60 Hz comb at 0.3 x the RMS added to the
    fan-end development records raised the velocity that gates shaft-order faults and stood in for 2X:
    7 wrong calls (looseness, misalignment) on 106 records (benchmarks/diagnosis_robustness.py). At
    1797 rpm 60 Hz is 2X + 0.1 Hz, 0.6 of a line on 6 s: there the comb is found from its higher
    harmonics (120 Hz is 4X + 0.2 Hz, 180 Hz 6X + 0.3 Hz) and its 60 Hz line fitted beside 2X."""
    df = f[1]
    top = min(MAINS_TOP_HZ, f[-1] - 210 * df)
    half = 0.5 * f1

    def standing(fm, tol):
        lo, hi = max(4, int(np.floor((fm - tol) / df))), int(np.ceil((fm + tol) / df))
        for i in range(lo, hi + 1):
            if A[i] >= A[i - 1] and A[i] > A[i + 1]:
                floor = np.median(np.r_[A[max(1, i - 200): i - 3], A[i + 4: i + 201]])
                if A[i] >= 10 ** (LINE_DB / 20) * floor:
                    fc = _refine(f, A, f[i])
                    if abs(fc - fm) <= tol:
                        yield fc

    lines, beside = [], []
    for m in mains:
        best = ([], [])
        for k0 in (1, 2, 3):
            if k0 * m > top:
                break
            for fc0 in standing(k0 * m, MAINS_TOL * k0 * m + 0.5 * df):
                m_act = fc0 / k0
                q = max(1, round(m_act / half))   # the shaft's comb nearest to the supply's: q half orders
                coincide = abs(m_act - q * half) <= 0.25 * df * (max(1.0, 0.5 * q) + 1.0 / k0)
                if coincide or not _electrical(fc0, fc0, f1, df):
                    continue   # the two combs cannot be told apart, or this line is a shaft order's
                own, mixed, low = [], [], False
                for k in range(1, int(top / m_act) + 1):
                    fk = k * m_act
                    order = round(fk / half) * half
                    near = sorted(standing(fk, 0.75 * df + MAINS_DRIFT * k * m), key=lambda v: abs(v - fk))
                    for fc in near[:1]:   # one line per harmonic: the nearest
                        low |= k <= 2
                        if _electrical(fc, fk, f1, df):
                            own.append((k, fc))
                        elif abs(fk - order) >= 0.5 * df:
                            mixed.append((fk, order))
                if low and (len(own) >= 2 or {k for k, _ in own} & {1, 2}) and len(own) > len(best[0]):
                    best = (own, mixed)
        lines += [fc for _, fc in best[0]] + [fk for fk, _ in best[1]]
        beside += [order for _, order in best[1]]
    return sorted(set(lines)), sorted(set(beside) - set(lines))


def _electrical(fc, f_supply, f1, df) -> bool:
    """A line at fc is the supply's harmonic at f_supply rather than a shaft order or half order j x f1:
    closer to f_supply, and further from the order than where the order may be (half a line, plus a
    quarter of a line times j: f1, measured from the 1X line, is known to about a quarter of a line)."""
    order = round(fc / (0.5 * f1)) * 0.5 * f1
    return abs(fc - f_supply) < abs(fc - order) and abs(fc - order) > 0.5 * df + 0.25 * df * order / f1


def _supply_part(x, fs, lines_hz, beside_hz=()):
    """The supply's lines in x and their amplitudes: sinusoids at ``lines_hz`` fitted by least squares
    together with those at ``beside_hz`` (shaft orders beside them, which are not returned). Complex
    amplitudes; the Gram matrix of the exponentials in closed form, the negative-frequency terms left out
    (they add 1 / (N x the line's frequency in bins) of coupling). Fitted together, a shaft order beside
    a supply line keeps its own amplitude: a window's leakage would lend it the supply's."""
    n = x.size
    w = 2 * np.pi * np.concatenate([np.asarray(lines_hz, float), np.asarray(beside_hz, float)]) / fs
    d = w[None, :] - w[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        G = np.where(np.abs(d) > 1e-12, np.expm1(1j * n * d) / np.expm1(1j * np.where(d == 0, 1.0, d)), n)
    # e^(i w (qB + r)) = P[q] R[r]: the exponentials in blocks of B samples, as matrix products
    B = 1024
    Q = -(-n // B)
    R = np.exp(1j * np.outer(np.arange(B), w))          # (B, L)
    P = np.exp(1j * np.outer(np.arange(Q) * B, w))      # (Q, L)
    X = np.zeros(Q * B)
    X[:n] = x
    b = np.sum(P.conj() * (X.reshape(Q, B) @ R.conj()), axis=0)
    a = np.linalg.solve(G, b)
    m = len(lines_hz)
    return 2.0 * ((P[:, :m] * a[:m]) @ R[:, :m].T).real.ravel()[:n], 2.0 * np.abs(a[:m])


@dataclass(frozen=True)
class Supply:
    """The supply's lines (Hz) and their fitted acceleration amplitudes, and the job whose primary
    channel has them subtracted (the one shaft-order faults are judged on)."""
    hz: list
    amp: tuple
    shaft_job: object


def supply_lines(run) -> Supply:
    """The supply's lines of a steady-speed record (there the spectrum's orders are where f1 puts them),
    fitted together with the shaft orders beside them and taken out of the primary channel."""
    job = run.job
    steady = not {"order_tracked", "speed_varies"} & set(job.flags)
    electrical, beside = _mains_lines(run.f, run.A, run.f1, job.mains) if steady else ([], [])
    supply, supply_amp = _supply_part(job.a, job.fs, electrical, beside) if electrical else (0.0, ())
    return Supply(electrical, supply_amp, replace(job, a=job.a - supply) if electrical else job)
