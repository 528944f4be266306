"""Andrews' squeezing mechanism (IVP test set problem `andrews`, Hairer & Wanner II §VII.7) built
from mbjax bodies, revolute joints and cut joints, against the test set: its equations (mass
matrix, constraints g(q), forces ff, transcribed below from the test set's Fortran `F`), its
initial values and its reference solution at t = 0.03 s."""

import json

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from mbjax_harness.cli import main
from mbjax.loops import Coupled, Loops, Stabilized
from mbjax._src.loops import numerical_rank
from mbjax_harness.reproduce import andrews_squeezer as reproduction
from mbjax._src.rigid.dynamics import mass_matrix
from mbjax.scenes import andrews_squeezer as S
from mbjax._src.scenes.andrews_squeezer import (c0, d, da, e, ea, fa, i1, i2, i3, i4, i5, i6, i7, l0,
                                           m1, m2, m3, m4, m5, m6, m7, mom, ra, rr, sa, sb, sc,
                                           sd, ss, ta, tb, u, ua, ub, xa, xb, xc, ya, yb, yc, zf,
                                           zt)

ORDER = list(S.TREE_ORDER)

# Error budget at the test's step dt = 10 us (QUICK_DT_STEPS = 3000), from the convergence study
# of `mbjax reproduce andrews-squeezer`: RK4's truncation error 2.2e-9 (difference from the runs
# at 5 and 2.5 us, which fall by 16 per halving), the reference's own error 1.4e-9 (the test
# set's equations integrated by DOP853 at rtol 1e-13 and by RK4 at 1 us agree to 1e-11 with each
# other and differ from SOLN by that much in beta and Theta): together below 4e-9 (measured:
# 2.1e-9).
TOLERANCE = 5e-9


def andrews_mass(y):
    """The test set's m(i, j) (its order of the angles)."""
    coth, siph, siom = np.cos(y[1]), np.sin(y[3]), np.sin(y[5])
    m = np.zeros((7, 7))
    m[0, 0] = m1 * ra**2 + m2 * (rr**2 - 2 * da * rr * coth + da**2) + i1 + i2
    m[1, 0] = m2 * (da**2 - da * rr * coth) + i2
    m[1, 1] = m2 * da**2 + i2
    m[2, 2] = m3 * (sa**2 + sb**2) + i3
    m[3, 3] = m4 * (e - ea)**2 + i4
    m[4, 3] = m4 * ((e - ea)**2 + zt * (e - ea) * siph) + i4
    m[4, 4] = m4 * (zt**2 + 2 * zt * (e - ea) * siph + (e - ea)**2) + m5 * (ta**2 + tb**2) + i4 + i5
    m[5, 5] = m6 * (zf - fa)**2 + i6
    m[6, 5] = m6 * ((zf - fa)**2 - u * (zf - fa) * siom) + i6
    m[6, 6] = m6 * ((zf - fa)**2 - 2 * u * (zf - fa) * siom + u**2) + m7 * (ua**2 + ub**2) + i6 + i7
    return np.tril(m) + np.tril(m, -1).T


def andrews_g(y):
    """The test set's position constraints g(q) (ground components)."""
    be, th, ga, ph, de, om, ep = y
    P = np.array([rr * np.cos(be) - d * np.cos(be + th), rr * np.sin(be) - d * np.sin(be + th)])
    return np.concatenate([
        P - [ss * np.sin(ga) + xb, -ss * np.cos(ga) + yb],
        P - [e * np.sin(ph + de) + zt * np.cos(de) + xa, -e * np.cos(ph + de) + zt * np.sin(de) + ya],
        P - [zf * np.cos(om + ep) + u * np.sin(ep) + xa, zf * np.sin(om + ep) - u * np.cos(ep) + ya]])


def andrews_forces(y, yp):
    """The test set's ff: motor, spring and velocity terms (M y'' = ff - G^T lambda)."""
    be, th, ga, ph, de, om, ep = y
    bep, thp, _, php, dep, omp, epp = yp
    xd, yd = sd * np.cos(ga) + sc * np.sin(ga) + xb, sd * np.sin(ga) - sc * np.cos(ga) + yb
    length = np.hypot(xd - xc, yd - yc)
    fx, fy = -c0 * (length - l0) / length * np.array([xd - xc, yd - yc])
    return np.array([
        mom - m2 * da * rr * thp * (thp + 2 * bep) * np.sin(th),
        m2 * da * rr * bep**2 * np.sin(th),
        fx * (sc * np.cos(ga) - sd * np.sin(ga)) + fy * (sd * np.cos(ga) + sc * np.sin(ga)),
        m4 * zt * (e - ea) * dep**2 * np.cos(ph),
        -m4 * zt * (e - ea) * php * (php + 2 * dep) * np.cos(ph),
        -m6 * u * (zf - fa) * epp**2 * np.cos(om),
        m6 * u * (zf - fa) * omp * (omp + 2 * epp) * np.cos(om)])


def andrews_G(y):
    """The test set's gp = dg/dq."""
    be, th, ga, ph, de, om, ep = y
    s1, c1 = rr * np.sin(be) - d * np.sin(be + th), rr * np.cos(be) - d * np.cos(be + th)
    s12, c12 = d * np.sin(be + th), d * np.cos(be + th)
    G = np.zeros((6, 7))
    G[0::2, 0], G[1::2, 0], G[0::2, 1], G[1::2, 1] = -s1, c1, s12, -c12
    G[0, 2], G[1, 2] = -ss * np.cos(ga), -ss * np.sin(ga)
    G[2, 3], G[3, 3] = -e * np.cos(ph + de), -e * np.sin(ph + de)
    G[2, 4], G[3, 4] = -e * np.cos(ph + de) + zt * np.sin(de), -e * np.sin(ph + de) - zt * np.cos(de)
    G[4, 5], G[5, 5] = zf * np.sin(om + ep), -zf * np.cos(om + ep)
    G[4, 6], G[5, 6] = zf * np.sin(om + ep) - u * np.cos(ep), -zf * np.cos(om + ep) - u * np.sin(ep)
    return G


def andrews_gqq(y, yp):
    """d/dt (G) y', the second derivative of g(q(t)) at y'' = 0 (differentiated by hand)."""
    be, th, ga, ph, de, om, ep = y
    bep, thp, gap, php, dep, omp, epp = yp
    P = -np.array([rr * np.cos(be), rr * np.sin(be)]) * bep**2 + np.array(
        [d * np.cos(be + th), d * np.sin(be + th)]) * (bep + thp)**2
    return np.concatenate([
        P + np.array([ss * np.sin(ga), -ss * np.cos(ga)]) * gap**2,
        P + np.array([e * np.sin(ph + de), -e * np.cos(ph + de)]) * (php + dep)**2
        + np.array([zt * np.cos(de), zt * np.sin(de)]) * dep**2,
        P + np.array([zf * np.cos(om + ep), zf * np.sin(om + ep)]) * (omp + epp)**2
        + np.array([u * np.sin(ep), -u * np.cos(ep)]) * epp**2])


def andrews_rhs(t, state):
    """The test set's equations as an index-1 ODE: M y'' + G^T lambda = ff, G y'' + gqq = 0."""
    y, yp = state[:7], state[7:]
    G = andrews_G(y)
    K = np.block([[andrews_mass(y), G.T], [G, np.zeros((6, 6))]])
    ypp = np.linalg.solve(K, np.concatenate([andrews_forces(y, yp), -andrews_gqq(y, yp)]))[:7]
    return np.concatenate([yp, ypp])


@pytest.fixture(scope="module")
def squeezer():
    return S.build()


@pytest.fixture(scope="module")
def phi(squeezer):
    return jax.jit(lambda q: Loops(squeezer.tree, squeezer.closures).phi(q))


@pytest.fixture(scope="module")
def quick_run(squeezer):
    """RK4 at dt = 10 us with the coupled multipliers: the run `--quick` times (one compilation,
    shared with the CLI test in this module)."""
    return reproduction.run(squeezer.system(Coupled()), reproduction.QUICK_DT_STEPS)[0]


def test_initial_values_satisfy_the_constraints_with_full_rank(squeezer, phi):
    loops = Loops(squeezer.tree, squeezer.closures)
    assert loops.m == 6
    assert float(jnp.abs(phi(squeezer.q0)).max()) < 1e-12
    A = jax.jit(lambda q: loops.jacobian(q))(squeezer.q0)
    assert int(numerical_rank(A @ A.T)) == 6
    np.testing.assert_allclose(andrews_g(np.array(S.Y0)), 0.0, atol=1e-15)


def test_cut_joints_are_the_test_sets_constraints_rotated(phi):
    """Each loop's residual is g of the test set in the second body's frame: the same norm."""
    rng = np.random.default_rng(0)
    for _ in range(3):
        y = np.array(S.Y0) + rng.normal(scale=0.3, size=7)
        ours = np.asarray(phi(S.from_testset(y))).reshape(3, 2)
        theirs = andrews_g(y).reshape(3, 2)
        np.testing.assert_allclose(np.linalg.norm(ours, axis=1), np.linalg.norm(theirs, axis=1),
                                   rtol=1e-12)


def test_mass_matrix_is_the_test_sets(squeezer):
    rng = np.random.default_rng(1)
    mass = jax.jit(lambda q: mass_matrix(squeezer.tree.model, q))
    for _ in range(3):
        y = rng.uniform(-np.pi, np.pi, size=7)
        ours = np.asarray(mass(S.from_testset(y)))
        np.testing.assert_allclose(ours, andrews_mass(y)[np.ix_(ORDER, ORDER)], rtol=0,
                                   atol=1e-14 * np.abs(ours).max())


def test_spring_force_is_minus_the_gradient_of_its_energy(squeezer):
    """Central differences of V = c0 (L - l0)^2 / 2 (step 1e-6 rad: error ~1e-12 relative), and
    the test set's ff(3)."""
    spring = squeezer.spring
    force = jax.jit(lambda q: spring(0.0, q, jnp.zeros(7)))
    # V at q +- h e_k for every k in one call
    energies = jax.jit(jax.vmap(spring.energy))
    h = 1e-6
    for q in (squeezer.q0, squeezer.q0 + 0.2 * jnp.cos(jnp.arange(7.0))):
        f = np.asarray(force(q))
        up, down = energies(q + h * jnp.eye(7)), energies(q - h * jnp.eye(7))
        fd = -np.asarray(up - down) / (2 * h)
        np.testing.assert_allclose(f, fd, rtol=0, atol=1e-8 * np.abs(f).max())
        y = np.asarray(S.to_testset(q))
        np.testing.assert_allclose(f[2], andrews_forces(y, np.zeros(7))[2], rtol=1e-13)
        assert np.count_nonzero(f) == 1                       # only gamma's joint feels it


@pytest.mark.slow
def test_accelerations_are_the_test_sets(squeezer, quick_run):
    """At rest at t = 0 (the test set's initial y'' = 14222.44..., -10666.83..., 0, ...) and at
    15 ms, where every velocity term acts (there the two formulations' different round-off,
    amplified by the cond(A M^-1 A^T) = 270 of the multiplier solve, leaves 2e-10)."""
    system = squeezer.system(Coupled())
    acceleration = jax.jit(lambda t, q, v: system.acceleration(t, q, v))
    a0 = np.asarray(S.to_testset(acceleration(0.0, squeezer.q0, squeezer.v0)))
    expected = np.array([14222.4439199541138705911625887, -10666.8329399655854029433719415,
                         0, 0, 0, 0, 0])
    np.testing.assert_allclose(a0, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
    q, v = quick_run.qs[30], quick_run.vs[30]
    a = np.asarray(S.to_testset(acceleration(quick_run.ts[30], q, v)))
    y, yp = np.asarray(S.to_testset(q)), np.asarray(S.to_testset(v))
    theirs = andrews_rhs(0.0, np.concatenate([y, yp]))[7:]
    np.testing.assert_allclose(a, theirs, rtol=0, atol=1e-9 * np.abs(theirs).max())


def test_matches_the_published_reference(quick_run, phi):
    """The test set's SOLN at 30 ms, within the error budget of TOLERANCE; success status (no
    constraint violation and full rank 6 at every saved state)."""
    assert quick_run.messages() == ["success"] and int(quick_run.status) == 0
    error = reproduction.end_error(quick_run)
    assert np.abs(error).max() < TOLERANCE, error
    assert float(jnp.abs(phi(quick_run.qs[-1])).max()) < 1e-10


def test_agrees_with_the_test_sets_equations_integrated_by_dop853(quick_run):
    """A second reference along the whole history: scipy's DOP853 on the test set's equations."""
    state0 = np.concatenate([np.array(S.Y0), np.zeros(7)])
    ts = np.asarray(quick_run.ts)
    ref = solve_ivp(andrews_rhs, (0.0, S.T1), state0, method="DOP853", rtol=1e-12, atol=1e-12,
                    t_eval=ts)
    assert ref.success
    ours = np.asarray(S.to_testset(quick_run.qs))
    np.testing.assert_allclose(ours, ref.y[:7].T, rtol=0, atol=TOLERANCE)


@pytest.mark.slow
def test_projection_and_order_n_routes_agree(squeezer, quick_run):
    """Anderson 1993's O(n + m^3) route gives the coupled multipliers' motion to round-off; projection
    after every step moves each state by its O(dt^5) constraint error, so it differs by RK4's
    truncation error (4e-9 at 10 us), and both meet the reference as closely."""
    for system, atol in ((squeezer.system(Stabilized()), 1e-11),
                         (squeezer.system(Coupled(), projection=True), TOLERANCE)):
        other = reproduction.run(system, reproduction.QUICK_DT_STEPS)[0]
        assert other.messages() == ["success"]
        np.testing.assert_allclose(other.qs, quick_run.qs, rtol=0, atol=atol)
        assert np.abs(reproduction.end_error(other)).max() < TOLERANCE


@pytest.mark.slow
def test_cli_reproduction_writes_the_contract(tmp_path, quick_run):
    assert main(["reproduce", "andrews-squeezer", "--quick", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "andrews-squeezer.json").read_text())
    assert {"t", "q", "reference", "max_abs_error", "seconds"} <= set(data)
    assert data["t"] == 0.03 and len(data["q"]) == len(data["reference"]) == 7
    assert data["reference"] == list(S.REFERENCE)
    assert data["max_abs_error"] < TOLERANCE and data["seconds"] > 0
    # RK4's truncation error at the quick run's 10 us, against 24000 steps: 2.1e-9 rad in the
    # angles, 1.0e-6 rad/s in the rates, which the estimate (the largest of both) follows
    assert data["status"] == "success" and 1e-7 < data["error_estimate"] < 1e-5
    assert [r["steps"] for r in data["convergence"]] == list(reproduction.QUICK_STEPS)
    assert (tmp_path / "andrews-squeezer.png").stat().st_size > 10_000
