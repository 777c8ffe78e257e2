"""A gearbox's hunting-tooth comb in an envelope spectrum. Two gears' tooth errors repeat together every
hunting-tooth period, and their lines stand every f1 x gcd(z1, z2) / z2 over the whole spectrum, at
random heights; a bearing's comb on those lines is the gearbox's (``on_grid``). Where the gear pair is
declared the spacing is known; where it is not (no gear declared, or a speed or a sampling rate
declared wrong, which moves the grid with every other line), it is measured (``line_grid``): the
spacing whose multiples hold the standing lines (the Rayleigh test of their phases, lines / spacing),
counted only where it holds many lines at many places, as no bearing's comb does."""

from __future__ import annotations

import numpy as np

# Where both gears of a pair are declared (teeth and ratio), that hunting-tooth comb is known: a line
# every f1 x gcd(z1, z2) / z2. Any line of it has lines of it at +-1X (z2 / gcd steps away), so a BPFI
# +-1X triplet can stand on it at any frequency, and its lines' random heights reach p = 1e-12 among
# thousands of such triplets (healthy gearboxes with rough gears, 20 % tooth errors: inner race at 0.99
# for 23/67 at 2400 rpm, 0.68 for 32/71 at 1800, 0.58 for 40/83 at 3600). A comb every one
# of whose standing lines (two or more), its frequency refined, lies within HUNT_TOL of a line of that
# grid is the gearbox's, not the bearing's. A bearing's comb falls on the grid by chance only as often as
# 2 HUNT_TOL over the grid's spacing in lines (at most 25 % for one carrier and its sidebands, where the
# grid is HUNT_MIN_SPACING lines; a few per cent for two carriers); a finer grid holds every line and
# is not tested. Measured on benchmarks/gearbox.py: no bearing fault under a two-gear mesh had every line
# of its comb within 0.25 line of the grid; the four healthy gearboxes' above (seeds 4-7 of 3-8) did.
HUNT_TOL = 0.25          # lines (bins)
HUNT_MIN_SPACING = 2.0   # lines (bins)

# A measured grid is a spacing of at least HUNT_MIN_SPACING lines and at most GRID_MAX_SHARE of
# the bearing's lowest frequency (FTF, about 0.4 x the speed), and it holds at least GRID_MIN_ON of the
# standing lines (R_LINE over their floor) within a quarter line of its multiples, on at least
# GRID_MIN_OCCUPANCY of the grid's places between its first and last line. Every comb lies on every
# sub-multiple of its spacing, and a bearing's comb with its sidebands and the shaft's harmonics lies
# close to a common fine grid where their ratios are near a fraction, so what sets a gearbox's grid apart
# is how many lines it holds and how densely. Measured: on the development records' (CWRU fan-end and
# drive-end, MFPT) envelope spectra where a family was found, the best grid held at most 68 lines and
# 8 % of its places; on the synthetic healthy gearboxes (5-10 % tooth errors) whose hunting-tooth comb
# was called a ball (no gear declared), 176-289 lines on 10-51 % of the places.
GRID_MIN_ON = 100
GRID_MIN_OCCUPANCY = 0.08
GRID_MAX_SHARE = 0.5
# the Rayleigh statistic Z = N R^2 of the lines' phases at a spacing has p ~ exp(-Z); the scan tries
# many spacings, each a test: the best must stand at GRID_P over all of them
GRID_P = 1e-6
GRID_COARSEST = 0.9   # the coarsest spacing whose Z is this share of the best's (a grid's lines lie on g / 2 too)
GRID_TOL = 0.25       # lines: how close to a multiple a line lies on the grid


def _standing(r: np.ndarray, df: float, r_line: float) -> np.ndarray:
    """Refined frequencies of the local maxima standing r_line over their floor (a parabola through the
    log of the floor ratio)."""
    k = np.flatnonzero((r[1:-1] >= r_line) & (r[1:-1] >= r[:-2]) & (r[1:-1] > r[2:])) + 1
    k = k[k >= 3]
    a, b, c = (np.log(np.maximum(r[k + d], 1e-300)) for d in (-1, 0, 1))
    den = a - 2 * b + c
    shift = np.where(den < 0, 0.5 * (a - c) / np.where(den < 0, den, -1.0), 0.0)
    return (k + shift) * df


def _best_spacing(p: np.ndarray, df: float, g_lo: float, g_hi: float) -> tuple[float, float] | None:
    """(coarsest spacing near the best Rayleigh statistic, log p over the scan) of the lines p (Hz), the
    spacings between g_lo and g_hi. The statistic |sum exp(2 pi i p / g)|^2 / N at every 1 / g is one
    Fourier transform: each line split between the two nearest points of a grid df / 4 apart (its phase
    off by under a sixteenth of a turn at a spacing of two lines), zero-padded to a step of at most a
    quarter turn at the highest line."""
    delta = df / 4
    size = int(2 ** np.ceil(np.log2(4 * p.max() / delta + 2)))
    u = p / delta
    i = np.floor(u).astype(int)
    x = np.zeros(size)
    np.add.at(x, i, 1.0 - (u - i))
    np.add.at(x, i + 1, u - i)
    z = np.abs(np.fft.rfft(x)) ** 2 / p.size
    nu = np.arange(z.size) / (size * delta)
    sel = (nu >= 1.0 / g_hi) & (nu <= 1.0 / g_lo)
    if not sel.any():
        return None
    nu, z = nu[sel], z[sel]
    best = float(z.max())
    return 1.0 / float(nu[int(np.flatnonzero(z >= GRID_COARSEST * best)[0])]), np.log(nu.size) - best


def line_grid(freq: np.ndarray, r: np.ndarray, n_valid: int, r_line: float, lowest_hz: float,
              min_spacing_lines: float) -> tuple[float, float, int] | None:
    """(spacing Hz, p over the scan, lines on it) of the dense grid the standing lines of an envelope
    spectrum lie on (``freq``, its floor ratio ``r``, the first ``n_valid`` bins); None where no grid
    holds GRID_MIN_ON lines densely (GRID_MIN_OCCUPANCY) beyond chance (GRID_P)."""
    df = float(freq[1])
    p = _standing(r[:n_valid], df, r_line)
    g_lo, g_hi = min_spacing_lines * df, GRID_MAX_SHARE * lowest_hz
    if p.size < GRID_MIN_ON or g_hi <= g_lo:
        return None
    found = _best_spacing(p, df, g_lo, g_hi)
    if found is None or found[1] > np.log(GRID_P):
        return None
    g, log_p = found
    n = np.rint(p / g)
    near = np.abs(p - n * g) <= 0.25 * g
    g = float(np.sum(n[near] * p[near]) / np.sum(n[near] ** 2))   # least squares over the lines near it
    on = np.unique(np.rint(p[np.abs(p - np.rint(p / g) * g) <= GRID_TOL * df] / g))
    if on.size < GRID_MIN_ON or on.size / (on[-1] - on[0] + 1) < GRID_MIN_OCCUPANCY:
        return None
    return g, float(np.exp(log_p)), int(on.size)


def measured_grid(ses, lowest_hz: float) -> tuple[float, float, int] | None:
    """A spectrum's dense line grid (``line_grid``), measured once and kept on the spectrum: where no gear
    pair is declared, a gearbox's hunting-tooth comb found from its lines (healthy gearboxes declared
    without their gear, under a user's band or at 0.8 x their speed, read as ball at 0.68-0.81 on it)."""
    if "_line_grid" not in ses.__dict__:
        ses._line_grid = line_grid(ses.freq, ses.r, ses.n_valid, ses.r_line, lowest_hz, HUNT_MIN_SPACING)
    return ses._line_grid


def on_grid(ses, hz: list, spacing: float | None) -> bool:
    """Whether every one of the lines ``hz`` (two or more; each refined by a parabola through the log power
    of its peak in the spectrum ``ses``) lies within HUNT_TOL lines of a grid of ``spacing`` Hz; never
    where the grid is finer than HUNT_MIN_SPACING lines (it would hold every line)."""
    df = float(ses.freq[1])
    if spacing is None or spacing < HUNT_MIN_SPACING * df or len(hz) < 2:
        return False
    P = ses.amp[: ses.n_valid].astype(float) ** 2
    for f in hz:
        i = int(round(f / df))
        if not 2 <= i < P.size - 2:
            return False
        j = i - 1 + int(np.argmax(P[i - 1: i + 2]))
        a, b, c = np.log(np.maximum(P[j - 1: j + 2], 1e-300))
        den = a - 2 * b + c
        fp = (j + (0.5 * (a - c) / den if den < 0 else 0.0)) * df
        if abs(fp - round(fp / spacing) * spacing) > HUNT_TOL * df:
            return False
    return True
