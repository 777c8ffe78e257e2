"""The estimators at the edges of their validity (issue 45): each case as a user meets it, and the figure
vibmeasure gives. Run it on an older checkout (PYTHONPATH=that/checkout) to see the same cases before.

  1. half_power on a ring-down, noise-free, zeta 0.05-0.3 at 9 phases: worst |fn| and |zeta| error.
  2. half_power on a ring-down with an offset and a drift of 0.1 units/s (zeta 0.05, 40 dB).
  3. half_power's std against its scatter (zeta 0.02, 40 dB, 60 seeds).
  4. log_decrement on two modes (10 and 25 Hz, amplitude ratio 0.5): zeta error and flag; and on
     single-mode decays (zeta 0.001-0.1, 20-60 dB, 5 seeds): how many are flagged.
  5. half_power of an FRF holding NaN lines outside its band (a swept sine without power there).
  6. oma_fdd without band=; the OMA duration rule on a 10 s record with a 8.9 Hz mode.
  7. vm.read of whitespace-separated columns (.asc).
  8. The README's Coulomb decay (friction 4e-4 per cycle) through ringdown and the classic estimators.
  9. vm.srs of a record that starts at 1 (fs 1 kHz) against scipy's lsim, oscillators below and above fs/32.

    python benchmarks/edges.py            (about 30 s)
"""

import dataclasses
import tempfile
import warnings
from pathlib import Path

import numpy as np

import vibmeasure as vm


def case(name, fn):
    try:
        print(f"{name}: {fn()}")
    except Exception as exc:  # noqa: BLE001 - an edge case's outcome is what we print
        print(f"{name}: {type(exc).__name__}: {str(exc)[:150]}")


def half_power_bias():
    out = []
    for z in (0.05, 0.1, 0.2, 0.3):
        worst_f = worst_z = 0.0
        for ph in np.linspace(0, np.pi, 9):
            rec = vm.synth.free_decay(fn=10.0, zeta=z, fs=1000.0, duration=20.0, phase=ph)
            try:
                e = vm.half_power(rec)
            except vm.FitError as exc:
                out.append(f"zeta {z}: refused ({str(exc)[:60]})")
                break
            worst_f, worst_z = max(worst_f, abs(e.fn[0] / 10 - 1)), max(worst_z, abs(e.zeta[0] / z - 1))
        else:
            out.append(f"zeta {z}: fn {100 * worst_f:.3f} %, zeta {100 * worst_z:.3f} %")
    return "; ".join(out)


def half_power_drift():
    rec = vm.synth.free_decay(fn=10.0, zeta=0.05, fs=1000.0, duration=10.0, snr_db=40, seed=1, dc_offset=0.1,
                              drift=0.1)
    e = vm.half_power(rec)
    return f"zeta {e.zeta[0]:.5f} (true 0.05) +- {e.zeta_std[0]:.2g}"


def half_power_std():
    errs, stds = [], []
    for seed in range(60):
        e = vm.half_power(vm.synth.free_decay(fn=10.0, zeta=0.02, fs=1000.0, duration=20.0, snr_db=40, seed=seed))
        errs.append(e.zeta[0] - 0.02)
        stds.append(e.zeta_std[0])
    if not np.isfinite(np.mean(stds)):
        return "no std (NaN)"
    return f"RMS error / mean std = {np.sqrt(np.mean(np.square(errs))) / np.mean(stds):.2f}"


def log_decrement_modes():
    two = vm.synth.free_decay(fn=[10.0, 25.0], zeta=[0.02, 0.02], amplitude=[1.0, 0.5], fs=1000.0, duration=10.0,
                              snr_db=40, seed=3)
    e = vm.log_decrement(two)
    flagged = tot = 0
    for z in (0.001, 0.005, 0.02, 0.1):
        for snr in (20, 40, 60):
            for seed in range(5):
                try:
                    s = vm.log_decrement(vm.synth.free_decay(fn=10.0, zeta=z, fs=1000.0, duration=10.0, snr_db=snr,
                                                             seed=seed))
                except vm.FitError:
                    continue
                tot += 1
                flagged += "several_modes" in s.flags
    return (f"two modes: zeta {100 * (e.zeta[0] / 0.02 - 1):+.1f} %, flags {list(e.flags)}; single modes flagged "
            f"several_modes: {flagged} of {tot}")


def half_power_nan_outside_band():
    h = vm.synth.modal_frf(np.linspace(1, 100, 4000), fn=[30.0], zeta=[0.02], shapes=[[1.0]], form="mobility")
    holed = h.h.copy()
    holed[..., :200] = np.nan
    return f"zeta {vm.half_power(dataclasses.replace(h, h=holed), band=(20, 40)).zeta[0]:.5f} (true 0.02)"


def oma_defaults():
    m = vm.models.MDOF(np.eye(3), np.array([[2e4, -1e4, 0], [-1e4, 2e4, -1e4], [0, -1e4, 1e4]]), modal_zeta=[0.02] * 3)
    amb = vm.synth.ambient(m, fs=100.0, duration=300.0, noise=0.05, seed=1)
    fdd = vm.oma_fdd(amb)
    return f"oma_fdd without band: {np.round(fdd.fn, 2).tolist()} Hz (true {np.round(m.modes().fn, 2).tolist()})"


def oma_duration():
    m = vm.models.MDOF(np.eye(3), np.array([[2e4, -1e4, 0], [-1e4, 2e4, -1e4], [0, -1e4, 1e4]]), modal_zeta=[0.02] * 3)
    amb = vm.synth.ambient(m, fs=100.0, duration=12.0, noise=0.05, seed=1)
    e = vm.oma_ssi(amb, band=(1, 40), n_blocks=5)
    return "; ".join(f"{f:.2f} Hz {list(fl)}" for f, fl in zip(e.fn, e.mode_flags))


def read_whitespace():
    p = Path(tempfile.mkdtemp()) / "log.asc"
    p.write_text("acc1 acc2\n 0.125  -1.5e-3\n 0.250   2.0e-3\n-0.375   1.0e-3\n")
    r = vm.read(p, fs=100.0)
    return f"{r.names} {r.data.tolist()}"


def coulomb():
    rec = vm.synth.coulomb_decay(fn=4.2, friction_decay=4e-4, amplitude=5e-3, fs=500, duration=6)
    out = []
    for method in (vm.ringdown, vm.log_decrement, vm.half_power, vm.hilbert_decay):
        e = method(rec)
        fric = e.extras.get("friction_decay_per_cycle")
        out.append(f"{method.__name__}: zeta {e.zeta[0]:.4g}, coulomb_friction {'coulomb_friction' in e.flags}"
                   + (f" ({fric:.3g}/cycle)" if fric is not None else ""))
    return "; ".join(out)


def srs_first_sample():
    from scipy import signal as sg
    fs, n = 1000.0, 2000
    x = np.ones(n)
    x[1000:] = 0.5
    fn = np.array([20.0, 40.0, 100.0, 200.0])
    sp = vm.srs(vm.Record.from_array(x, fs=fs, unit="m/s^2"), fn=fn, zeta=0.05)
    t0, u0 = np.arange(-1, n) / fs, np.concatenate([[0.0], x])
    out = []
    for f, v in zip(fn, sp.values["maximax"]):
        w = 2 * np.pi * f
        tt = np.linspace(t0[0], t0[-1] + 1.0, 600001)
        _, yy, _ = sg.lsim(sg.lti([0.1 * w, w ** 2], [1, 0.1 * w, w ** 2]), np.interp(tt, t0, u0, right=0.0), tt - tt[0])
        out.append(f"{f:g} Hz {100 * (v / np.abs(yy).max() - 1):+.4f} %")
    return ", ".join(out)


def srs_residual_high_damping():
    from scipy import signal as sg
    fs, tau = 20_000.0, 2e-3
    t = np.arange(41) / fs
    x = np.where(t < tau, 50.0 * np.sin(np.pi * t / tau), 0.0)
    t0, u0 = np.arange(-1, x.size) / fs, np.concatenate([[0.0], x])
    out = []
    for z in (0.7, 0.9):
        sp = vm.srs(vm.Record.from_array(x, fs=fs, unit="m/s^2"), fn=[200.0, 1000.0], zeta=z)
        for k, f in enumerate((200.0, 1000.0)):
            w = 2 * np.pi * f
            tt = np.linspace(t0[0], t0[-1] + 20.0 / f, 400001)
            _, yy, _ = sg.lsim(sg.lti([2 * z * w, w ** 2], [1, 2 * z * w, w ** 2]), np.interp(tt, t0, u0, right=0.0),
                               tt - tt[0])
            exact = max(yy[tt >= t0[-1]].max(), 0.0)
            out.append(f"zeta {z} {f:g} Hz {sp.extras['residual_positive'][k]:.3f} / {exact:.3f}")
    return ", ".join(out)


def tower(seed):
    """Four modes like a tall building's (two bending modes 0.06 Hz apart, torsion, a higher bending) and
    two above, random orthonormal shapes over 6 dofs, 4 sensors, 600 s at 20 Hz."""
    fns = np.array([1.23, 1.29, 1.45, 3.86, 6.0, 7.5])
    phi, _ = np.linalg.qr(np.random.default_rng(5).standard_normal((6, 6)))
    k = phi @ np.diag((2 * np.pi * fns) ** 2) @ phi.T
    model = vm.models.MDOF(np.eye(6), (k + k.T) / 2, modal_zeta=[0.012, 0.015, 0.012, 0.015, 0.02, 0.02])
    return vm.synth.ambient(model, fs=20.0, duration=600.0, noise=0.05, seed=seed, outputs=[0, 1, 2, 3])


def oma_close_pair():
    out = []
    for seed in range(3):
        rec = tower(seed)
        fdd = vm.oma_fdd(rec, band=(0.8, 5))
        ssi = vm.oma_ssi(rec, band=(0.8, 5))
        line = (f"seed {seed}: SSI {np.round(ssi.fn, 3).tolist()}, FDD {np.round(fdd.fn, 3).tolist()} flags "
                f"{list(fdd.flags)}")
        if hasattr(vm, "oma_cross_check"):
            both = vm.oma_cross_check(ssi, fdd)
            line += f", SSI modes not confirmed {sum('not_confirmed' in f for f in both.mode_flags)}"
        out.append(line)
    return "; ".join(out)


def oma_chain_fdd():
    chain = vm.models.MDOF(np.eye(3), np.array([[2e4, -1e4, 0], [-1e4, 2e4, -1e4], [0, -1e4, 1e4]]),
                           modal_zeta=[0.02] * 3)
    fdd = vm.oma_fdd(vm.synth.ambient(chain, fs=100.0, duration=300.0, noise=0.05, seed=1))
    return f"fn {np.round(fdd.fn, 3).tolist()} zeta {np.round(fdd.zeta, 4).tolist()} +- {np.round(fdd.zeta_std, 4).tolist()}"


def oma_cross_check_false_alarms():
    if not hasattr(vm, "oma_cross_check"):
        return "no oma_cross_check"
    import sys
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from oma import system
    model, sensors = system()
    n = disagree = unconfirmed = 0
    for seed in range(20):
        rec = vm.synth.ambient(model, fs=200.0, duration=600.0, outputs=sensors, noise=0.05, seed=seed)
        both = vm.oma_cross_check(vm.oma_ssi(rec, band=(1, 80)), vm.oma_fdd(rec, band=(1, 80)))
        n += both.n_modes
        disagree += sum("methods_disagree" in f for f in both.mode_flags)
        unconfirmed += sum("not_confirmed" in f for f in both.mode_flags)
    return f"{n} SSI modes on 20 records of the OMA benchmark: {disagree} methods_disagree, {unconfirmed} not_confirmed"


SHARED = Path(__file__).resolve().parents[2] / "shared" / "data"


def fit_modes_nested_bands():
    rec = vm.read(SHARED / "impact" / "case1.mat")
    rec = rec.replace(channels=(vm.Channel("Time_chan_1", "force"), vm.Channel("Time_chan_2")))
    frf = vm.impact_frf(rec, input="Time_chan_1")
    out = []
    for band in ((20, 50), (10, 100), (10, 300), (10, 600)):
        try:
            est = vm.fit_modes(frf, band=band)
        except vm.FitError as exc:
            out.append(f"{band}: FitError {str(exc)[:60]}")
            continue
        k = int(np.argmin(np.abs(est.fn - 34.06)))
        if abs(est.fn[k] - 34.06) < 0.1:
            out.append(f"{band}: 34 Hz zeta {est.zeta[k]:.3g} +- {est.zeta_std[k]:.2g}")
        else:
            rej = [d for d in est.extras["rejected_modes"] if abs(d["fn_hz"] - 34.06) < 0.2]
            out.append(f"{band}: 34 Hz refused ({rej[0]['reason'][:55] if rej else 'not found'})")
    # synthetic: three modes, 1 % complex noise, the 21.3 Hz mode in three nested bands
    freq = np.arange(0.25, 150.25, 0.25)
    clean = vm.synth.modal_frf(freq, fn=[21.3, 57.9, 110.4], zeta=[0.01, 0.02, 0.015], shapes=[[1.0, 0.8, 0.6]])
    rng = np.random.default_rng(0)
    h = clean.h + 0.01 * np.abs(clean.h).max() * (rng.standard_normal(clean.h.shape)
                                                  + 1j * rng.standard_normal(clean.h.shape)) / np.sqrt(2)
    noisy = dataclasses.replace(clean, h=h)
    syn = []
    for band in ((12, 32), (5, 80), (1, 150)):
        est = vm.fit_modes(noisy, band=band)
        k = int(np.argmin(np.abs(est.fn - 21.3)))
        syn.append(f"{band}: {est.zeta[k]:.5f} +- {est.zeta_std[k]:.2g}")
    return "; ".join(out) + " | synthetic 21.3 Hz mode: " + "; ".join(syn)


def swept_sine_frf():
    from scipy.signal import chirp
    fs, out = 1000.0, []
    for f0, f1, dur in ((1, 100, 20), (5, 60, 40), (1, 200, 10), (2, 80, 30)):
        t = np.arange(int(dur * fs)) / fs
        force = chirp(t, f0, dur, f1, method="logarithmic")
        x = vm.synth.modal_response(force, fs=fs, fn=[25.0], zeta=[0.02], shapes=[[1.0]])[0]
        rec = vm.Record(np.vstack([force, x]), fs=fs, channels=[vm.Channel("F", "force", "N"),
                                                                 vm.Channel("x", "displacement", "m")])
        est = vm.fit_modes(vm.estimate_frf(rec, input="F"), band=(10, 50))
        out.append(f"{f0}-{f1} Hz in {dur} s: fn {np.round(est.fn, 3).tolist()} zeta {np.round(est.zeta, 4).tolist()}")
    return "; ".join(out)


def _duffing(k3_over_k, zeta=0.005, fn=10.0, fs=1000.0, T=12.0, noise=1e-3, friction=0.0, seed=0):
    """Exact Duffing (and dry friction) decay of a unit mass released from x = 1 (solve_ivp, rtol 1e-10)."""
    from scipy.integrate import solve_ivp
    w0 = 2 * np.pi * fn
    k, k3, c = w0 ** 2, k3_over_k * w0 ** 2, 2 * zeta * w0
    t = np.arange(int(T * fs)) / fs

    def f(_, y):
        return [y[1], -c * y[1] - k * y[0] - k3 * y[0] ** 3 - friction * np.tanh(y[1] / (1e-3 * w0))]
    x = solve_ivp(f, (0, T), [1.0, 0.0], t_eval=t, rtol=1e-10, atol=1e-12, method="DOP853").y[0]
    return vm.Record.from_array(x + noise * np.random.default_rng(seed).standard_normal(t.size), fs=fs)


def backbone_coverage():
    out = []
    cases = [(k3k, 0.0) for k3k in (0.02, 0.05, 0.1, 0.2)] + [(0.0, 3.0), (0.05, 3.0)]
    for k3k, fric in cases:
        zk, zf, zz, fits, modes = [], [], [], 0, []
        for seed in range(34 if fric == 0 else 32):
            est = vm.ringdown(_duffing(k3k, friction=fric, T=12.0 if fric == 0 else 6.0, seed=seed))
            modes.append(est.n_modes)
            m = est.extras.get("backbone_model", {}).get(0)
            if not m or not m.get("fits", True):
                continue
            fits += 1
            zk.append((m["k3_over_k"] - k3k) / m["k3_over_k_std"])
            zz.append((m["zeta_viscous"] - 0.005) / m["zeta_viscous_std"])
            if fric:
                zf.append((m["friction_term"] - 2 * fric / (np.pi * (2 * np.pi * 10.0) ** 2)) / m["friction_term_std"])
        rms = lambda z: f"{np.sqrt(np.mean(np.square(z))):.2f}" if z else "-"
        out.append(f"k3/k {k3k} friction {fric}: modes {min(modes)}-{max(modes)}, model fits {fits}/{len(modes)}, "
                   f"z-rms k3 {rms(zk)} zeta_v {rms(zz)}" + (f" friction {rms(zf)}" if fric else ""))
    return "; ".join(out)


def main():
    warnings.simplefilter("ignore")
    case("1. half_power on ring-downs (noise-free, worst over 9 phases)", half_power_bias)
    case("2. half_power with offset and drift", half_power_drift)
    case("3. half_power std", half_power_std)
    case("4. log_decrement, several modes", log_decrement_modes)
    case("5. half_power of an FRF with NaN lines outside the band", half_power_nan_outside_band)
    case("6a. oma_fdd defaults", oma_defaults)
    case("6b. OMA duration rule (12 s record, 3-DOF chain, band 1-40 Hz)", oma_duration)
    case("7. vm.read of whitespace-separated columns", read_whitespace)
    case("8. a Coulomb decay", coulomb)
    case("9. srs of a record starting at 1, against lsim", srs_first_sample)
    case("10. srs positive residual of a half-sine at high damping (vibmeasure / lsim)", srs_residual_high_damping)
    case("11. OMA close pair 1.23 / 1.29 Hz (tower, 600 s)", oma_close_pair)
    case("12. oma_fdd on the guide's 3-DOF chain, seed 1 (truth 7.083 / 19.846 / 28.679 Hz, zeta 0.02)", oma_chain_fdd)
    case("13. SSI-FDD cross-check false alarms", oma_cross_check_false_alarms)
    case("14. fit_modes of case1.mat in nested bands", fit_modes_nested_bands)
    case("15. swept-sine FRF (default estimate_frf) of one 25 Hz mode, zeta 0.02", swept_sine_frf)
    case("16. backbone model on exact Duffing / friction decays (200 seeds): z = (estimate - truth) / std",
         backbone_coverage)


if __name__ == "__main__":
    main()
