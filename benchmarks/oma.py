"""Output-only modal analysis: accuracy and calibration of vm.oma_ssi and vm.oma_fdd on simulated
ambient responses, and pyOMA2 on the same records when it is installed.

System: a 5-dof chain (masses 0.9-1.2 kg, modal damping 1-2 %, modes 8.9-57.3 Hz), driven by
independent white forces at every mass; 6 acceleration outputs (the 5 masses and a sensor reading
the mean of masses 3 and 4), 10 min at 200 Hz, 5 % output noise (of each output's RMS).

Per method over the seeds: modes found, worst |fn error| (%), fn bias, zeta RMSE against the mean
std the method states (their ratio should be near 1: within 30 % is the target), worst MAC with
the true shapes, median time per record.

    python benchmarks/oma.py [n_seeds]        (default 50)

pyOMA2 is not a vibmeasure dependency. Install it beside vibmeasure to compare
(``pip install pyOMA-2``; it is then run on the first 10 seeds, its modes picked at the true
frequencies, since it needs them picked); the script says so when it is missing.
"""

import statistics
import sys
import time
import warnings

import numpy as np

import vibmeasure as vm


def system():
    n = 5
    M = np.diag([1.0, 1.2, 0.9, 1.1, 1.0])
    k = np.array([4e3, 3.5e3, 3e3, 2.5e3, 2e3]) * 12
    K = np.zeros((n, n))
    for i in range(n):
        K[i, i] += k[i]
        if i + 1 < n:
            K[i, i] += k[i + 1]
            K[i, i + 1] = K[i + 1, i] = -k[i + 1]
    model = vm.models.MDOF(M, K, modal_zeta=[0.01, 0.012, 0.015, 0.015, 0.02])
    sensors = np.vstack([np.eye(5), [0, 0, 0, 0.5, 0.5]])
    return model, sensors


def match(true_fn, est_fn):
    """Index of the estimated mode nearest each true mode (within 2 %), or -1."""
    out = []
    for f in true_fn:
        j = int(np.argmin(np.abs(est_fn - f))) if est_fn.size else -1
        out.append(j if j >= 0 and abs(est_fn[j] - f) <= 0.02 * f else -1)
    return out


def pyoma2_ssi(rec, sel_freq):
    """pyOMA2's SSIcov (br 30, orders up to 40, uncertainty propagation on) on the same record, its
    modes picked at the true frequencies (pyOMA2 needs a person, or these, to pick them; vibmeasure
    picks them itself). Returns (fn, zeta, zeta_std, shapes)."""
    import logging
    logging.getLogger("pyoma2").setLevel(logging.WARNING)
    from pyoma2.algorithms import SSI
    from pyoma2.setup import SingleSetup
    setup = SingleSetup(rec.data.T.copy(), fs=rec.fs)
    setup.add_algorithms(SSI(name="SSIcov", method="cov", br=30, ordmax=40, calc_unc=True))
    setup.run_by_name("SSIcov")
    setup.mpe("SSIcov", sel_freq=list(sel_freq), order_in="find_min")
    r = setup["SSIcov"].result
    return np.asarray(r.Fn), np.asarray(r.Xi), np.asarray(r.Xi_std), np.asarray(r.Phi)


def summarise(name, rows, truth, times):
    nm = len(truth.fn)
    found = np.array([[j >= 0 for j in r["idx"]] for r in rows])
    print(f"\n{name}: {len(rows)} records, modes found {int(found.sum())} of {found.size}; "
          f"median time {statistics.median(times):.3f} s")
    print("  mode    fn true  worst|dfn| %  bias %   zeta true  zeta bias %  zeta RMSE  mean stated std  ratio  worst MAC")
    for m in range(nm):
        sel = [(r["fn"][r["idx"][m]], r["zeta"][r["idx"][m]], r["zeta_std"][r["idx"][m]], r["mac"][m])
               for r in rows if r["idx"][m] >= 0]
        if not sel:
            print(f"  {m + 1:4d}  {truth.fn[m]:9.4f}   not found")
            continue
        f, z, zs, mc = (np.array(v) for v in zip(*sel))
        err = (f - truth.fn[m]) / truth.fn[m] * 100
        rmse = float(np.sqrt(np.mean((z - truth.zeta[m]) ** 2)))
        std = float(np.nanmean(zs))
        zbias = (np.mean(z) / truth.zeta[m] - 1) * 100
        print(f"  {m + 1:4d}  {truth.fn[m]:9.4f}   {np.max(np.abs(err)):10.3f}  {np.mean(err):+7.3f}   "
              f"{truth.zeta[m]:9.4f}  {zbias:+11.2f}  {rmse:9.5f}  {std:15.5f}  {rmse / std:5.2f}  {np.min(mc):9.4f}")


N_PYOMA = 10   # pyOMA2 takes about 10 s per record here: the first 10 seeds


def main(n_seeds=50):
    warnings.simplefilter("ignore", vm.QualityWarning)
    model, sensors = system()
    truth = model.modes()
    true_shapes = sensors @ truth.shapes
    band = (1.0, 80.0)
    rows = {"oma_ssi": [], "oma_fdd": []}
    times = {"oma_ssi": [], "oma_fdd": []}
    have_pyoma = _pyoma_available()
    if have_pyoma:
        rows["pyOMA2 SSIcov"], times["pyOMA2 SSIcov"] = [], []
    for seed in range(n_seeds):
        rec = vm.synth.ambient(model, fs=200.0, duration=600.0, outputs=sensors, noise=0.05, seed=seed)
        for name, fn in (("oma_ssi", vm.oma_ssi), ("oma_fdd", vm.oma_fdd)):
            t0 = time.perf_counter()
            est = fn(rec, band=band)
            times[name].append(time.perf_counter() - t0)
            idx = match(truth.fn, est.fn)
            mac = [float(vm.mac(true_shapes[:, [m]], est.shapes[:, [j]])[0, 0]) if j >= 0 else np.nan
                   for m, j in enumerate(idx)]
            rows[name].append({"idx": idx, "fn": est.fn, "zeta": est.zeta, "zeta_std": est.zeta_std, "mac": mac})
        if have_pyoma and seed < N_PYOMA:
            import contextlib
            import io
            t0 = time.perf_counter()
            with contextlib.redirect_stderr(io.StringIO()):   # its progress bars
                fn_p, z_p, zs_p, phi_p = pyoma2_ssi(rec, truth.fn)
            times["pyOMA2 SSIcov"].append(time.perf_counter() - t0)
            idx = match(truth.fn, fn_p)
            mac = [float(vm.mac(true_shapes[:, [m]], phi_p[:, [j]])[0, 0]) if j >= 0 else np.nan
                   for m, j in enumerate(idx)]
            rows["pyOMA2 SSIcov"].append({"idx": idx, "fn": fn_p, "zeta": z_p, "zeta_std": zs_p, "mac": mac})
    print(f"5-dof chain, 6 outputs, 10 min at 200 Hz, 5 % output noise, {n_seeds} seeds; true fn (Hz) "
          f"{np.round(truth.fn, 4).tolist()}, zeta {np.round(truth.zeta, 4).tolist()}")
    for name in rows:
        summarise(name, rows[name], truth, times[name])
    if not have_pyoma:
        print("\npyOMA2: not installed in this environment (pip install pyOMA-2 to compare); see the module "
              "docstring")


def _pyoma_available():
    try:
        import pyoma2  # noqa: F401
        return True
    except ImportError:
        return False


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 50)
