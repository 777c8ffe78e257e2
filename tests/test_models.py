"""Models against textbook worked examples and independent computations."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import vibmeasure as vm
from vibmeasure import models as M


# --- textbook worked examples ----------------------------------------------------------------------
def test_pendulum_gravity():
    # a 2 m pendulum with a period of 2.893 s: g = 4 pi^2 L / T^2 = 9.434 m/s^2
    assert M.pendulum_gravity(2.0, 2.893) == pytest.approx(9.434, abs=5e-4)
    assert M.pendulum_period(2.0, 9.434) == pytest.approx(2.893, abs=1e-3)


def test_decay_to_one_fiftieth():
    # m = 200 kg, zeta = 0.22, k = 40 N/mm: 1/50 of the amplitude in 1.26 s, 2.76 oscillations, Td 0.455 s
    s = M.SDOF(m=200.0, k=40e3, zeta=0.22)
    assert s.time_to_decay(1 / 50) == pytest.approx(1.26, abs=5e-3)
    assert s.Td == pytest.approx(0.455, abs=5e-4)
    assert s.time_to_decay(1 / 50) / s.Td == pytest.approx(2.76, abs=5e-3)


def test_door_critically_damped():
    # J = 20 kg m^2, c = 48 N m s/rad, k = 28.8 N m/rad: critically damped; opened at 4 rad/s: 1.226 rad
    door = M.SDOF(m=20.0, k=28.8, c=48.0)
    assert door.regime == "critically damped" and door.zeta == pytest.approx(1.0)
    t = np.linspace(0, 5, 500001)
    assert door.free_response(t, v0=4.0).max() == pytest.approx(1.226, abs=5e-4)


def test_wheel_stiffness():
    # a 30 kg wheel assembly at 10 Hz needs k = m (2 pi f)^2 = 1.184e5 N/m
    assert M.stiffness_for(10.0, 30.0) == pytest.approx(1.184e5, rel=5e-4)


@pytest.mark.parametrize("zeta", [0.05, 0.1, 0.3])
def test_magnification_peak(zeta):
    s = M.SDOF(m=1.0, k=(2 * np.pi * 10) ** 2, zeta=zeta)
    r = np.linspace(0.01, 2, 200001)
    mag, _ = s.magnification(r * s.fn)
    k = np.argmax(mag)
    assert r[k] == pytest.approx(np.sqrt(1 - 2 * zeta ** 2), abs=2e-5)
    assert mag[k] == pytest.approx(1 / (2 * zeta * np.sqrt(1 - zeta ** 2)), rel=1e-9)


# --- independent computations ----------------------------------------------------------------------
@pytest.mark.parametrize("zeta", [0.0, 0.05, 1.0, 2.0])
def test_sdof_free_response_against_ode(zeta):
    s = M.SDOF(m=2.0, k=800.0, zeta=zeta)
    t = np.linspace(0, 2, 2001)
    sol = solve_ivp(lambda _, y: [y[1], -(s.c * y[1] + s.k * y[0]) / s.m], (0, 2), [0.01, -0.3], t_eval=t,
                    rtol=1e-11, atol=1e-14, method="DOP853")
    np.testing.assert_allclose(s.free_response(t, x0=0.01, v0=-0.3), sol.y[0], atol=1e-10)


def test_sdof_forced_responses_against_ode():
    s = M.SDOF(m=2.0, k=800.0, zeta=0.05)
    t = np.linspace(0, 3, 30001)
    def ode(force):
        return solve_ivp(lambda tt, y: [y[1], (force(tt) - s.c * y[1] - s.k * y[0]) / s.m], (0, 3), [0, 0],
                         t_eval=t, rtol=1e-11, atol=1e-14, method="DOP853").y[0]
    np.testing.assert_allclose(s.step_response(t, 5.0), ode(lambda tt: 5.0), atol=1e-10)
    np.testing.assert_allclose(s.ramp_response(t, 2.0), ode(lambda tt: 2.0 * tt), atol=1e-10)
    f = np.sin(2 * np.pi * 3 * t) * np.exp(-t)
    np.testing.assert_allclose(s.response(t, f), ode(lambda tt: np.sin(2 * np.pi * 3 * tt) * np.exp(-tt)), atol=2e-7)
    # impulse response: the ODE from v0 = 1/m
    np.testing.assert_allclose(s.impulse_response(t), s.free_response(t, v0=1 / s.m), atol=0)
    # periodic force (square-wave Fourier series, 5 harmonics) against the steady state of the ODE
    T = 0.4
    b = [4 / (np.pi * n) if n % 2 else 0.0 for n in range(1, 6)]
    tt = np.linspace(20, 21, 1001)
    steady = solve_ivp(lambda x, y: [y[1], (sum(bn * np.sin(2 * np.pi * (n + 1) * x / T) for n, bn in enumerate(b))
                                              - s.c * y[1] - s.k * y[0]) / s.m], (0, 21), [0, 0], t_eval=tt,
                       rtol=1e-10, atol=1e-13, method="DOP853").y[0]
    np.testing.assert_allclose(s.periodic_response(tt, period=T, b=b), steady, atol=1e-8)


def test_transmissibility_base_unbalance():
    s = M.SDOF(m=1.0, k=(2 * np.pi * 10) ** 2, zeta=0.1)
    r = np.array([0.5, 1.0, np.sqrt(2), 3.0])
    T = s.transmissibility(r * 10)
    np.testing.assert_allclose(T, np.sqrt(1 + (0.2 * r) ** 2) / np.sqrt((1 - r ** 2) ** 2 + (0.2 * r) ** 2), rtol=1e-12)
    assert T[2] == pytest.approx(1.0)  # isolation starts at r = sqrt 2
    base = s.base_excitation(r * 10, Y=1e-3)
    np.testing.assert_allclose(base["absolute"], 1e-3 * T, rtol=1e-12)
    u = s.unbalance_response(r * 10, me=0.01)
    np.testing.assert_allclose(u, 0.01 * r ** 2 / np.sqrt((1 - r ** 2) ** 2 + (0.2 * r) ** 2), rtol=1e-12)


def test_hysteretic_and_coulomb():
    s = M.SDOF(m=1.0, k=1000.0, loss_factor=0.04)
    peak = np.abs(s.frf(s.fn)) * s.k
    assert peak == pytest.approx(1 / 0.04)  # at resonance |X k / F| = 1 / eta
    c = M.SDOF(m=1.0, k=1000.0)
    x = c.coulomb_free_response(np.arange(0, 2, 1e-4), x0=0.01, friction_force=0.5)
    # per cycle the amplitude falls by 4 F / k = 2 mm
    assert x[int(round(1 / c.fn / 1e-4))] == pytest.approx(0.01 - 4 * 0.5 / 1000, abs=1e-9)


def test_mdof_frf_modes_and_response():
    Mm = np.diag([2.0, 1.0, 1.5])
    K = np.array([[3000.0, -1000, 0], [-1000, 2000, -1000], [0, -1000, 1000]])
    sys_ = M.MDOF(Mm, K, rayleigh=(0.5, 1e-4))
    fn, phi = sys_.undamped_modes()
    np.testing.assert_allclose(phi.T @ Mm @ phi, np.eye(3), atol=1e-12)  # mass-normalised
    np.testing.assert_allclose(phi.T @ K @ phi, np.diag((2 * np.pi * fn) ** 2), atol=1e-9)
    f = np.linspace(0.5, 15, 300)
    H = sys_.frf(f)
    w = 2 * np.pi * f
    for i in (0, 150, 299):
        direct = np.linalg.inv(K - w[i] ** 2 * Mm + 1j * w[i] * sys_.C)
        np.testing.assert_allclose(H[:, :, i], direct, rtol=1e-12)
    est = sys_.modes()
    np.testing.assert_allclose(est.zeta, 0.5 / (2 * 2 * np.pi * fn) + 1e-4 * 2 * np.pi * fn / 2, rtol=1e-9)
    t = np.linspace(0, 4, 4001)
    F = np.zeros((3, t.size))
    F[0] = np.sin(2 * np.pi * 2 * t)
    x = sys_.response(t, F)
    Minv = np.linalg.inv(Mm)
    sol = solve_ivp(lambda _, y: np.r_[y[3:], Minv @ (np.r_[np.sin(2 * np.pi * 2 * _), 0, 0] - sys_.C @ y[3:]
                                                     - K @ y[:3])], (0, 4), np.zeros(6), t_eval=t, rtol=1e-10,
                    atol=1e-13, method="DOP853")
    # modal superposition integrates each mode exactly for a force linear between samples; a sine
    # sampled 500 times per period differs from that by ~1e-5 of the response
    np.testing.assert_allclose(x, sol.y[:3], atol=2e-5 * np.abs(sol.y[:3]).max())


def test_complex_modes_of_general_damping():
    Mm = np.diag([1.0, 1.0])
    K = np.array([[2000.0, -1000], [-1000, 1000]])
    C = np.array([[3.0, 0], [0, 0.1]])  # not proportional
    sys_ = M.MDOF(Mm, K, C)
    assert not sys_.is_proportional()
    est = sys_.modes()
    lam, _ = sys_.complex_modes()
    # each eigenvalue solves det(K + lambda C + lambda^2 M) = 0
    for l in lam:
        assert abs(np.linalg.det(K + l * C + l ** 2 * Mm)) < 1e-6 * np.abs(K).max() ** 2
    assert np.all(est.zeta > 0) and np.all(np.diff(est.fn) > 0)


def test_absorber_and_den_hartog():
    mu = 0.05
    opt = M.den_hartog(mu)
    assert opt["frequency_ratio"] == pytest.approx(1 / 1.05)
    assert opt["zeta"] == pytest.approx(np.sqrt(3 * mu / (8 * 1.05 ** 3)))
    # an undamped absorber tuned to the main system cancels the main mass motion at that frequency
    k1, m1 = 1000.0, 1.0
    sys_ = M.absorber(m1, k1, mu * m1, mu * k1)
    f0 = np.sqrt(k1 / m1) / (2 * np.pi)
    assert abs(sys_.frf([f0])[0, 0, 0]) < 1e-12


@pytest.mark.parametrize("bc,roots", [("cantilever", [1.8751, 4.6941, 7.8548]),
                                      ("simply-supported", [np.pi, 2 * np.pi, 3 * np.pi]),
                                      ("clamped-clamped", [4.7300, 7.8532, 10.9956]),
                                      ("free-free", [4.7300, 7.8532, 10.9956]),
                                      ("clamped-pinned", [3.9266, 7.0686, 10.2102])])
def test_beam_roots_against_published(bc, roots):
    np.testing.assert_allclose(M.beta_l(bc, 3), roots, atol=5e-5)
    b = M.Beam(E=210e9, I=1e-8, rho=7850, A=1e-4, L=1.0, bc=bc)
    fn = b.modes(3).fn
    np.testing.assert_allclose(fn, np.array(roots) ** 2 / (2 * np.pi) * np.sqrt(210e9 * 1e-8 / (7850 * 1e-4)),
                               rtol=5e-5)
    # the shape is scaled to 1 at its true largest point, which a grid of 101 points may straddle
    y = b.shape(2, np.linspace(0, 1, 101))
    assert 0.999 < np.max(np.abs(y)) <= 1 + 1e-9
    assert np.max(np.abs(b.shape(2, np.linspace(0, 1, 20001)))) == pytest.approx(1.0, abs=1e-7)


def test_rod_string_stiffness_pendulum_whirl():
    rod = M.Rod(E=200e9, rho=8000, L=2.0, bc="fixed-free")
    c = np.sqrt(200e9 / 8000)
    np.testing.assert_allclose(rod.modes(2).fn, [c / 8, 3 * c / 8])
    np.testing.assert_allclose(M.String(T=100.0, mu=0.01, L=0.5).modes(2).fn, [100.0, 200.0])
    assert M.stiffness("cantilever", E=2e11, I=1e-8, L=1.0) == pytest.approx(6000.0)
    assert M.stiffness("simply-supported", E=2e11, I=1e-8, L=1.0) == pytest.approx(96000.0)
    assert M.series(1000.0, 1000.0) == pytest.approx(500.0) and M.parallel(1000.0, 1000.0) == 2000.0
    # a uniform bar of length l pivoted at its end: I = m l^2 / 3, d = l / 2 -> wn = sqrt(3 g / (2 l))
    assert M.compound_pendulum_fn(mass=1.0, inertia_pivot=1 / 3, distance=0.5) == pytest.approx(
        np.sqrt(1.5 * 9.80665) / (2 * np.pi))
    assert M.whirling_speed_rpm(k=1e6, m=10.0) == pytest.approx(np.sqrt(1e5) * 60 / (2 * np.pi))


# --- TOML, updating, bad input ---------------------------------------------------------------------
def test_load_toml_models(tmp_path):
    p = tmp_path / "sdof.toml"
    p.write_text('type = "sdof"\n[parameters]\nm = "200 kg"\nk = "40 N/mm"\nzeta = 0.22\n')
    s = M.load(p)
    assert s.k == 40e3 and s.m == 200.0
    q = tmp_path / "mdof.toml"
    q.write_text('type = "mdof"\n[parameters]\nM = { value = [[2, 0], [0, 1]], unit = "kg" }\n'
                 'K = { value = [[3, -1], [-1, 1]], unit = "kN/m" }\nmodal_zeta = [0.02, 0.02]\n')
    m = M.load(q)
    assert m.n_dof == 2 and m.K[0, 0] == 3000.0
    b = tmp_path / "beam.toml"
    b.write_text('type = "beam"\n[parameters]\nE = "210 GPa"\nI = "1e4 mm^4"\nrho = "7850 kg/m^3"\n'
                 'A = "100 mm^2"\nL = "1 m"\nbc = "cantilever"\n')
    assert M.load(b).modes(1).fn[0] == pytest.approx(1.8751 ** 2 / (2 * np.pi) * np.sqrt(210e9 * 1e-8 / 0.785), rel=1e-4)
    for text, match in [('type = "plate"\n[parameters]\nm = "1 kg"\n', "type='plate'"),
                        ('type = "sdof"\n[parameters]\nm = 200\nk = "1 N/m"\n', "has no unit"),
                        ('type = "sdof"\n[parameters]\nm = "200 N/m"\nk = "1 N/m"\n', "must be a mass"),
                        ('type = "sdof"\n[parameters]\nm = "2 kg"\nk = "1 furlong"\n', "unit 'furlong'")]:
        bad = tmp_path / "bad.toml"
        bad.write_text(text)
        with pytest.raises(vm.ParameterError, match=match):
            M.load(bad)


def test_update_sdof_and_mdof():
    est = vm.ModalEstimate(fn=[12.5], zeta=[0.02], fn_std=[0.01], zeta_std=[0.001])
    u = M.update_sdof(est, m=2.0)
    assert u["k"] == pytest.approx(2.0 * (2 * np.pi * 12.5) ** 2)
    assert u["k_std"] / u["k"] == pytest.approx(2 * 0.01 / 12.5, rel=1e-9)  # dk/k = 2 df/f
    assert u["model"].zeta == pytest.approx(0.02)
    sys_ = M.MDOF(np.diag([1.0, 1.0]), np.array([[2000.0, -1000], [-1000, 1000]]))
    fn = sys_.modes().fn * np.sqrt(0.9)
    up = M.update_mdof(sys_, vm.ModalEstimate(fn=fn, zeta=[0.01, 0.01], fn_std=fn * 1e-4, zeta_std=[1e-3, 1e-3]))
    assert up["k_scale"] == pytest.approx(0.9, rel=1e-9)


@pytest.mark.parametrize("call,match", [
    (lambda: M.SDOF(m=0.0, k=1.0), "m="), (lambda: M.SDOF(m=1.0, k=-1.0), "k="),
    (lambda: M.SDOF(m=1.0, k=1.0, zeta=0.1, c=1.0), "one of c and zeta"),
    (lambda: M.SDOF(m=1.0, k=1.0, zeta=1.5).fd, "zeta=1.5 >= 1"),
    (lambda: M.MDOF(np.eye(2), np.array([[1.0, 2.0], [0.0, 1.0]])), "symmetric"),
    (lambda: M.MDOF(np.eye(2), np.array([[1.0, 2.0], [2.0, 1.0]])), "positive definite"),
    (lambda: M.MDOF(np.eye(2), np.eye(3)), "same shape"),
    (lambda: M.Beam(E=1.0, I=1.0, rho=1.0, A=1.0, L=1.0, bc="hinged"), "bc="),
])
def test_bad_input(call, match):
    with pytest.raises(vm.ParameterError, match=match):
        call()
