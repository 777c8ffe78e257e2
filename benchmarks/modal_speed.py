"""fit_modes against sdypy-EMA's LSCF on the same FRFs (issue 50), side by side in one process.

Five modes (86-581 Hz, zeta 0.6-1.4 %), five outputs, 5000 lines to 1 kHz, clean and with 1 % complex
noise, in a wide band (1-999 Hz) and a narrow one (50-650 Hz). vibmeasure selects the modes itself and
gives their stds after an ML polish; sdypy-EMA (order 60) is handed the true frequencies to pick its
poles and computes its modal constants (``get_constants``), so both end with frequencies, damping and
shapes. Medians of 3 interleaved runs. Target: vm <= 1x sdypy-EMA.

sdypy-EMA is not a vibmeasure dependency (``pip install sdypy-EMA``).

    python benchmarks/modal_speed.py
"""

import contextlib
import io
import statistics
import time
import warnings

import numpy as np

import vibmeasure as vm

FREQ = np.linspace(0.2, 1000, 5000)
FN = np.array([86.0, 246.0, 386.0, 502.0, 581.0])
ZETA = np.array([0.006, 0.010, 0.012, 0.013, 0.014])


def peer(H, lo, hi):
    from sdypy import EMA
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()), \
            warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = EMA.Model(frf=H, freq=FREQ, lower=lo, upper=hi, pol_order_high=60, frf_type="receptance")
        m.get_poles(method="lscf", show_progress=False)
        m.select_closest_poles(list(FN), f_window=20)
        m.get_constants(whose_poles="own", FRF_ind="all")
    return np.asarray(m.nat_freq, float)


def main():
    rng = np.random.default_rng(0)
    shapes = rng.normal(size=(5, 5))
    clean = vm.synth.modal_frf(FREQ, fn=FN, zeta=ZETA, shapes=shapes, input_dof=0)
    H = clean.h[:, 0]
    s = 0.01 * np.abs(H).max(axis=1, keepdims=True)
    Hn = H + s * (rng.normal(size=H.shape) + 1j * rng.normal(size=H.shape)) / np.sqrt(2)
    try:
        import sdypy.EMA  # noqa: F401
        have_peer = True
    except ImportError:
        have_peer = False
        print("(sdypy-EMA not installed: pip install sdypy-EMA to compare)")
    print(f"{'FRFs':<10} {'band Hz':<10} {'vm s':>7} {'sdypy s':>8} {'vm/sdypy':>9}  {'vm worst |dfn| %':>16}")
    for name, h in (("clean", H), ("1% noise", Hn)):
        frf = vm.FRF(freq=FREQ, h=h[:, None, :])
        for band in ((1, 999), (50, 650)):
            t_vm, t_peer = [], []
            for _ in range(3):
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    t0 = time.perf_counter()
                    est = vm.fit_modes(frf, band=band)
                    t_vm.append(time.perf_counter() - t0)
                if have_peer:
                    t0 = time.perf_counter()
                    peer(h, *band)
                    t_peer.append(time.perf_counter() - t0)
            err = max(np.min(np.abs(est.fn - f)) / f for f in FN) * 100
            tv = statistics.median(t_vm)
            tp = statistics.median(t_peer) if t_peer else float("nan")
            print(f"{name:<10} {band[0]:g}-{band[1]:<6g} {tv:>7.3f} {tp:>8.3f} {tv / tp:>9.2f}  {err:>16.2e}")


if __name__ == "__main__":
    main()
