"""The measurement behind diagnose's smeared ball comb (``bearing.smeared._smeared_ball``): does a ball
defect whose 2 x BSF lines do not stand out leave a comb of humps (a few per cent wide) at 2 x BSF and its
harmonics? A ball's spin wanders (its axis tilts, it skids), so its lines may spread over many bins where a
race defect's, locked to the cage and the shaft, stay sharp.

For every development record (cwru_fe, mfpt, cwru) and a few synthetic machines: the cepstral whole-band
SES of each channel as diagnose computes it, over the wide floor of ``_wide_ratio`` (a +-40 Hz median;
shaft and cage harmonics left out), the channels averaged; the comb statistic of ``_smear_comb`` (energy
in +-1.5 % bands at 2 x BSF x 1-3, common slip within +-2 %, Gamma law with the Hann window's variance),
log10 p uncorrected, and the best of the decoy combs of ``_smear_decoys``. Printed first with every bin
kept, then with the race families' lines and their +-1X and +-2X sidebands left out (+-1 %), as diagnose
does: on the 6203 BPFO + 1X (4.05 X) and BPFI - 1X (3.95 X) lie 1.6 % and 1.0 % from 2 x BSF (3.99 X),
and a race defect's skirts fill the ball's bands.

    python benchmarks/ball_smear.py
"""

import sys
import warnings
from pathlib import Path

import numpy as np

import vibmeasure as vm
from vibmeasure.monitor.bearing import smeared as bf
from vibmeasure.monitor.bearing.spectra import _spectra

sys.path.insert(0, str(Path(__file__).resolve().parent))
from diagnosis_real import SHORT, records  # noqa: E402


def analyse(rec, rpm, bearing):
    """[(log10 p, best decoy log10 p)] with every bin kept, then with the races' lines left out."""
    f1 = rpm / 60
    freqs = vm.models.bearing.bearing_from(bearing).frequencies(f1)
    views = [next(s for s in _spectra(rec.channel(c).astype(float), rec.fs, c, f1, freqs, None)[0]
                  if s.prep == "cepstral") for c in rec.names]
    decoys = bf._smear_decoys(freqs, f1)
    df = float(views[0].freq[1])
    out = []
    for races in (False, True):
        ratios = [bf._wide_ratio(s, freqs, f1, races=races) for s in views]
        n = min(r.size for r, _ in ratios)
        r = np.mean([r[:n] for r, _ in ratios], axis=0)
        keep = np.all([k[:n] for _, k in ratios], axis=0)
        shape = float(len(views))
        logp = bf._smear_comb(r, keep, df, freqs["2xBSF"], shape)[0]
        best = min((bf._smear_comb(r, keep, df, d, shape)[0] for d in decoys), default=0.0)
        out.append((logp / np.log(10), best / np.log(10)))
    return out


def main():
    warnings.simplefilter("ignore", vm.QualityWarning)
    rows = [(name, truth, rec, rpm, bearing) for _, name, rec, rpm, bearing, truth, _ in records()]
    for seed in range(3):
        for fault, kw in (("none", {}), ("none", dict(cage_modulation=1.0)), ("bearing_ball", {}),
                          ("bearing_outer_race", {}), ("bearing_inner_race", {})):
            rec = vm.synth.machine(fault=fault, snr_db=0, seed=7700 + seed, duration=6.0, **kw)
            rows.append((f"synthetic {fault}{' + cage' if kw else ''} {seed}", fault, rec, rec.meta["rpm"], "6205-2RS"))
    print(f"log10 p, channels averaged; right: the races' lines left out (+-{100 * bf.SMEAR_EXCL:g} %), as diagnose")
    print(f"{'record':42s} {'truth':>6s} {'2xBSF humps':>12s} {'best decoy':>11s} {'2xBSF humps':>12s} {'best decoy':>11s}")
    for name, truth, rec, rpm, bearing in rows:
        (a, b), (c, d) = analyse(rec, rpm, bearing)
        print(f"{name:42s} {SHORT.get(truth, truth):>6s} {a:12.1f} {b:11.1f} {c:12.1f} {d:11.1f}", flush=True)


if __name__ == "__main__":
    main()
