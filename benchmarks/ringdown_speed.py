"""Speed of vm.ringdown on one-mode ring-downs of 100k and 1M samples (median of several runs).

Targets (issue 2): 100k samples under 0.3 s, 1M samples under 3 s on a 2-core machine.
The peer, in the same process on the same records, is scipy.optimize.curve_fit on a damped
sinusoid started from the FFT peak (what an engineer writes by hand; no uncertainty, no order
selection, no trimming).

    python benchmarks/ringdown_speed.py
"""

import statistics
import time
import warnings

import numpy as np
from scipy.optimize import curve_fit

import vibmeasure as vm


def peer_curve_fit(x, fs):
    t = np.arange(x.size) / fs
    X = np.abs(np.fft.rfft(x - x.mean()))
    f0 = np.argmax(X[1:]) + 1
    f0 = f0 * fs / x.size

    def model(t, a, s, f, ph, c):
        return a * np.exp(-s * t) * np.cos(2 * np.pi * f * t + ph) + c

    p, _ = curve_fit(model, t, x, p0=[np.max(np.abs(x)), 1.0, f0, 0.0, 0.0], maxfev=20000)
    wn = np.hypot(2 * np.pi * p[2], p[1])
    return wn / (2 * np.pi), p[1] / wn


def timed(fn, reps):
    out, ts = None, []
    for _ in range(reps):
        t0 = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts), out


def main():
    warnings.simplefilter("ignore", vm.QualityWarning)
    print(f"{'samples':>9} {'fs':>7} {'vm.ringdown s':>14} {'target s':>9} {'curve_fit s':>12} {'ratio':>6} "
          f"{'vm fn err':>10} {'vm zeta err':>11} {'peer zeta err':>13}")
    for n, fs, target in [(100_000, 10_000.0, 0.3), (1_000_000, 10_000.0, 3.0)]:
        dur = n / fs
        # a light mode that rings through the whole record (no trimming helps)
        fn, zeta = 137.31, 0.5 / (2 * np.pi * 137.31 * dur)
        rec = vm.synth.free_decay(fn=fn, zeta=zeta, fs=fs, duration=dur, snr_db=40, seed=1, phase=0.4)
        reps = 5 if n <= 100_000 else 3
        t_vm, est = timed(lambda: vm.ringdown(rec), reps)
        t_peer, (pf, pz) = timed(lambda: peer_curve_fit(rec.data[0], fs), reps)
        print(f"{n:>9} {fs:>7g} {t_vm:>14.3f} {target:>9.1f} {t_peer:>12.3f} {t_peer / t_vm:>6.2f} "
              f"{(est.fn[0] - fn) / fn:>10.2e} {(est.zeta[0] - zeta) / zeta:>11.2e} {(pz - zeta) / zeta:>13.2e}")


if __name__ == "__main__":
    main()
