"""Dynamics of rigid trees: identities between the O(n) recursion (Anderson 1993), the RNEA and Jerkovsky
1978's transformation operator; Pinocchio and MuJoCo on the same URDF; invariants of simulated
motion; gradients, vmap and input checks.

Everything traced is jitted once per model (a compile per topology), so the file stays fast.
"""

import functools

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from jax.test_util import check_grads

import mbjax
from mbjax import Recursive, Dense
from mbjax._src import rigid
from mbjax.integrate import RK4, RKMK4, simulate
from mbjax.model import Model, chain, random_tree
from mbjax._src.model.urdf import to_urdf
from mbjax._src.rigid.aba import _wide_root

RTOL = 1e-10          # float64 identities


def assert_close(actual, expected, rtol=RTOL):
    """Relative to the largest entry of `expected` (entries near zero do not blow up rtol)."""
    actual, expected = np.asarray(actual), np.asarray(expected)
    assert actual.shape == expected.shape, (actual.shape, expected.shape)
    scale = max(np.abs(expected).max(), 1e-300)
    np.testing.assert_allclose(actual, expected, rtol=rtol, atol=rtol * scale)


# --------------------------------------------------------------------------------------------
# Models
# --------------------------------------------------------------------------------------------


def _retyped(base: Model, joint_types) -> Model:
    """`base`'s topology and parameters with other joint types."""
    return Model(base.topology, joint_types, mass=base.mass, inertia=base.inertia, com=base.com,
                 axis=base.axis, axis2=base.axis2, placement_rotation=base.placement_rotation,
                 placement_translation=base.placement_translation, gravity=base.gravity)


def _mixed() -> Model:
    """Every joint type: a free base carrying spherical, universal, revolute and prismatic joints."""
    return _retyped(random_tree(5, seed=8), ("free", "spherical", "universal", "revolute",
                                             "prismatic"))


def _multi_dof() -> Model:
    """The multi-DOF joints (chains and trees cover revolute and prismatic): a free base, a
    spherical and a universal joint."""
    return _retyped(random_tree(4, seed=12), ("free", "spherical", "universal", "universal"))


# The chain and the branched tree come from URDF text, so the very same models (and compiled
# functions) serve the identities and the comparison with Pinocchio and MuJoCo.
CHAIN_URDF = to_urdf(chain(6, seed=2))
TREE_URDF = to_urdf(random_tree(8, seed=1, max_back=5))
MODELS = {
    "chain": lambda: mbjax.load_urdf(CHAIN_URDF),
    "tree": lambda: mbjax.load_urdf(TREE_URDF),
    "multi_dof": _multi_dof,
    "mixed": _mixed,
    "spherical_universal": lambda: random_tree(7, seed=4,
                                               joint_types=("universal", "spherical", "revolute")),
}
SLOW_MODELS = {"mixed", "spherical_universal"}     # a compile each: the default suite has every
                                                    # joint type in "chain", "tree" and "multi_dof"


def random_state(model: Model, seed: int):
    """(q, v, tau, a): random angles and offsets, unit quaternions, random rates."""
    rng = np.random.default_rng(seed)
    q = model.normalize(model.neutral() + 0.7 * jnp.asarray(rng.normal(size=model.nq)))
    v, tau, a = (jnp.asarray(rng.normal(size=model.nv)) for _ in range(3))
    return q, v, tau, a


def _vee(S):
    return jnp.stack([S[..., 2, 1], S[..., 0, 2], S[..., 1, 0]], -1)


def _tilde(r):
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


@eqx.filter_jit
def _dynamics(model: Model, q, v, tau, a):
    """Every quantity the identity and peer tests compare, in one compiled call per model."""
    out = {}
    out["fd_recursive"] = rigid.forward_dynamics(model, q, v, tau, method=Recursive())
    out["fd_dense"] = rigid.forward_dynamics(model, q, v, tau, method=Dense())
    out["tau_of_a"] = tau_a = rigid.inverse_dynamics(model, q, v, a)
    out["fd_of_id"] = rigid.forward_dynamics(model, q, v, tau_a, method=Recursive())

    out["M"] = M = rigid.mass_matrix(model, q)
    out["M_hessian"] = jax.jit(jax.hessian(lambda v_: rigid.kinetic_energy(model, q, v_)))(v)
    # At v = 0 without gravity the RNEA of a unit acceleration is a column of M.
    no_gravity = eqx.tree_at(lambda m: m.gravity, model, jnp.zeros(3))
    zero = jnp.zeros(model.nv)
    out["M_rnea"] = jax.jit(jax.vmap(lambda e: rigid.inverse_dynamics(no_gravity, q, zero, e)))(
        jnp.eye(model.nv)).T

    # Momentum form (Jerkovsky 1978 eqs 72-73): d/dt (M v) along the motion under tau.
    q_dot = model.q_dot(q, v)
    p, p_dot = jax.jvp(lambda q_, v_: rigid.momentum(model, q_, v_), (q, v),
                       (q_dot, out["fd_recursive"]))
    out["p"], out["Mv"], out["p_dot"] = p, M @ v, p_dot
    out["momentum_rate"] = rigid.momentum_rate(model, q, v, tau)

    # Joint wrenches three ways: eq 76, eq 75 and the RNEA's (body frame -> ground frame).
    R, h = rigid.forward_kinematics(model, q)
    W = rigid.joint_wrenches(model, q, v, a)
    out["wrench_body"] = W
    out["wrench_rnea"] = jnp.concatenate([jnp.einsum("kij,kj->ki", R, W[:, :3]),
                                          jnp.einsum("kij,kj->ki", R, W[:, 3:])], -1)
    out["wrench_76"] = rigid.joint_reactions(model, q, v, a)
    out["wrench_75"] = rigid.constraint_forces_momentum(model, q, v, a)
    out["K_c"] = rigid.constraint_forces(model, q, v, a)

    A, A_hat = rigid.transformation_operator(model, q)
    out["A"], out["A_hat"] = A, A_hat
    out["sigma_operator"] = (A @ A_hat @ v).reshape(model.n, 6)

    # Per-body (omega; v_c) from forward kinematics, by forward-mode autodiff along q_dot and by
    # central differences (step FD_STEP).
    def frames(q_):
        R_, p_ = rigid.forward_kinematics(model, q_)
        return R_, p_ + jnp.einsum("kij,kj->ki", R_, model.com)

    (R, c), (R_dot, c_dot) = jax.jvp(frames, (q,), (q_dot,))
    out["sigma_jvp"] = jnp.concatenate([_vee(R_dot @ jnp.swapaxes(R, -1, -2)), c_dot], -1)
    (R_plus, c_plus), (R_minus, c_minus) = frames(q + FD_STEP * q_dot), frames(q - FD_STEP * q_dot)
    R_diff = (R_plus - R_minus) / (2 * FD_STEP)
    out["sigma_fd"] = jnp.concatenate([_vee(R_diff @ jnp.swapaxes(R, -1, -2)),
                                       (c_plus - c_minus) / (2 * FD_STEP)], -1)
    out["R"], out["h"], out["c"] = R, h, c
    return out


FD_STEP = 1e-6


@pytest.fixture(scope="module", params=[
    pytest.param(name, marks=pytest.mark.slow) if name in SLOW_MODELS else name for name in MODELS])
def case(request):
    model = MODELS[request.param]()
    state = random_state(model, seed=len(request.param))
    return request.param, model, state, _dynamics(model, *state)


def test_a_floating_base_is_eliminated_on_its_own():
    """A free base under narrower joints is eliminated with its own 6 x 6 blocks and the tree
    passes run at the other joints' width (mbjax._src.rigid.aba._wide_root): the identities below
    check that route on "multi_dof" and "mixed", the URDF tests on real floating robots. Two
    free bodies, or a tree without a free base, keep one width."""
    assert _wide_root(_multi_dof()) == _wide_root(_mixed()) == (0, 3)     # spherical joints
    assert _wide_root(mbjax.load_urdf(TREE_URDF)) == (None, 1)
    assert _wide_root(random_tree(3, joint_types="free")) == (None, 6)
    floating = mbjax.load_urdf(TREE_URDF, floating_base=True)
    assert _wide_root(floating) == (0, 1)


# --------------------------------------------------------------------------------------------
# Identities
# --------------------------------------------------------------------------------------------


def test_recursive_equals_dense(case):
    _, _, _, out = case
    assert_close(out["fd_recursive"], out["fd_dense"])


def test_forward_dynamics_inverts_inverse_dynamics(case):
    _, _, (_, _, _, a), out = case
    assert_close(out["fd_of_id"], a)


def test_mass_matrix_is_hessian_of_kinetic_energy(case):
    _, _, _, out = case
    assert_close(out["M"], out["M_hessian"])
    assert_close(out["M"], out["M"].T, rtol=1e-14)
    assert np.linalg.eigvalsh(np.asarray(out["M"]))[0] > 0


def test_mass_matrix_is_rnea_of_unit_accelerations(case):
    _, _, _, out = case
    assert_close(out["M"], out["M_rnea"])


def test_momentum_rate_is_time_derivative_of_momentum(case):
    """Jerkovsky 1978 eq 72 against d/dt (M v) along the motion (forward-mode autodiff); eq 73."""
    _, _, _, out = case
    assert_close(out["p"], out["Mv"])
    assert_close(out["momentum_rate"], out["p_dot"])


def test_joint_wrenches_three_ways(case):
    """Eq 76 (velocity form) == eq 75 (momentum form) == the RNEA's wrench in ground axes."""
    _, _, _, out = case
    assert_close(out["wrench_76"], out["wrench_rnea"])
    assert_close(out["wrench_75"], out["wrench_rnea"])


def test_wrench_projections_give_tau_and_constraint_forces(case):
    """A_hat_f^T W = tau (the free components), A_hat_f^T K_c = 0 (eq 76 is orthogonal to the
    joint axes) and W - K_c lies in the span of the axes."""
    _, model, _, out = case
    A_hat, W, K_c = (np.asarray(out[k]) for k in ("A_hat", "wrench_76", "K_c"))
    assert_close(A_hat.T @ W.reshape(-1), out["tau_of_a"])
    np.testing.assert_allclose(A_hat.T @ K_c.reshape(-1), 0, atol=RTOL * np.abs(W).max())
    free = (W - K_c).reshape(-1)
    projected = A_hat @ np.linalg.lstsq(A_hat, free, rcond=None)[0]
    assert_close(projected, free)
    for k, kind in enumerate(model.joint_types):
        if kind == "free":                   # nothing constrained: no constraint wrench
            np.testing.assert_allclose(K_c[k], 0, atol=RTOL * np.abs(W).max())
        else:
            assert np.abs(K_c[k]).max() > 1e-3 * np.abs(W).max()


def test_transformation_operator_gives_primitive_velocities(case):
    """sigma = A A_hat_f v (Jerkovsky 1978 eqs 14, 49): per body (omega; v_c) in ground axes, against
    forward kinematics differentiated by autodiff and by central differences."""
    _, _, _, out = case
    assert_close(out["sigma_operator"], out["sigma_jvp"])
    assert_close(out["sigma_operator"], out["sigma_fd"], rtol=1e-7)


def test_mass_matrix_from_operator_and_primitive_mass(case):
    """mu_hat_ff = A_hat_f^T A^T mu A A_hat_f (eqs 18, 55) with mu = diag(I_c, M 1) per body
    (eq 7a) built here from the model's parameters."""
    _, model, _, out = case
    R = np.asarray(out["R"])
    mu = np.zeros((6 * model.n, 6 * model.n))
    for k in range(model.n):
        mu[6 * k:6 * k + 3, 6 * k:6 * k + 3] = R[k] @ np.asarray(model.inertia[k]) @ R[k].T
        mu[6 * k + 3:6 * k + 6, 6 * k + 3:6 * k + 6] = float(model.mass[k]) * np.eye(3)
    alpha = np.asarray(out["A"]) @ np.asarray(out["A_hat"])
    assert_close(alpha.T @ mu @ alpha, out["M"])


def test_operator_structure_follows_path_matrix(case):
    """A's (k, j) block is zero off the path (pi_kj = 0) and [[1, 0], [-(c_k - h_j)~, 1]] on it
    (eq 17); A_hat_f is block diagonal: each joint's axes sit in its own body's rows."""
    _, model, _, out = case
    A = np.asarray(out["A"]).reshape(model.n, 6, model.n, 6).transpose(0, 2, 1, 3)
    pi = model.topology.path_matrix()
    h, c = np.asarray(out["h"]), np.asarray(out["c"])
    for k in range(model.n):
        for j in range(model.n):
            expected = np.zeros((6, 6))
            if pi[k, j]:
                expected = np.eye(6)
                expected[3:, :3] = -_tilde(c[k] - h[j])
            np.testing.assert_allclose(A[k, j], expected, atol=1e-14)
    owner = np.repeat(np.arange(model.n), 6)
    for col, body in enumerate(model.dof_body()):
        assert np.all(np.asarray(out["A_hat"])[owner != body, col] == 0)


# --------------------------------------------------------------------------------------------
# Against Pinocchio and MuJoCo (the same URDF text for all three)
# --------------------------------------------------------------------------------------------

PEER_CASES = {
    "chain": CHAIN_URDF,
    "tree": TREE_URDF,
    # more than 10 joints: Pinocchio's sibling order (by name: joint10 < joint9) differs from the
    # document order, so the name matching below matters
    "big_tree": to_urdf(random_tree(14, seed=1)),
}


@pytest.fixture(scope="module", params=[
    pytest.param(name, marks=pytest.mark.slow) if name == "big_tree" else name
    for name in PEER_CASES])
def peer_case(request):
    xml = PEER_CASES[request.param]
    model = mbjax.load_urdf(xml)
    assert set(model.joint_types) <= {"revolute", "prismatic"}
    if request.param != "chain":                    # branched, with both joint types
        assert max(len(model.topology.distal(k)) for k in range(model.n)) > 1
        assert set(model.joint_types) == {"revolute", "prismatic"}
    state = random_state(model, seed=len(request.param))
    return xml, model, state, _dynamics(model, *state)


def test_against_pinocchio(peer_case):
    pin = pytest.importorskip("pinocchio")
    xml, model, (q, v, tau, a), out = peer_case
    pm = pin.buildModelFromXML(xml)
    data = pm.createData()
    # Bodies matched by joint name (Pinocchio orders sibling joints by name, mbjax by document).
    jid = [pm.getJointId(name) for name in model.joint_names]
    perm = np.asarray([pm.idx_vs[j] for j in jid])
    assert sorted(perm.tolist()) == list(range(model.nv)) and pm.nq == model.nq

    def to_pin(x):
        y = np.zeros(model.nv)
        y[perm] = np.asarray(x)
        return y

    qp, vp, tp, ap = to_pin(q), to_pin(v), to_pin(tau), to_pin(a)
    assert_close(out["fd_recursive"], pin.aba(pm, data, qp, vp, tp)[perm])
    assert_close(out["fd_dense"], pin.aba(pm, data, qp, vp, tp)[perm])
    M = pin.crba(pm, data, qp)
    M = np.triu(M) + np.triu(M, 1).T                 # Pinocchio fills the upper triangle
    assert_close(out["M"], M[np.ix_(perm, perm)])
    assert_close(out["tau_of_a"], pin.rnea(pm, data, qp, vp, ap)[perm])
    # data.f: the wrench joint i transmits, local joint frame, (linear; angular).
    f = np.stack([np.concatenate([data.f[j].angular, data.f[j].linear]) for j in jid])
    assert_close(out["wrench_body"], f)


def test_against_mujoco(peer_case):
    mujoco = pytest.importorskip("mujoco")
    xml, model, (q, v, tau, a), out = peer_case
    mj = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(mj)
    names = [mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(mj.njnt)]
    perm = np.asarray([mj.jnt_dofadr[names.index(name)] for name in model.joint_names])
    assert sorted(perm.tolist()) == list(range(model.nv)) and mj.nq == model.nq

    def to_mj(x):
        y = np.zeros(model.nv)
        y[perm] = np.asarray(x)
        return y

    data.qpos[:], data.qvel[:], data.qfrc_applied[:] = to_mj(q), to_mj(v), to_mj(tau)
    mujoco.mj_forward(mj, data)
    assert data.nefc == 0                              # no contacts or limits in play
    assert_close(out["fd_recursive"], data.qacc[perm])
    M = np.zeros((mj.nv, mj.nv))
    mujoco.mj_fullM(mj, data, M)
    assert_close(out["M"], M[np.ix_(perm, perm)])
    data.qacc[:] = to_mj(a)
    mujoco.mj_inverse(mj, data)
    assert_close(out["tau_of_a"], data.qfrc_inverse[perm])


# --------------------------------------------------------------------------------------------
# Invariants of simulated motion
# --------------------------------------------------------------------------------------------

SEVEN = chain(7)
Q0_SEVEN = jnp.asarray(np.linspace(0.9, -0.6, 7))
V0_SEVEN = jnp.asarray(np.linspace(-1.0, 1.5, 7))
GRAVITIES = {"zero_gravity": (0.0, 0.0, 0.0), "gravity": (0.0, 0.0, -9.81)}
SAVE = np.linspace(0.0, 2.0, 21)
STEPS = (0.01, 0.005)


@functools.cache
def _seven_link_run(form: str, gravity: str, dt: float):
    """The torque-free 7-link chain over 2 s with RK4: (q, v, energy) at SAVE. Cached, since
    several tests share the runs; one compile per form and dt (gravity is a model leaf)."""
    model = eqx.tree_at(lambda m: m.gravity, SEVEN, jnp.asarray(GRAVITIES[gravity]))
    if form == "velocity":
        system, u0 = rigid.TreeSystem(model), V0_SEVEN
    else:
        system, u0 = rigid.MomentumSystem(model), jax.jit(rigid.momentum)(model, Q0_SEVEN, V0_SEVEN)
    sol = simulate(system, RK4(), Q0_SEVEN, u0, dt=dt, t1=2.0, saveat=SAVE)
    assert sol.messages() == ["success"]
    energy = jax.jit(jax.vmap(system.energy))(sol.qs, sol.vs)
    velocity = sol.vs if form == "velocity" else jax.jit(jax.vmap(system.velocity))(sol.qs, sol.vs)
    return np.asarray(sol.qs), np.asarray(velocity), np.asarray(energy)


@pytest.mark.parametrize("gravity", list(GRAVITIES))
def test_energy_conservation_converges_at_fourth_order(gravity):
    """RK4 on a torque-free 7-link chain over 2 s: the relative energy error is small and falls
    about 2^4 when dt halves."""
    errors = []
    for dt in STEPS:
        _, _, E = _seven_link_run("velocity", gravity, dt)
        errors.append(np.max(np.abs(E - E[0])) / abs(E[0]))
    assert errors[0] < 1e-4, errors
    order = np.log2(errors[0] / errors[1])
    assert 3.5 < order < 4.8, (errors, order)


def test_momentum_and_velocity_forms_agree():
    """MomentumSystem (Jerkovsky 1978 eqs 72-73) and TreeSystem integrate the same motion: they differ
    by RK4's error only (falling about 2^4 when dt halves), and both keep the energy."""
    differences = []
    for dt in STEPS:
        q_v, v_v, _ = _seven_link_run("velocity", "gravity", dt)
        q_p, v_p, E_p = _seven_link_run("momentum", "gravity", dt)
        differences.append(max(np.abs(q_v - q_p).max(), np.abs(v_v - v_p).max()))
        assert np.max(np.abs(E_p - E_p[0])) / abs(E_p[0]) < 1e-4
    assert differences[1] < 1e-3, differences
    assert 10 < differences[0] / differences[1] < 25, differences
    assert np.abs(q_v[-1] - q_v[0]).max() > 0.3                       # it did move


@pytest.mark.slow     # 51 s; tests/integrate/test_accuracy checks a floating tree's momentum
def test_floating_base_conserves_momentum():
    """A free-floating tree without gravity or torques: RKMK4 keeps the spatial momentum about
    the ground origin, the energy and the unit quaternions."""
    model = eqx.tree_at(lambda m: m.gravity,
                        _retyped(random_tree(3, seed=9), ("free", "spherical", "revolute")),
                        jnp.zeros(3))
    q0, v0, _, _ = random_state(model, seed=5)
    sol = simulate(rigid.TreeSystem(model), RKMK4(), q0, v0, dt=0.01, t1=1.0,
                   saveat=np.linspace(0, 1, 11))
    assert sol.messages() == ["success"]

    @jax.jit
    def invariants(qs, us):
        return (jax.jit(jax.vmap(rigid.spatial_momentum, (None, 0, 0)))(model, qs, us),
                jax.jit(jax.vmap(rigid.energy, (None, 0, 0)))(model, qs, us))

    h, E = invariants(sol.qs, sol.vs)
    np.testing.assert_allclose(h, np.broadcast_to(h[0], h.shape), rtol=0,
                               atol=1e-8 * float(jnp.abs(h[0]).max()))
    np.testing.assert_allclose(E, E[0], rtol=1e-8)
    quats = np.asarray(sol.qs)[:, 3:11].reshape(-1, 2, 4)        # the free and spherical joints
    np.testing.assert_allclose(np.linalg.norm(quats, axis=-1), 1.0, atol=1e-14)
    assert float(jnp.max(jnp.abs(sol.qs[-1, :3] - sol.qs[0, :3]))) > 1e-2   # the base drifted


# --------------------------------------------------------------------------------------------
# Gradients, vmap and input checks
# --------------------------------------------------------------------------------------------

GRAD_MODEL = _mixed()


def _forward_dynamics_of(method):
    @jax.jit
    def f(q, v, tau, mass):
        """GRAD_MODEL's joint accelerations as a function of the state, the joint forces and the
        masses (a model leaf)."""
        model = eqx.tree_at(lambda m: m.mass, GRAD_MODEL, mass)
        return rigid.forward_dynamics(model, q, v, tau, method=method)
    return f


FORWARD_DYNAMICS = {name: _forward_dynamics_of(method)
                    for name, method in (("recursive", Recursive()), ("dense", Dense()))}


@pytest.mark.parametrize("method", ["recursive", pytest.param("dense", marks=pytest.mark.slow)])
def test_check_grads_forward_dynamics(method):
    """Forward and reverse mode against central differences with respect to q, v, tau and the
    masses, at a random state and at q = neutral (identity quaternions, zero angles), v = 0, for
    every joint type. A NaN anywhere in a Jacobian would make the random directional derivative
    NaN and fail the check; the reverse-mode rows at neutral are checked finite too."""
    f = FORWARD_DYNAMICS[method]
    model = GRAD_MODEL
    q, v, tau, _ = random_state(model, seed=3)
    neutral = (model.neutral(), jnp.zeros(model.nv), jnp.zeros(model.nv), model.mass)
    for args in ((q, v, tau, model.mass), neutral):
        check_grads(f, args, order=1, modes=("fwd", "rev"), eps=1e-5, atol=1e-6, rtol=1e-6)
    _, pullback = jax.vjp(f, *neutral)
    for row in np.eye(model.nv):
        for leaf in pullback(jnp.asarray(row)):
            assert np.all(np.isfinite(leaf))


def test_vmap_over_states_equals_loop():
    model = GRAD_MODEL
    f = FORWARD_DYNAMICS["recursive"]
    states = [random_state(model, seed=s)[:3] for s in range(4)]
    q, v, tau = (jnp.stack(x) for x in zip(*states, strict=True))
    batched = jax.jit(jax.vmap(f, (0, 0, 0, None)))(q, v, tau, model.mass)
    # the batch runs as one compiled loop over the states (mbjax._src.rigid.batching), a single call
    # kernel by kernel: the same arithmetic, rounded apart by at most about 1e-12
    for i in range(len(states)):
        assert_close(batched[i], f(q[i], v[i], tau[i], model.mass), rtol=1e-11)


def test_forward_dynamics_rejects_bad_input():
    model = GRAD_MODEL
    q, v, tau = model.neutral(), jnp.zeros(model.nv), jnp.zeros(model.nv)
    with pytest.raises(TypeError, match=r"method must be mbjax.Recursive\(\), .*strings are gone"):
        rigid.forward_dynamics(model, q, v, tau, method="euler")
    with pytest.raises(ValueError, match=rf"q must have shape \({model.nq},\)"):
        rigid.forward_dynamics(model, v, v, tau)
    with pytest.raises(ValueError, match=rf"v must have shape \({model.nv},\)"):
        rigid.forward_dynamics(model, q, q, tau)
    with pytest.raises(ValueError, match="tau must have shape.*use jax.vmap for batches"):
        rigid.forward_dynamics(model, q, v, jnp.zeros((2, model.nv)))
    with pytest.raises(ValueError, match="v_dot must have shape"):
        rigid.inverse_dynamics(model, q, v, jnp.zeros(model.nv + 1))
    with pytest.raises(ValueError, match="q must have shape"):
        rigid.mass_matrix(model, q[:-1])
    with pytest.raises(ValueError, match=rf"f_ext must have shape \({model.n}, 6\)"):
        rigid.forward_dynamics(model, q, v, tau, f_ext=jnp.zeros(6))
    with pytest.raises(TypeError, match="method must be mbjax.Recursive"):
        rigid.TreeSystem(model, method="euler")
