"""Output-only modal analysis speed against pyOMA2, side by side in one process, on pyOMA2's own
example: its 5-dof shear frame under white noise (``pyoma2.functions.gen.example_data``: 5 floors of
25.91 kg and 10 kN/m, 2 % damping, accelerations with 10 % noise, 30001 samples at 100 Hz).

vibmeasure picks the modes itself and states their stds; pyOMA2 is handed the true frequencies to
pick (``mpe(sel_freq=...)``), once without and once with its uncertainty propagation (``calc_unc``).
Both SSI runs use 30 block rows and orders up to 40 (vibmeasure's defaults). pyOMA2's EFDD runs with
its default segment (1024) where it can, else 2048 and 4096 samples; the largest |fn error| shows
what each answer is worth. Times are the median of ``repeats`` runs, the tools interleaved so that
the machine's load falls on both alike.

    python benchmarks/oma_speed.py [repeats]        (default 7)

pyOMA2 is not a vibmeasure dependency: ``pip install pyOMA-2`` to compare (the example data come
from it too, so without it the script says so and stops).
"""

import contextlib
import io
import logging
import statistics
import sys
import time
import warnings

import numpy as np

import vibmeasure as vm


def _pyoma_ssi(Y, fs, fn_true, calc_unc):
    from pyoma2.algorithms import SSI
    from pyoma2.setup import SingleSetup
    s = SingleSetup(Y.copy(), fs=fs)
    s.add_algorithms(SSI(name="SSIcov", method="cov", br=30, ordmax=40, calc_unc=calc_unc))
    s.run_by_name("SSIcov")
    s.mpe("SSIcov", sel_freq=list(fn_true), order_in="find_min")
    return np.asarray(s["SSIcov"].result.Fn)


def _pyoma_efdd(Y, fs, fn_true, nxseg):
    from pyoma2.algorithms import EFDD
    from pyoma2.setup import SingleSetup
    s = SingleSetup(Y.copy(), fs=fs)
    s.add_algorithms(EFDD(name="EFDD", nxseg=nxseg))
    s.run_by_name("EFDD")
    s.mpe("EFDD", sel_freq=list(fn_true), npmax=15)
    return np.asarray(s["EFDD"].result.Fn)


def _worst_error(fn, fn_true):
    fn = np.sort(np.asarray(fn, float))
    if fn.size != fn_true.size:
        return float("nan")
    return float(np.max(np.abs(fn / fn_true - 1)) * 100)


def main(repeats=7):
    try:
        from pyoma2.functions.gen import example_data
    except ImportError:
        print("pyOMA2 is not installed (pip install pyOMA-2): its example data and its algorithms are the "
              "comparison; nothing to run")
        return
    logging.getLogger("pyoma2").setLevel(logging.WARNING)
    warnings.simplefilter("ignore")
    np.random.seed(0)                      # example_data draws from numpy's global generator
    Y, _, (fn_true, xi, _) = example_data()
    fs = 100.0
    rec = vm.Record.from_array(Y.T, fs=fs, quantity="acceleration", unit="m/s^2")
    cases = {
        "vm.oma_ssi (picks modes, jackknife stds)": lambda: vm.oma_ssi(rec).fn,
        "pyOMA2 SSIcov, no uncertainty": lambda: _pyoma_ssi(Y, fs, fn_true, False),
        "pyOMA2 SSIcov, calc_unc=True": lambda: _pyoma_ssi(Y, fs, fn_true, True),
        "vm.oma_fdd (EFDD, picks modes, jackknife stds)": lambda: vm.oma_fdd(rec).fn,
        "pyOMA2 EFDD nxseg 1024": lambda: _pyoma_efdd(Y, fs, fn_true, 1024),
        "pyOMA2 EFDD nxseg 2048": lambda: _pyoma_efdd(Y, fs, fn_true, 2048),
        "pyOMA2 EFDD nxseg 4096": lambda: _pyoma_efdd(Y, fs, fn_true, 4096),
    }
    times = {k: [] for k in cases}
    fns = {}
    for _ in range(repeats):
        for name, run in cases.items():
            t0 = time.perf_counter()
            try:
                with contextlib.redirect_stderr(io.StringIO()):   # pyOMA2's progress bars
                    fns[name] = run()
            except Exception as exc:   # a peer that cannot answer on this record: said, not timed
                fns[name] = exc
                continue
            times[name].append(time.perf_counter() - t0)
    print(f"pyOMA2 5-dof example: {Y.shape[0]} samples x {Y.shape[1]} channels at {fs:g} Hz, true fn "
          f"{np.round(fn_true, 4).tolist()} Hz, zeta {xi}; median of {repeats} runs")
    print(f"  {'method':48s} {'time s':>8s} {'worst |fn err| %':>17s}")
    for name in cases:
        if isinstance(fns[name], Exception):
            print(f"  {name:48s} {'fails':>8s}  {str(fns[name]).splitlines()[0][:60]}")
            continue
        print(f"  {name:48s} {statistics.median(times[name]):8.3f} {_worst_error(fns[name], fn_true):17.3f}")
    med = {k: statistics.median(v) for k, v in times.items() if v}
    vs, vf = med["vm.oma_ssi (picks modes, jackknife stds)"], med["vm.oma_fdd (EFDD, picks modes, jackknife stds)"]
    print(f"ratio vm.oma_ssi / pyOMA2 SSIcov: {vs / med['pyOMA2 SSIcov, no uncertainty']:.2f} (no uncertainty), "
          f"{vs / med['pyOMA2 SSIcov, calc_unc=True']:.2f} (with)")
    efdd = [k for k in med if k.startswith("pyOMA2 EFDD")]
    if efdd:
        fastest = min(efdd, key=med.get)
        print(f"ratio vm.oma_fdd / {fastest} (pyOMA2's fastest EFDD that answers): {vf / med[fastest]:.2f}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 7)
