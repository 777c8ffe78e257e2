"""The textbook both ways (issue 51): each model and each inverse calculation against a closed form or a
textbook's worked figure, with the tolerance and its reason beside it."""

import warnings

import numpy as np
import pytest

import vibmeasure as vm
from vibmeasure.models import beams as B

M = vm.models
EXACT = 1e-9        # closed form against closed form: only rounding differs


# --- hysteretic damping: one definition across every property ------------------------------------------
def test_loss_factor_is_equivalent_viscous_everywhere():
    s = M.SDOF(m=1.0, k=1000.0, loss_factor=0.04)
    assert s.zeta == pytest.approx(0.02, rel=EXACT)
    assert s.Q == pytest.approx(25.0, rel=EXACT)                       # = 1 / eta
    assert np.abs(s.frf(s.fn)) * s.k == pytest.approx(s.Q, rel=EXACT)  # the FRF's peak says the same Q
    assert s.modes().zeta[0] == pytest.approx(0.02, rel=EXACT)
    assert s.log_decrement == pytest.approx(2 * np.pi * 0.02 / np.sqrt(1 - 0.02 ** 2), rel=EXACT)
    t = np.arange(0, 2.0, 1e-3)
    # free and transient responses decay at the equivalent rate exp(-zeta wn t)
    env = np.exp(-0.02 * s.wn * t)
    x = s.free_response(t, x0=1.0)
    assert np.all(np.abs(x) <= env * (1 + 1e-9) / np.sqrt(1 - 0.02 ** 2))
    y = s.response(t, np.zeros(t.size), x0=1.0)
    np.testing.assert_allclose(y, x, atol=1e-9)
    both = M.SDOF(m=1.0, k=1000.0, c=2.0, loss_factor=0.04)
    assert both.zeta == pytest.approx(2.0 / both.c_crit + 0.02, rel=EXACT)
    assert both.c_equivalent == pytest.approx(2.0 + 0.04 * 1000.0 / both.wn, rel=EXACT)


def test_initial_conditions_add_the_free_response():
    s = M.SDOF(m=2.0, k=5000.0, zeta=0.03)
    t = np.arange(0, 1.0, 1e-3)
    F = np.sin(2 * np.pi * 3 * t)
    # linear superposition: forced from rest plus free from (x0, v0); lsim is exact for a piecewise-linear force
    np.testing.assert_allclose(s.response(t, F, x0=0.01, v0=-0.2),
                               s.response(t, F) + s.free_response(t, x0=0.01, v0=-0.2), atol=1e-12)
    with pytest.raises(vm.ParameterError, match="x0"):
        s.response(t, F, x0=np.nan)
    K = np.array([[2e4, -1e4], [-1e4, 1e4]])
    sys2 = M.MDOF(np.eye(2), K)
    fn, phi = sys2.undamped_modes()
    x0 = np.array([0.01, -0.02])
    x = sys2.response(t, np.zeros((2, t.size)), x0=x0)
    # undamped modal closed form: sum_r phi_r phi_r^T M x0 cos(w_r t)
    ref = sum(np.outer(phi[:, r], np.cos(2 * np.pi * fn[r] * t)) * (phi[:, r] @ x0) for r in range(2))
    np.testing.assert_allclose(x, ref, atol=1e-10)
    with pytest.raises(vm.ParameterError, match="x0 must be 2 finite numbers"):
        sys2.response(t, np.zeros((2, t.size)), x0=[0.0, 1.0, 2.0])


# --- inverse calculations ---------------------------------------------------------------------------
@pytest.mark.parametrize("zeta", [0.01, 0.1, 0.4])
def test_damping_read_off_a_resonance_returns_the_model_zeta(zeta):
    s = M.SDOF(m=1.0, k=(2 * np.pi * 10) ** 2, zeta=zeta)
    f = np.linspace(5, 15, 2_000_001)
    mag, _ = s.magnification(f)
    # the peak read on a 5 uHz grid: its magnification to 1e-9, its frequency to 5e-6 Hz
    assert M.zeta_from_magnification(mag.max()) == pytest.approx(zeta, rel=1e-6)
    fp = f[np.argmax(mag)]
    assert M.zeta_from_peak_frequency(fp, 10.0) == pytest.approx(zeta, abs=2e-3 / (100 * zeta))
    acc = np.abs(s.frf(f, form="accelerance"))
    fa = f[np.argmax(acc)]
    assert M.zeta_from_peak_frequency(fa, 10.0, form="accelerance") == pytest.approx(zeta, abs=2e-3 / (100 * zeta))


def test_inverse_refusals_name_the_rule():
    with pytest.raises(vm.ParameterError, match="no resonant peak"):
        M.zeta_from_magnification(0.9)
    with pytest.raises(vm.ParameterError, match="whatever the damping"):
        M.zeta_from_peak_frequency(10.0, 10.0, form="mobility")
    with pytest.raises(vm.ParameterError, match="above fn"):
        M.zeta_from_peak_frequency(11.0, 10.0)
    with pytest.raises(vm.ParameterError, match="below 1"):
        M.isolator_stiffness(10.0, 30.0, 1.2)
    with pytest.raises(vm.ParameterError, match="fall"):
        M.decrement_from_amplitudes(1.0, 1.2, 3)
    with pytest.raises(vm.ParameterError, match="exactly one"):
        M.q_factor(zeta=0.1, loss_factor=0.2)
    with pytest.raises(vm.ParameterError, match="does not oscillate"):
        M.amplitude_phase(1.0, 0.0, 10.0, zeta=1.0)
    with pytest.raises(vm.ParameterError, match="exactly 2"):
        M.harmonic_frequency(displacement=1.0)
    with pytest.raises(vm.ParameterError, match="truth value"):
        M.SDOF(m=1.0, k=1.0, zeta=True)


@pytest.mark.parametrize("zeta", [0.0, 0.05, 0.2])
def test_isolator_stiffness_gives_the_target_transmissibility(zeta):
    k = M.isolator_stiffness(250.0, 24.0, 0.08, zeta=zeta)
    s = M.SDOF(m=250.0, k=k, zeta=zeta)
    assert s.transmissibility([24.0])[0] == pytest.approx(0.08, rel=EXACT)
    assert 24.0 / s.fn > np.sqrt(2)                     # the isolation side of resonance
    if zeta == 0:   # textbook: T = 1 / (r^2 - 1)
        assert (24.0 / s.fn) ** 2 == pytest.approx(1 + 1 / 0.08, rel=EXACT)


def test_decrement_q_and_initial_conditions_against_the_free_response():
    s = M.SDOF(m=1.0, k=(2 * np.pi * 5) ** 2, zeta=0.03)
    Td = 1 / s.fd
    a0, a5 = (float(s.free_response([Td * n], x0=1.0)[0]) for n in (0, 5))
    d = M.decrement_from_amplitudes(a0, a5, 5)
    assert d == pytest.approx(s.log_decrement, rel=EXACT)
    assert float(vm.zeta_from_delta(d)) == pytest.approx(0.03, rel=EXACT)
    assert M.q_factor(log_decrement=d) == pytest.approx(s.Q, rel=EXACT)
    assert M.q_factor(zeta=0.03) == M.q_factor(loss_factor=0.06) == pytest.approx(1 / 0.06, rel=EXACT)
    assert M.q_factor(fn=50.0, bandwidth=2.5) == 20.0
    A, phi = M.amplitude_phase(0.004, -0.3, 5.0, zeta=0.03)
    t = np.linspace(0, 2, 500)
    ref = s.free_response(t, x0=0.004, v0=-0.3)
    np.testing.assert_allclose(A * np.exp(-0.03 * s.wn * t) * np.cos(s.wd * t - phi), ref, atol=1e-15)


def test_static_deflection_and_harmonic_motion_textbook_figures():
    # Rao: a machine that sags 10 mm on its mounts has fn = sqrt(g / delta) / 2 pi = 4.98 Hz
    assert M.fn_from_deflection(0.010) == pytest.approx(4.9840, abs=5e-5)
    assert M.static_deflection(M.fn_from_deflection(0.010)) == pytest.approx(0.010, rel=EXACT)
    m = M.harmonic_motion(100.0, velocity=0.01)
    assert m["displacement"] == pytest.approx(0.01 / (2 * np.pi * 100), rel=EXACT)
    assert m["acceleration"] == pytest.approx(0.01 * 2 * np.pi * 100, rel=EXACT)
    for pair in (("displacement", "velocity"), ("velocity", "acceleration"), ("displacement", "acceleration")):
        assert M.harmonic_frequency(**{k: m[k] for k in pair}) == pytest.approx(100.0, rel=EXACT)


# --- damping from a measured loop ----------------------------------------------------------------------
def _loop(kind, fs=2000.0, f=8.0, X=2e-3, k=5e4, cycles=12):
    t = np.arange(int(cycles * fs / f)) / fs
    x = X * np.sin(2 * np.pi * f * t)
    xd = X * 2 * np.pi * f * np.cos(2 * np.pi * f * t)
    F = {"viscous": k * x + 40.0 * xd,
         "hysteretic": k * x + 0.05 * k * X * np.cos(2 * np.pi * f * t),
         "coulomb": k * x + 6.0 * np.sign(xd)}[kind]
    return x, F, fs


@pytest.mark.parametrize("kind,W", [("viscous", np.pi * 40.0 * 2 * np.pi * 8.0 * 4e-6),   # pi c w X^2
                                    ("hysteretic", np.pi * 0.05 * 5e4 * 4e-6),           # pi eta k X^2
                                    ("coulomb", 4 * 6.0 * 2e-3)])                         # 4 F X
def test_loop_energy_per_cycle_against_closed_forms(kind, W):
    x, F, fs = _loop(kind)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = vm.loop_damping(x, F, fs=fs)
    # 250 samples a cycle: the linear interpolation at each cycle's cut points leaves (2 pi / 250)^2 / 6
    # = 1e-4 of a smooth loop's area; a friction loop's jumps cost up to one sample's width of area
    assert r.energy_per_cycle == pytest.approx(W, rel=3e-4 if kind != "coulomb" else 1e-2)
    assert r.c_equivalent == pytest.approx(W / (np.pi * 2 * np.pi * 8.0 * 4e-6), rel=1e-2)
    if kind == "hysteretic":
        assert r.loss_factor == pytest.approx(0.05, rel=1e-3)
        assert r.stiffness == pytest.approx(5e4, rel=1e-3)


def test_loop_checks_its_assumptions():
    x, F, fs = _loop("viscous")
    with pytest.raises(vm.FitError, match="supplies"):
        vm.loop_damping(x, -F, fs=fs)
    with pytest.raises(vm.FitError, match="whole cycles"):
        vm.loop_damping(x[:200], F[:200], fs=fs)
    with pytest.raises(vm.FitError, match="samples per cycle"):
        vm.loop_damping(x[::40], F[::40], fs=fs / 40)
    with pytest.raises(vm.ParameterError, match="NaN"):
        vm.loop_damping(np.r_[x[:-1], np.nan], F, fs=fs)
    with pytest.raises(vm.ParameterError, match="same length"):
        vm.loop_damping(x, F[:-1], fs=fs)
    grow = np.linspace(1, 2, x.size)
    with pytest.warns(vm.QualityWarning, match="amplitude_varies"):
        r = vm.loop_damping(x * grow, F * grow, fs=fs)
    assert "amplitude_varies" in r.flags


# --- equivalent systems --------------------------------------------------------------------------------
def test_chain_of_equal_masses_against_the_closed_form():
    n, k, m = 5, 2e4, 3.0
    fn, _ = M.chain([m] * n, [k] * n).undamped_modes()
    r = np.arange(1, n + 1)
    ref = 2 * np.sqrt(k / m) * np.sin((2 * r - 1) * np.pi / (2 * (2 * n + 1))) / (2 * np.pi)
    np.testing.assert_allclose(fn, ref, rtol=1e-10)
    # a two-storey shear frame (Chopra's example 10.4 form): m 2m, k 2k/k -> w^2 = (k/m) (1/2, 2)
    fn, _ = M.chain([2.0, 1.0], [2e3, 1e3]).undamped_modes()
    np.testing.assert_allclose((2 * np.pi * fn) ** 2, [500.0, 2000.0], rtol=1e-10)
    with pytest.raises(vm.ParameterError, match="storey"):
        M.chain([1.0, 1.0], [1.0])
    assert M.stiffness("guided", E=2e11, I=1e-6, L=3.0) == pytest.approx(12 * 2e11 * 1e-6 / 27, rel=EXACT)


def test_large_amplitude_pendulum_textbook_ratios():
    t0 = M.pendulum_period(1.0)
    # Thornton & Marion's table: T / T0 = 1.0174 at 30 degrees, 1.1803 at 90, 1.7622 at 150
    for deg, ratio in ((30, 1.01741), (90, 1.18034), (150, 1.76220)):
        assert M.pendulum_period(1.0, amplitude=np.radians(deg)) / t0 == pytest.approx(ratio, abs=1e-5)
    with pytest.raises(vm.ParameterError, match="over the top"):
        M.pendulum_period(1.0, amplitude=np.pi)


def test_tip_mass_beam_against_an_independent_lumped_model():
    E, I, rho, A, L = 70e9, 2e-9, 2700.0, 1.2e-4, 0.6
    mb = rho * A * L
    bare = M.tip_mass_beam(E=E, I=I, rho=rho, A=A, L=L, tip_mass=0.0)
    # mu = 0: the bare cantilever (beta L = 1.8751) and Rayleigh's known 1.5 % over-estimate
    assert bare["fn_exact"] == pytest.approx(M.Beam(E=E, I=I, rho=rho, A=A, L=L).modes(1).fn[0], rel=1e-10)
    assert bare["error_pct"] == pytest.approx(1.47, abs=0.01)
    loaded = M.tip_mass_beam(E=E, I=I, rho=rho, A=A, L=L, tip_mass=mb)
    # 400 lumped masses on the cantilever's flexibility x_i^2 (3 x_j - x_i) / 6EI: error O(1/n^2) < 1e-5
    n = 400
    x = L * np.arange(1, n + 1) / n
    xi, xj = np.minimum.outer(x, x), np.maximum.outer(x, x)
    flex = xi ** 2 * (3 * xj - xi) / (6 * E * I)
    mass = np.full(n, mb / n)
    mass[-1] = mb / n / 2 + mb      # half a segment plus the tip mass
    mass[:-1] = mb / n
    lam = np.linalg.eigvals(flex * mass[None, :]).real.max()
    assert loaded["fn_exact"] == pytest.approx(1 / np.sqrt(lam) / (2 * np.pi), rel=2e-3)
    assert 0 < loaded["error_pct"] < bare["error_pct"]        # the heavier the tip, the better Rayleigh


# --- beam theories -------------------------------------------------------------------------------------
@pytest.mark.parametrize("bc", ["cantilever", "simply-supported", "clamped-clamped", "free-free",
                                "clamped-pinned"])
def test_the_exact_solver_reproduces_euler_bernoulli_to_rounding(bc):
    w = B._Section(1.0, 1.0, 0.0, None, 1.0, bc).omegas(8)
    np.testing.assert_allclose(np.sqrt(w), M.beta_l(bc, 8), rtol=1e-12)
    # a very slender Timoshenko beam tends to Euler-Bernoulli: L/r = 1e4 leaves (pi n r / L)^2 ~ 1e-7
    tb = M.TimoshenkoBeam(E=1.0, I=1e-8, rho=1.0, A=1.0, L=1.0, bc=bc, nu=0.3)
    np.testing.assert_allclose(tb.ratio_to_euler(3), 1.0, atol=2e-5)


def test_simply_supported_rayleigh_and_timoshenko_closed_forms():
    E, nu, kap, rho, b, h, L = 210e9, 0.3, 5 / 6, 7850.0, 0.05, 0.1, 1.2
    A, I, G = b * h, b * h ** 3 / 12, E / (2 * (1 + nu))
    tw = 2 * np.pi * M.TimoshenkoBeam(E=E, I=I, rho=rho, A=A, L=L, bc="simply-supported", nu=nu).modes(2).fn
    rw = 2 * np.pi * M.RayleighBeam(E=E, I=I, rho=rho, A=A, L=L, bc="simply-supported").modes(2).fn
    for n in (1, 2):
        k = n * np.pi / L
        a = rho ** 2 * I / (kap * G)
        bb = rho * A + rho * I * k ** 2 + E * I * k ** 2 * rho / (kap * G)
        w2 = (bb - np.sqrt(bb ** 2 - 4 * a * E * I * k ** 4)) / (2 * a)
        assert tw[n - 1] == pytest.approx(np.sqrt(w2), rel=1e-10)
        assert rw[n - 1] == pytest.approx(np.sqrt(E * I * k ** 4 / (rho * A + rho * I * k ** 2)), rel=1e-10)
    eb = 2 * np.pi * M.Beam(E=E, I=I, rho=rho, A=A, L=L, bc="simply-supported").modes(2).fn
    assert np.all(tw < rw) and np.all(rw < eb)
    # Rayleigh alone is 1 % low where 1 / sqrt(1 + (pi r / L)^2) = 0.99
    assert M.slenderness_limit("simply-supported", theory="rayleigh") == pytest.approx(
        np.pi / np.sqrt(1 / 0.99 ** 2 - 1), rel=1e-8)


def _fe_timoshenko_cantilever(n_el, E, G, kap, rho, A, I, L):
    """Linear Timoshenko elements with one-point shear integration: an independent O(h^2) oracle."""
    h = L / n_el
    nd = 2 * (n_el + 1)
    K, Mm = np.zeros((nd, nd)), np.zeros((nd, nd))
    Bs = np.array([-1 / h, -0.5, 1 / h, -0.5])
    kb = E * I / h * np.array([[0, 0, 0, 0], [0, 1, 0, -1], [0, 0, 0, 0], [0, -1, 0, 1]])
    ks = kap * G * A * h * np.outer(Bs, Bs)
    mm = h / 6 * np.array([[2, 1], [1, 2]])
    for e in range(n_el):
        d = slice(2 * e, 2 * e + 4)
        K[d, d] += kb + ks
        Mm[2 * e:2 * e + 4:2, 2 * e:2 * e + 4:2] += rho * A * mm
        Mm[2 * e + 1:2 * e + 4:2, 2 * e + 1:2 * e + 4:2] += rho * I * mm
    from scipy.linalg import eigh
    lam = eigh(K[2:, 2:], Mm[2:, 2:], eigvals_only=True, subset_by_index=[0, 1])
    return np.sqrt(lam)


def test_stocky_timoshenko_cantilever_against_finite_elements():
    E, nu, kap, rho, b, h, L = 210e9, 0.3, 5 / 6, 7850.0, 0.1, 0.1, 0.5
    A, I, G = b * h, b * h ** 3 / 12, E / (2 * (1 + nu))
    w = 2 * np.pi * M.TimoshenkoBeam(E=E, I=I, rho=rho, A=A, L=L, nu=nu).modes(2).fn
    w1, w2 = (_fe_timoshenko_cantilever(n, E, G, kap, rho, A, I, L) for n in (200, 400))
    fe = (4 * w2 - w1) / 3            # Richardson: the O(h^2) error cancels, O(h^4) ~ 1e-8 is left
    np.testing.assert_allclose(w, fe, rtol=1e-5)
    assert w[1] / (2 * np.pi * M.Beam(E=E, I=I, rho=rho, A=A, L=L).modes(2).fn[1]) < 0.9   # L/r 17: shear matters


# --- forced response of continua by modal expansion ----------------------------------------------------
def test_cantilever_modal_masses_and_effective_masses():
    b = M.Beam(E=210e9, I=1e-8, rho=7850.0, A=1e-4, L=1.0)
    m = 7850.0 * 1e-4
    np.testing.assert_allclose(b.modal_mass(4), m / 4, rtol=1e-9)       # unit-tip shapes: m L / 4
    # the textbook's 61.3 %, 18.8 %, 6.5 % of the mass in the first three modes
    np.testing.assert_allclose(b.effective_mass(3) / m, [0.6131, 0.1883, 0.0647], atol=1e-4)
    # the sum tends to the whole mass, the remainder falling as 1 / n (halved from 30 to 60 modes)
    rest30, rest60 = (1 - b.effective_mass(n).sum() / m for n in (30, 60))
    assert 0 < rest30 < 0.015 and rest60 / rest30 == pytest.approx(0.5, abs=0.01)


@pytest.mark.parametrize("bc,at,static", [("cantilever", 1.0, 1 / 3), ("simply-supported", 0.5, 1 / 48),
                                          ("clamped-clamped", 0.5, 1 / 192)])
def test_static_limit_of_the_expansion_is_the_beam_compliance(bc, at, static):
    b = M.Beam(E=210e9, I=1e-8, rho=7850.0, A=1e-4, L=1.0, bc=bc)
    h0 = b.frf([0.0], at=at, force_at=at, n_modes=40)[0]
    # 40 modes: the omitted modes' share of the static compliance is below 1e-5
    assert h0.real * 210e9 * 1e-8 == pytest.approx(static, rel=2e-5)
    tb = M.TimoshenkoBeam(E=210e9, I=8.33e-6, rho=7850.0, A=0.01, L=0.5, nu=0.3)
    G = 210e9 / 2.6
    ht = tb.frf([0.0], at=0.5, force_at=0.5, n_modes=40)[0].real
    # bending plus shear: L^3 / 3EI + L / (kappa G A); the shear part's modal sum converges as 1 / n,
    # 2e-4 short at 40 modes
    assert ht == pytest.approx(0.125 / (3 * 210e9 * 8.33e-6) + 0.5 / (5 / 6 * G * 0.01), rel=3e-4)


def test_free_free_beam_is_a_mass_below_its_first_mode():
    b = M.Beam(E=210e9, I=1e-8, rho=7850.0, A=1e-4, L=1.0, bc="free-free")
    m = 7850.0 * 1e-4
    w = 2 * np.pi * 0.5
    h = b.frf([0.5], at=0.0, force_at=0.0, n_modes=10)[0]
    # at the end: translation 1/m plus rotation (L/2)^2 / (m L^2 / 12) = 4 / m, so H = -4 / (m w^2)
    assert h.real == pytest.approx(-4 / (m * w ** 2), rel=1e-3)


def test_string_participation_and_resonant_response():
    s = M.String(T=100.0, mu=0.01, L=0.5, zeta=0.01)
    n = np.arange(1, 6)
    np.testing.assert_allclose(s.participation(5), np.where(n % 2, 4 / (n * np.pi), 0.0), atol=1e-12)
    x, _ = s.harmonic_response([100.0], 2.0, at=0.25, force_at=0.25, n_modes=1)
    # one mode at resonance: F phi^2 / (m_r 2 zeta w^2) with m_r = mu L / 2
    w = 2 * np.pi * 100.0
    assert x[0] == pytest.approx(2.0 / (0.01 * 0.25 * 2 * 0.01 * w ** 2), rel=1e-9)
    with pytest.raises(vm.ParameterError, match="off the structure"):
        s.frf([1.0], at=0.6, force_at=0.1)
    with pytest.raises(vm.ParameterError, match="needs its section"):
        M.Rod(E=1e9, rho=1e3, L=1.0).modal_mass(2)


# --- stepped sine and anti-resonances -------------------------------------------------------------------
def _dwells(s, tones, fs=2000.0, dwell=3.0, noise=0.01, seed=0, distort=0.0):
    t = np.arange(int(dwell * fs)) / fs
    f = np.concatenate([np.sin(2 * np.pi * ft * t) for ft in tones])
    x = s.response(np.arange(f.size) / fs, f)
    x = x + distort * np.max(np.abs(x)) * np.sin(2 * np.pi * 2 * np.repeat(tones, t.size) * np.tile(t, tones.size))
    rng = np.random.default_rng(seed)
    x = x + rng.normal(size=x.size) * noise * np.std(x)
    f = f + rng.normal(size=f.size) * noise
    return vm.Record(np.vstack([f, x]), fs=fs, channels=[vm.Channel("F", "force", "N"),
                                                         vm.Channel("x", "displacement", "m")])


def test_stepped_sine_frf_within_its_std_of_the_closed_form():
    s = M.SDOF(m=1.0, k=(2 * np.pi * 20) ** 2, zeta=0.02)
    tones = np.linspace(12, 28, 9)
    frf = vm.stepped_sine(_dwells(s, tones), tones, settle=0.8)
    err = np.abs(frf.h[0, 0] / s.frf(tones) - 1)
    # a 1 % noise on each channel: every tone within 4 of its own std, and better than 1 %
    assert np.all(err < 4 * frf.random_error[0]) and np.all(err < 0.01)
    assert frf.form == "receptance" and frf.estimator == "stepped-sine"
    with pytest.warns(vm.QualityWarning, match="not_settled"):
        early = vm.stepped_sine(_dwells(s, tones), tones, settle=0.0)
    assert any("not_settled" in f for f in early.params["flags"])
    # the std widens with the unsettled transient: the error stays within 4 stds
    e2 = np.abs(early.h[0, 0] / s.frf(tones) - 1)
    assert np.all(e2 < 4 * early.random_error[0])
    with pytest.warns(vm.QualityWarning, match="distorted"):
        vm.stepped_sine(_dwells(s, tones, distort=0.1), tones, settle=0.8)
    with pytest.raises(vm.ParameterError, match="Nyquist"):
        vm.stepped_sine(_dwells(s, tones), [1500.0] * 9)
    with pytest.raises(vm.ParameterError, match="whole cycles"):
        vm.stepped_sine(_dwells(s, tones, dwell=0.3), tones, settle=0.5)


def test_anti_resonances_against_the_chain_with_the_driven_mass_held():
    m, k = 1.0, 1e4
    three = M.chain([m] * 3, [k] * 3, modal_zeta=0.001)
    f = np.linspace(1, 40, 39001)
    H = three.frf(f)
    top = vm.antiresonances(vm.FRF(freq=f, h=H[2, 2]))
    # the top mass held: two masses between three springs, sqrt(k/m) and sqrt(3 k/m); light damping
    # and a 1 mHz grid leave 1e-4
    np.testing.assert_allclose(top["antiresonances"], np.sqrt([k / m, 3 * k / m]) / (2 * np.pi), rtol=1e-4)
    assert top["alternates"]
    cross = vm.antiresonances(vm.FRF(freq=f, h=H[2, 0]), drive_point=False)
    assert cross["antiresonances"].size == 0 and not cross["alternates"]
    with pytest.warns(vm.QualityWarning, match="driving-point FRF alternates"):
        vm.antiresonances(vm.FRF(freq=f, h=H[2, 0]))


def test_model_files_take_the_new_beams_and_refuse_truth_values(tmp_path):
    p = tmp_path / "t.toml"
    p.write_text('type = "timoshenko_beam"\n[parameters]\nE = "210 GPa"\nI = "8.33e6 mm^4"\nrho = "7850 kg/m^3"\n'
                 'A = "10000 mm^2"\nL = "0.5 m"\nnu = 0.3\nzeta = 0.01\n')
    tb = M.load(p)
    ref = M.TimoshenkoBeam(E=210e9, I=8.33e-6, rho=7850.0, A=0.01, L=0.5, nu=0.3)
    assert tb.modes(2).fn == pytest.approx(ref.modes(2).fn, rel=1e-12)
    p.write_text('type = "sdof"\n[parameters]\nm = "1 kg"\nk = "1 N/m"\nzeta = true\n')
    with pytest.raises(vm.ParameterError, match="truth value"):
        M.load(p)
    p.write_text('type = "sdof"\n[parameters]\nm = "1 kg"\nk = "1 N/m"\nzeta = ' + "9" * 4000 + "\n")
    with pytest.raises(vm.ParameterError, match="zeta"):
        M.load(p)


def test_new_functions_name_their_bad_arguments():
    """Found on the final read: each refused by name, none a raw numpy error or a silent NaN."""
    t = np.arange(6000) / 1000.0
    f = np.sin(2 * np.pi * 10 * t)
    x = f.copy()
    x[4000] = np.nan
    rec = vm.Record(np.vstack([f, x]), 1000.0, channels=[vm.Channel("F", "force", "N"),
                                                         vm.Channel("x", "displacement", "m")])
    with pytest.raises(vm.ParameterError, match="output channel 'x' holds NaN"):
        vm.stepped_sine(rec, [10.0, 20.0])
    flat = vm.FRF(freq=np.linspace(1, 60, 600), h=np.ones(600) + 0j)
    for band in ("ab", (1,), (50, 10)):
        with pytest.raises(vm.ParameterError, match="band="):
            vm.antiresonances(flat, band=band)
    with pytest.raises(vm.ParameterError, match="nu='x' must be a number"):
        M.TimoshenkoBeam(E=1.0, I=1.0, rho=1.0, A=1.0, L=1.0, nu="x")
    with pytest.raises(vm.ParameterError, match=r"nu=0.7 must be in \(-1, 0.5\]"):
        M.slenderness_limit(nu=0.7)
    with pytest.raises(vm.ParameterError, match="stiffnesses='a' must be a number"):
        M.chain([1.0], ["a"])
