"""The textbook both ways (issue 51): each model and inverse calculation against its closed form or a
textbook figure, the largest relative error printed beside the figure it reproduces.

    python benchmarks/textbook.py            (about 20 s)
"""

import time
import warnings

import numpy as np

import vibmeasure as vm

M = vm.models
rows = []


def row(what, got, ref, note=""):
    got, ref = np.atleast_1d(np.asarray(got, float)), np.atleast_1d(np.asarray(ref, float))
    err = float(np.max(np.abs(got / ref - 1)))
    rows.append((what, err, note))


# hysteretic damping: the FRF's peak, Q, zeta, modes and the free decay agree
s = M.SDOF(m=1.0, k=1000.0, loss_factor=0.04)
row("loss factor 0.04: FRF peak |X k/F| = Q = 1/eta", np.abs(s.frf(s.fn)) * s.k, s.Q)
row("loss factor 0.04: modes() zeta = eta/2", s.modes().zeta[0], 0.02)
t = np.arange(0, 3, 1e-3)
x = s.response(t, np.zeros(t.size), x0=1.0)
pk = [abs(x[int(round(n / s.fd / 1e-3))]) for n in (0, 5)]
row("loss factor 0.04: response() decrement over 5 cycles", np.log(pk[0] / pk[1]) / 5, s.log_decrement,
    "sampled at 1 ms: peaks read on the grid")

# inverse calculations, round trips through the forward model
for z in (0.01, 0.1, 0.4):
    sd = M.SDOF(m=1.0, k=(2 * np.pi * 10) ** 2, zeta=z)
    f = np.linspace(5, 15, 2_000_001)
    mag = sd.magnification(f)[0]
    row(f"zeta {z} from peak magnification", M.zeta_from_magnification(mag.max()), z, "5 uHz grid")
    row(f"zeta {z} from peak frequency", M.zeta_from_peak_frequency(f[np.argmax(mag)], 10.0), z, "5 uHz grid")
for z in (0.0, 0.05, 0.2):
    k = M.isolator_stiffness(250.0, 24.0, 0.08, zeta=z)
    row(f"isolator for T = 0.08 at zeta {z}", M.SDOF(m=250.0, k=k, zeta=z).transmissibility([24.0])[0], 0.08)
t0 = M.pendulum_period(1.0)
for deg, ratio in ((30, 1.01741), (90, 1.18034), (150, 1.76220)):
    row(f"pendulum T/T0 at {deg} deg (table {ratio})",
        M.pendulum_period(1.0, amplitude=np.radians(deg)) / t0, ratio, "table to 5 decimals")
row("fn from 10 mm static deflection (4.984 Hz)", M.fn_from_deflection(0.01), 4.98403, "to 5 digits")

# loop damping
fs, f0, X = 2000.0, 8.0, 2e-3
tt = np.arange(int(12 * fs / f0)) / fs
xx = X * np.sin(2 * np.pi * f0 * tt)
xd = np.gradient(xx, tt)
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    for name, F, W in (("viscous c 40", 5e4 * xx + 40 * X * 2 * np.pi * f0 * np.cos(2 * np.pi * f0 * tt),
                        np.pi * 40 * 2 * np.pi * f0 * X ** 2),
                       ("hysteretic eta 0.05", 5e4 * xx + 0.05 * 5e4 * X * np.cos(2 * np.pi * f0 * tt),
                        np.pi * 0.05 * 5e4 * X ** 2),
                       ("Coulomb 6 N", 5e4 * xx + 6 * np.sign(xd), 4 * 6 * X)):
        row(f"loop energy per cycle, {name}", vm.loop_damping(xx, F, fs=fs).energy_per_cycle, W,
            "250 samples a cycle")

# chains, tip mass
n, kk, mm = 5, 2e4, 3.0
fn, _ = M.chain([mm] * n, [kk] * n).undamped_modes()
r = np.arange(1, n + 1)
row("5-mass chain, 2 sqrt(k/m) sin((2r-1) pi / 22)", fn,
    2 * np.sqrt(kk / mm) * np.sin((2 * r - 1) * np.pi / (2 * (2 * n + 1))) / (2 * np.pi))
bare = M.tip_mass_beam(E=70e9, I=2e-9, rho=2700.0, A=1.2e-4, L=0.6, tip_mass=0.0)
rows.append(("Rayleigh 33/140 on a bare cantilever: +1.47 % over exact", bare["error_pct"] / 100, "an error"))
for mu in (0.5, 1.0, 5.0):
    loaded = M.tip_mass_beam(E=70e9, I=2e-9, rho=2700.0, A=1.2e-4, L=0.6, tip_mass=mu * 2700 * 1.2e-4 * 0.6)
    rows.append((f"Rayleigh 33/140 with tip mass {mu} x beam", loaded["error_pct"] / 100, "an error"))

# beam theories
for bc in ("cantilever", "simply-supported", "clamped-clamped", "free-free", "clamped-pinned"):
    w = vm.models.Beam(E=1.0, I=1.0, rho=1.0, A=1.0, L=1.0, bc=bc)
    from vibmeasure.models._beam_solver import _Section
    row(f"exact solver, EB {bc}, 20 modes vs beta_l", np.sqrt(_Section(1, 1, 0, None, 1, bc).omegas(20)),
        M.beta_l(bc, 20))
E, nu, kap, rho, b, h, L = 210e9, 0.3, 5 / 6, 7850.0, 0.05, 0.1, 1.2
A, I, G = b * h, b * h ** 3 / 12, E / (2 * (1 + nu))
tw = 2 * np.pi * M.TimoshenkoBeam(E=E, I=I, rho=rho, A=A, L=L, bc="simply-supported", nu=nu).modes(3).fn
ref = []
for k in np.pi * np.arange(1, 4) / L:
    a = rho ** 2 * I / (kap * G)
    bb = rho * A + rho * I * k ** 2 + E * I * k ** 2 * rho / (kap * G)
    ref.append(np.sqrt((bb - np.sqrt(bb ** 2 - 4 * a * E * I * k ** 4)) / (2 * a)))
row("Timoshenko simply supported, 3 modes, closed form", tw, ref)
row("Rayleigh 1 % slenderness (SS), pi / sqrt(1/0.99^2 - 1)", M.slenderness_limit("simply-supported",
    theory="rayleigh"), np.pi / np.sqrt(1 / 0.99 ** 2 - 1))
limits = {bc: M.slenderness_limit(bc, tolerance=0.01) for bc in ("cantilever", "simply-supported",
                                                                  "clamped-clamped")}

# modal expansion
bm = M.Beam(E=210e9, I=1e-8, rho=7850.0, A=1e-4, L=1.0)
row("cantilever effective mass 61.3/18.8/6.5 %", bm.effective_mass(3) / 0.785, [0.6131, 0.1883, 0.0647],
    "textbook to 4 digits")
row("cantilever tip static compliance L^3/3EI, 40 modes", bm.frf([0.0], at=1.0, force_at=1.0, n_modes=40)[0].real,
    1 / (3 * 210e9 * 1e-8), "truncation")
tb = M.TimoshenkoBeam(E=210e9, I=8.33e-6, rho=7850.0, A=0.01, L=0.5, nu=0.3)
row("Timoshenko tip compliance + L/(kappa G A), 40 modes", tb.frf([0.0], at=0.5, force_at=0.5, n_modes=40)[0].real,
    0.125 / (3 * 210e9 * 8.33e-6) + 0.5 / (5 / 6 * 210e9 / 2.6 * 0.01), "truncation: shear converges as 1/n")

# stepped sine and anti-resonances
sd = M.SDOF(m=1.0, k=(2 * np.pi * 20) ** 2, zeta=0.02)
tones, fs, dwell = np.linspace(12, 28, 9), 2000.0, 3.0
ts = np.arange(int(dwell * fs)) / fs
F = np.concatenate([np.sin(2 * np.pi * ft * ts) for ft in tones])
xr = sd.response(np.arange(F.size) / fs, F)
rng = np.random.default_rng(0)
rec = vm.Record(np.vstack([F + rng.normal(size=F.size) * 0.01, xr + rng.normal(size=F.size) * 0.01 * np.std(xr)]),
                fs=fs, channels=[vm.Channel("F", "force", "N"), vm.Channel("x", "displacement", "m")])
frf = vm.stepped_sine(rec, tones, settle=0.8)
row("stepped sine, 9 tones, 1 % noise", np.abs(frf.h[0, 0]), np.abs(sd.frf(tones)), "noise")
worst_sigma = float(np.max(np.abs(frf.h[0, 0] / sd.frf(tones) - 1) / frf.random_error[0]))
three = M.chain([1.0] * 3, [1e4] * 3, modal_zeta=0.001)
fq = np.linspace(1, 40, 39001)
ar = vm.antiresonances(vm.FRF(freq=fq, h=three.frf(fq)[2, 2]))
row("anti-resonances of the top mass = chain with it held", ar["antiresonances"],
    np.sqrt([1e4, 3e4]) / (2 * np.pi), "1 mHz grid, zeta 0.001")

t1 = time.perf_counter()
M.TimoshenkoBeam(E=E, I=I, rho=rho, A=A, L=L).modes(10)
t_modes = time.perf_counter() - t1

w = max(len(r[0]) for r in rows)
print(f"{'check':<{w}}  {'rel. error':>10}  note")
for what, err, note in rows:
    print(f"{what:<{w}}  {err:>10.2e}  {note}")
print(f"\nstepped sine: worst tone {worst_sigma:.2f} of its own std from the closed form")
print("slenderness L/r below which Timoshenko is >1 % below Euler-Bernoulli (mode 1, rectangle, nu 0.3): "
      + ", ".join(f"{bc} {v:.1f}" for bc, v in limits.items()))
print(f"Timoshenko cantilever, 10 modes: {t_modes * 1e3:.0f} ms")
