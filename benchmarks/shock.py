"""Shock response spectrum speed and accuracy.

1 s of a random shock at 100 kHz, 1/12-octave natural frequencies from 1 Hz to 10 kHz (160
oscillators), Q = 10: vm.srs against the textbook loop (Smallwood's coefficients through
scipy.signal.lfilter on the record plus one cycle of zeros, no refinement of the peaks), and both
against scipy's lsim (exact for the linearly interpolated input) at a few frequencies.

Target (issue 15): < 1 s.

Then issue 50's case side by side with endaq's ``shock_spectrum`` when endaq is installed
(``pip install endaq``; not a vibmeasure dependency): 2^17 samples of a random shock at 20 kHz, 108
oscillators 10 Hz - 4.8 kHz (1/12 octave), 5 % damping; the error of each against the exact response
of the linearly interpolated input (scipy lsim at 256 points a cycle) at six frequencies up to fs/4.
Target: vm.srs <= 1.5x endaq, within 0.5 % of exact at every oscillator up to fs/4.

    python benchmarks/shock.py
"""

import statistics
import time

import numpy as np
from scipy.signal import lfilter, lsim

import vibmeasure as vm
from vibmeasure.signal.shock import smallwood_coefficients

FS = 100_000.0


def textbook(x, fn, zeta):
    b, a = smallwood_coefficients(fn, zeta, FS)
    out = np.empty(fn.size)
    for k, f in enumerate(fn):
        y = lfilter(b[k], a[k], np.r_[x, np.zeros(int(FS / f) + 2)])
        out[k] = np.max(np.abs(y))
    return out


def main():
    rng = np.random.default_rng(0)
    n = int(FS)
    x = np.r_[np.zeros(1000), rng.normal(size=n - 1000) * np.exp(-np.arange(n - 1000) / 8000.0)] * 50 * 9.81
    rec = vm.Record.from_array(x, fs=FS, quantity="acceleration", unit="m/s^2")
    fn = 2.0 ** np.arange(0, np.log2(10_000) + 1e-9, 1 / 12)
    t_vm, t_tb = [], []
    for _ in range(5):
        t0 = time.perf_counter()
        sp = vm.srs(rec, fn=fn, Q=10)
        t_vm.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        tb = textbook(x, fn, 0.05)
        t_tb.append(time.perf_counter() - t0)
    print(f"1 s at 100 kHz, {fn.size} natural frequencies 1 Hz - 10 kHz (1/12 octave), Q 10")
    print(f"  vm.srs (maximax, primary, residual, refined peaks): {statistics.median(t_vm):.3f} s (target < 1 s)")
    print(f"  textbook Smallwood lfilter loop (maximax only):       {statistics.median(t_tb):.3f} s")
    t = np.arange(n + int(FS * 1.1)) / FS
    xx = np.r_[x, np.zeros(t.size - n)]
    print("  maximax against scipy lsim (exact for the interpolated input):")
    for f in (5.0, 100.0, 1000.0, 4000.0, 9000.0):
        k = int(np.argmin(np.abs(fn - f)))
        w = 2 * np.pi * fn[k]
        m = max(1, int(np.ceil(64 * fn[k] / FS)))   # lsim on a finer interpolated grid for the peak
        tf = np.arange((t.size - 1) * m + 1) / (FS * m)
        _, y, _ = lsim(([0.1 * w, w * w], [1.0, 0.1 * w, w * w]), np.interp(tf, t, xx), tf)
        ref = np.max(np.abs(y))
        print(f"    {fn[k]:8.1f} Hz  vm {sp['maximax'][k] / ref - 1:+.2e}   textbook {tb[k] / ref - 1:+.2e}")


def against_endaq():
    fs, n = 20000.0, 2 ** 17
    rng = np.random.default_rng(0)
    x = np.r_[np.zeros(2000), rng.normal(size=n - 2000) * np.exp(-np.arange(n - 2000) / 4000.0)] * 50 * 9.81
    rec = vm.Record.from_array(x, fs=fs, quantity="acceleration", unit="m/s^2")
    fn = 10.0 * 2 ** (np.arange(108) / 12)
    print(f"\n2^17 samples at 20 kHz, {fn.size} oscillators {fn[0]:g} Hz - {fn[-1]:.0f} Hz (1/12 octave), zeta 0.05")
    try:
        import pandas as pd
        from endaq.calc.shock import shock_spectrum
    except ImportError:
        shock_spectrum = None
        print("  (endaq not installed: pip install endaq to compare)")
    t_vm, t_en = [], []
    df = None
    for _ in range(5):
        t0 = time.perf_counter()
        sp = vm.srs(rec, fn=fn, zeta=0.05)
        t_vm.append(time.perf_counter() - t0)
        if shock_spectrum is not None:
            df = pd.DataFrame({"x": x}, index=pd.Index(np.arange(n) / fs, name="time"))
            t0 = time.perf_counter()
            en = shock_spectrum(df, freqs=fn, damp=0.05, mode="srs", max_time=None)
            t_en.append(time.perf_counter() - t0)
    line = f"  vm.srs {statistics.median(t_vm):.3f} s"
    if t_en:
        line += f"   endaq shock_spectrum {statistics.median(t_en):.3f} s   vm / endaq {statistics.median(t_vm) / statistics.median(t_en):.2f}x (target <= 1.5x)"
    print(line)
    t = np.arange(40000) / fs
    for f in (100.0, 761.0, 1500.0, 2280.0, 3400.0, 4800.0):
        k = int(np.argmin(np.abs(fn - f)))
        w = 2 * np.pi * fn[k]
        m = max(1, int(np.ceil(256 * fn[k] / fs)))
        tf = np.arange((t.size - 1) * m + 1) / (fs * m)
        _, y, _ = lsim(([0.1 * w, w * w], [1.0, 0.1 * w, w * w]), np.interp(tf, t, x[:t.size]), tf)
        ref = np.max(np.abs(y))
        row = f"    {fn[k]:8.1f} Hz  vm {sp['maximax'][k] / ref - 1:+.2e}"
        if t_en:
            row += f"   endaq {float(np.asarray(en).ravel()[k]) / ref - 1:+.2e}"
        print(row)


if __name__ == "__main__":
    main()
    against_endaq()
