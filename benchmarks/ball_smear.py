"""A measurement, not a method vm.diagnose uses: does a ball defect whose 2 x BSF lines do not stand out
leave a smeared comb (a hump a few per cent wide at 2 x BSF and its harmonics) in the envelope? A ball's
spin wanders (its axis tilts, it skids), so its lines may spread over many bins where a race defect's,
locked to the cage and the shaft, stay sharp. vm.diagnose tests lines (2 bins each); the fan-end ball
records it leaves at "none" show no ball line comb (README, issue 9 notes).

For every development record (cwru_fe, mfpt, cwru) and a few synthetic machines: the cepstrally
pre-whitened SES of each channel above 10 x BPFI, the channels averaged, over a wide floor (running
median of +-40 Hz); the bins of shaft harmonics (+-2 bins) and cage harmonics (+-1 bin) left out; the
statistic is the sum of the ratio over bands of +-1.5 % around harmonics 1-3 of a fundamental at a
common slip within +-2 %, against Gamma(bins) (log10 p, no correction: Hann-windowed bins are not
independent, so the decoys say what the tail of real spectra is). Printed for 2 x BSF, and as a
control for decoy fundamentals (0.55-1.8 x 2 x BSF) whose harmonics stay 4 % away from every bearing
line (harmonics of BPFO, BPFI +-1X, 2 x BSF, BSF); each first as is, then with the race families'
lines left out too (harmonics 1-12 of BPFO and BPFI with +-1X and +-2X sidebands, +-EXCL of their
frequency): on the 6203 the races' sidebands BPFO + 1X (4.05 X) and BPFI - 1X (3.95 X) lie 1.6 % and
1.0 % from 2 x BSF (3.99 X), and a race defect's skirts fill the ball's bands.

    python benchmarks/ball_smear.py
"""

import sys
import warnings
from pathlib import Path

import numpy as np
from scipy import fft as sfft
from scipy.ndimage import median_filter
from scipy.special import gammaincc

import vibmeasure as vm
from vibmeasure.signal.kurtogram import _ses_power
from vibmeasure.signal.whiten import _cepstral_spectrum

sys.path.insert(0, str(Path(__file__).resolve().parent))
from diagnosis_real import SHORT, records  # noqa: E402

WIDTH, SLIP, EXCL = 0.015, 0.02, 0.01


def smear(r, keep, df, f0):
    """Best log10 p of the band-energy comb at f0 x (1 + slip), harmonics 1-3."""
    best = 0.0
    for s in np.linspace(-SLIP, SLIP, 9):
        tot, m = 0.0, 0
        for h in (1, 2, 3):
            c = h * f0 * (1 + s)
            lo, hi = int(c * (1 - WIDTH) / df), int(c * (1 + WIDTH) / df) + 1
            tot += r[lo:hi][keep[lo:hi]].sum()
            m += int(keep[lo:hi].sum())
        if m:
            best = min(best, float(np.log10(max(gammaincc(m, tot), 1e-300))))
    return best


def analyse(rec, rpm, bearing):
    f1 = rpm / 60
    fr = vm.models.bearing.bearing_from(bearing).frequencies(f1)
    f_max = 4 * fr["2xBSF"] * 1.1
    powers = []
    for name in rec.names:
        x = rec.channel(name).astype(float)
        X = _cepstral_spectrum(sfft.rfft(x - x.mean()))
        freq, amp, _ = _ses_power(X, x.size, rec.fs, (max(1000.0, 10 * fr["BPFI"]), 0.45 * rec.fs), f_max)
        P = amp ** 2
        powers.append(P / np.median(P[P.size // 10:]))
    P, df = np.mean(powers, axis=0), freq[1]
    r = P / median_filter(P, 2 * int(round(40 / df)) + 1)
    r /= r[int(20 / df): int(f_max / df)].mean()
    keep = np.ones(r.size, bool)
    for hz, half in ((f1, 2), (fr["FTF"], 1)):
        for k in range(1, int(r.size * df / hz) + 1):
            i = int(round(k * hz / df))
            keep[max(0, i - half): i + half + 1] = False
    lines = np.array([h * fr[key] + sb * f1 for key in ("BPFO", "BPFI", "2xBSF", "BSF") for h in range(1, 12)
                      for sb in ((-1, 0, 1) if key == "BPFI" else (0,))])
    decoys = [m for m in np.linspace(0.55, 1.8, 60)
              if all(np.min(np.abs(lines - h * fr["2xBSF"] * m)) > 0.04 * h * fr["2xBSF"] * m for h in (1, 2, 3))]
    races = keep.copy()
    for key in ("BPFO", "BPFI"):
        for h in range(1, 13):
            for sb in (-2, -1, 0, 1, 2):
                c = h * fr[key] + sb * f1
                races[max(0, int(c * (1 - EXCL) / df)): max(0, int(c * (1 + EXCL) / df) + 1)] = False
    return [(smear(r, k, df, fr["2xBSF"]), min((smear(r, k, df, fr["2xBSF"] * m) for m in decoys), default=0.0))
            for k in (keep, races)]


def main():
    warnings.simplefilter("ignore", vm.QualityWarning)
    rows = [(name, truth, rec, rpm, bearing) for _, name, rec, rpm, bearing, truth, _ in records()]
    for seed in range(3):
        for fault, kw in (("none", {}), ("none", dict(cage_modulation=1.0)), ("bearing_ball", {}),
                          ("bearing_outer_race", {}), ("bearing_inner_race", {})):
            rec = vm.synth.machine(fault=fault, snr_db=0, seed=7700 + seed, duration=6.0, **kw)
            rows.append((f"synthetic {fault}{' + cage' if kw else ''} {seed}", fault, rec, rec.meta["rpm"], "6205-2RS"))
    print(f"log10 p; right: the races' lines left out (+-{100 * EXCL:g} %)")
    print(f"{'record':42s} {'truth':>6s} {'2xBSF smear':>12s} {'best decoy':>11s} {'2xBSF smear':>12s} {'best decoy':>11s}")
    for name, truth, rec, rpm, bearing in rows:
        (ball, decoy), (ball_x, decoy_x) = analyse(rec, rpm, bearing)
        print(f"{name:42s} {SHORT.get(truth, truth):>6s} {ball:12.1f} {decoy:11.1f} {ball_x:12.1f} {decoy_x:11.1f}",
              flush=True)


if __name__ == "__main__":
    main()
