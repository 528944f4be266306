"""Planar ANCF beam (mbjax._src.flex.ancf) and the Anderson 1993 §3.1 / §3.2 references built on it."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
import scipy.linalg

from mbjax.flex import AncfBeam, simulate_ancf
from mbjax._src.flex import slider_crank_reference, spin_up_beam_reference
from mbjax._src.flex.references import INCH

L, EA, EI, RHOA = 10.0, 2.8e7, 1.4e4, 1.2   # the spin-up beam (Anderson 1993 §3.2)


def clamped(beam):
    """Linearised cantilever at the straight state, K_ff and M_ff: node 0's position and transverse
    slope dy/ds fixed, its dx/ds (the axial strain at the root) free."""
    f = np.setdiff1d(np.arange(beam.n_coordinates), [0, 1, 3])
    K = jax.jit(jax.hessian(beam.elastic_energy))(beam.initial_coordinates())
    return np.asarray(K)[np.ix_(f, f)], np.asarray(beam.mass_matrix())[np.ix_(f, f)]


@pytest.mark.parametrize("origin, angle", [((0.0, 0.0), 0.0), ((1.5, -2.0), 0.7), ((-3.0, 4.0), -2.9)])
def test_rigid_motion_is_strain_free(origin, angle):
    beam = AncfBeam(L, EA, EI, RHOA, 3)
    e = beam.initial_coordinates(origin, angle)
    assert abs(beam.elastic_energy(e)) < 1e-20
    np.testing.assert_allclose(beam.elastic_force(e), 0.0, atol=1e-14 * EA)  # round-off of EA eps
    np.testing.assert_allclose(beam.position(e, 0.37 * L), jnp.asarray(origin) + 0.37 * L * jnp.stack(
        [jnp.cos(angle), jnp.sin(angle)]), atol=1e-12)


def test_mass_matrix_mass_and_moments():
    beam = AncfBeam(L, EA, EI, RHOA, 4)
    M, e = beam.mass_matrix(), beam.initial_coordinates((0.0, 0.0), 0.0)
    ux = jnp.tile(jnp.array([1.0, 0.0, 0.0, 0.0]), 5)           # unit rigid translation along x
    np.testing.assert_allclose(M, M.T, atol=0)
    np.testing.assert_allclose(ux @ M @ ux, RHOA * L, rtol=1e-13)          # total mass
    np.testing.assert_allclose(ux @ M @ e, RHOA * L**2 / 2, rtol=1e-13)    # first moment
    np.testing.assert_allclose(e @ M @ e, RHOA * L**3 / 3, rtol=1e-13)     # second moment
    assert np.all(np.linalg.eigvalsh(np.asarray(M)) > 0)


def test_cantilever_frequencies_match_euler_bernoulli():
    K, M = clamped(AncfBeam(L, EA, EI, RHOA, 10))
    w = np.sqrt(scipy.linalg.eigh(K, M, eigvals_only=True))
    bending = np.array([1.8751, 4.6941, 7.8548]) ** 2 * np.sqrt(EI / (RHOA * L**4))
    np.testing.assert_allclose(w[:3], bending, rtol=3e-4)   # cubic elements: O(h^4)
    axial = np.pi / 2 * np.sqrt(EA / RHOA) / L
    assert np.min(np.abs(w / axial - 1)) < 1e-5


def test_static_tip_deflection():
    """Small tip load: Newton on the nonlinear equilibrium, tip deflection vs P L^3 / (3 EI)."""
    beam = AncfBeam(L, EA, EI, RHOA, 2)
    P, f = 1e-3, np.setdiff1d(np.arange(beam.n_coordinates), [0, 1, 3])
    hessian = jax.jit(jax.hessian(beam.elastic_energy))
    Q = jnp.zeros(beam.n_coordinates).at[-3].set(P)
    e = beam.initial_coordinates()
    for _ in range(3):
        r = (beam.elastic_force(e) + Q)[f]
        K = hessian(e)[np.ix_(f, f)]
        e = e.at[f].add(jnp.linalg.solve(K, r))
    np.testing.assert_allclose(e[-3], P * L**3 / (3 * EI), rtol=1e-7)


def test_free_oscillation_conserves_energy():
    """No prescribed motion, conservative: RK4's energy error is its dissipation of the linear modes,
    |R(i w h)|^2 = 1 - (w h)^6 / 72 + (w h)^8 / 576 per step (R the RK4 polynomial), so the drift
    falls as dt^5 (32x per halving: the h^5 term of the local error is energy-orthogonal for linear
    dynamics) and the state converges as dt^4 (16x); momentum holds to round-off. The runs use
    safety 1/16 to 1/64 (w_max h = 0.18 to 0.044): at safety 0.5 and 0.25 (w_max h = 1.41, 0.71)
    the axial modes (2774, 2955 rad/s) lose all the 6.1e-5 of the energy they hold, so the drift
    saturates (3.0e-4, 7.7e-5: 3.9x, not asymptotic)."""
    beam = AncfBeam(1.0, 1e4, 10.0, 1.0, 3)
    e0 = beam.initial_coordinates((0.0, 0.0), 0.3)
    # smooth velocity field v(s) = (0.5, 2 s^2): nodal (v, dv/ds), so mostly low modes are excited
    s = jnp.linspace(0.0, 1.0, 4)
    e_dot0 = jnp.stack([0.5 + 0 * s, 2 * s**2, 0 * s, 4 * s], 1).ravel()
    ts = np.linspace(0.0, 1.0, 11)
    # linear modes at the start and their share of the (kinetic) energy
    K, M = np.asarray(jax.jit(jax.hessian(beam.elastic_energy))(e0)), np.asarray(beam.mass_matrix())
    w2, V = scipy.linalg.eigh(K, M)
    w, c = np.sqrt(np.clip(w2, 0.0, None)), V.T @ M @ np.asarray(e_dot0)
    share = 0.5 * c**2 / (0.5 * e_dot0 @ M @ e_dot0)
    H_of = jax.jit(jax.vmap(lambda e, v: beam.elastic_energy(e) + beam.kinetic_energy(v)))
    drift, es = [], []
    for safety in (1 / 16, 1 / 32, 1 / 64):
        sol = simulate_ancf(beam, e0, e_dot0, ts, safety=safety)
        H = H_of(sol.e, sol.e_dot)
        assert float(jnp.max(jax.jit(jax.vmap(beam.elastic_energy))(sol.e))) > 0.01 * float(H[0])
        drift.append(float(jnp.max(jnp.abs(H / H[0] - 1))))
        es.append(sol.e)
        p = sol.e_dot @ beam.mass_matrix()
        np.testing.assert_allclose(p[:, 0::4].sum(1), p[0, 0::4].sum(), rtol=1e-12)
        np.testing.assert_allclose(p[:, 1::4].sum(1), p[0, 1::4].sum(), rtol=1e-12)
        # the drift is RK4's linear-mode dissipation over the run's n equal steps h
        n = 10 * int(np.ceil(0.1 / sol.dt))
        z = w / n
        R2 = (1 - z**2 / 2 + z**4 / 24) ** 2 + (z - z**3 / 6) ** 2
        np.testing.assert_allclose(drift[-1], np.sum(share * (1 - R2**n)), rtol=5e-3)  # 2e-4
    assert drift[0] < 1e-6 and drift[2] < 1e-9                        # 3.7e-7, 1.2e-8, 3.6e-10
    for a, b in zip(drift, drift[1:]):
        assert 24 < a / b < 40                                         # 31.8, 32.0
    state = [float(jnp.max(jnp.abs(a - b))) for a, b in zip(es, es[1:])]
    assert 12 < state[0] / state[1] < 20                               # 17.2: fourth order


def test_prescribed_motion_converges_at_fourth_order():
    """A time-dependent root clamp (e_p(t), its rates by jax.jvp) keeps RK4 fourth order: the
    stages see e_p at their own times (at the step's start for k2, k3 the ratio is 2)."""
    beam = AncfBeam(1.0, 1e4, 10.0, 1.0, 3)

    def e_p(t):   # root oscillating along x, its slope turning by 2 t^2
        return jnp.stack([0.1 * jnp.sin(5 * t), 0 * t, jnp.cos(2 * t**2), jnp.sin(2 * t**2)])

    es = [simulate_ancf(beam, beam.initial_coordinates(), jnp.zeros(16).at[0].set(0.5),
                        np.linspace(0.0, 0.5, 6), prescribed=[0, 1, 2, 3], e_p=e_p, safety=safety).e
          for safety in (1 / 16, 1 / 32, 1 / 64)]
    d = [float(jnp.max(jnp.abs(a - b))) for a, b in zip(es, es[1:])]
    assert d[0] < 1e-7 and 12 < d[0] / d[1] < 20                      # 3.2e-8, 14.4


def test_a_run_past_the_stable_step_says_so_or_raises():
    """Twice RK4's stable step (safety 2 in `stable_step`): the status says nonfinite, and
    throw=True raises by name; at the stable step the same run succeeds."""
    import equinox as eqx

    beam = AncfBeam(1.0, 1e4, 10.0, 1.0, 3)
    e0 = beam.initial_coordinates((0.0, 0.0), 0.3)
    e_dot0 = jnp.zeros(beam.n_coordinates).at[1::4].set(1.0)
    ts = np.linspace(0.0, 1.0, 3)
    assert simulate_ancf(beam, e0, e_dot0, ts, safety=0.5).messages() == ["success"]
    blown = simulate_ancf(beam, e0, e_dot0, ts, safety=2.0)
    assert blown.messages() == ["nonfinite"] and not bool(blown.ok)
    with pytest.raises(eqx.EquinoxRuntimeError, match="simulate_ancf: .*status nonfinite"):
        simulate_ancf(beam, e0, e_dot0, ts, safety=2.0, throw=True)


@pytest.mark.slow
def test_spin_up_converges_with_mesh_and_step():
    ts = np.linspace(0.0, 2.0, 5)
    ref = spin_up_beam_reference(4, ts).tip_deflection
    finer = spin_up_beam_reference(8, ts).tip_deflection
    smaller = spin_up_beam_reference(4, ts, safety=0.25).tip_deflection
    assert -0.2 < float(ref[-1]) < -0.01                   # lags the rotation
    np.testing.assert_allclose(finer, ref, rtol=1e-3, atol=1e-6)
    np.testing.assert_allclose(smaller, ref, rtol=1e-6, atol=1e-9)


def test_slider_crank_stays_on_its_constraints():
    r = slider_crank_reference(2, np.linspace(0.0, 0.05, 51))      # one crank revolution
    e, ts = r.solution.e, r.ts
    P = 6 * INCH * jnp.stack([jnp.cos(np.pi / 2 + 125.6 * ts), jnp.sin(np.pi / 2 + 125.6 * ts)], 1)
    np.testing.assert_allclose(e[:, :2], P, atol=1e-14)
    np.testing.assert_allclose(e[:, 9], 0.0, atol=1e-14)
    # rigid-mechanism start: pure translation with P's velocity, undeformed
    np.testing.assert_allclose(r.solution.e_dot[0, 0::4], -6 * INCH * 125.6, rtol=1e-12)
    np.testing.assert_allclose(r.solution.e_dot[0, 1::4], 0.0, atol=1e-12)
    np.testing.assert_allclose(r.solution.e_dot[0, 2::4], 0.0, atol=1e-12)
    assert r.midpoint_deflection[0] == pytest.approx(0.0, abs=1e-12)
    assert 1e-3 < float(jnp.max(jnp.abs(r.midpoint_deflection))) < 0.5
    # Q slides: the rod's length between its ends stays close to 12 in (axially stiff)
    chord = jnp.linalg.norm(e[:, 8:10] - e[:, :2], axis=1)
    np.testing.assert_allclose(chord, 12 * INCH, rtol=1e-3)


@pytest.mark.slow
def test_slider_crank_periodic_and_mesh_converged():
    """The rod's response repeats per crank revolution, and the mesh converges fast: the largest
    difference over 0.15 s falls from 0.029 in (2 against 4 elements) to 0.0016 in (4 against 8,
    1.1 % of the 0.142 in peak), so the 4-element rod the reproductions use is converged to about
    0.002 in, a fifth of the modal models' 0.01 in tolerance."""
    ts = np.linspace(0.0, 0.15, 151)
    d2, d4, d8 = (np.asarray(slider_crank_reference(n, ts).midpoint_deflection) for n in (2, 4, 8))
    peaks = np.abs(d4[1:]).reshape(3, 50).max(1)                     # per crank revolution
    assert peaks.max() < 1.5 * peaks.min()
    coarse, fine = np.max(np.abs(d4 - d2)), np.max(np.abs(d8 - d4))
    assert fine < 0.02 * np.max(np.abs(d8)) and fine < coarse / 8   # measured 1.1 %, ratio 18


@pytest.mark.slow
def test_spin_up_full_run_peak_converges():
    ts = np.linspace(0.0, 20.0, 2001)
    peaks = []
    for n in (8, 16):
        d = np.asarray(spin_up_beam_reference(n, ts).tip_deflection)
        peaks.append(np.max(np.abs(d)))
    assert peaks[1] < 1.0
    assert abs(peaks[1] - peaks[0]) < 1e-3 * peaks[1]


@pytest.mark.slow
def test_spin_up_root_clamp_variants_agree_transversally():
    """Prescribing the root slope's length too (eps(0) = 0) changes the tip deflection little."""
    ts = np.linspace(0.0, 1.0, 3)
    a = spin_up_beam_reference(2, ts).tip_deflection
    b = spin_up_beam_reference(2, ts, free_root_stretch=False).tip_deflection
    np.testing.assert_allclose(a, b, rtol=1e-3)
