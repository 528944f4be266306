"""The throughput layout (`mbjax._src.rigid.batched`) against the one-state recursion, Pinocchio and
finite differences; `BatchTreeSystem` rollouts against vmapped ones; checkpointed gradients."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from jax.test_util import check_grads

from mbjax.integrate import RK4, simulate
from mbjax.model import Model, chain, random_tree
from mbjax._src.model.urdf import to_urdf
from mbjax.rigid import BatchTreeSystem, TreeSystem, batched_forward_dynamics, forward_dynamics
from mbjax._src.rigid import batch_aba
from mbjax._src.rigid.aba import aba
from mbjax._src.rigid.batched import CHUNK

MODELS = {
    "regular chain": lambda: chain(7),
    "random chain": lambda: chain(9, seed=3),
    "tree with sliders": lambda: random_tree(12, seed=4, joint_types=("revolute", "prismatic")),
    "damped, sprung chain": lambda: eqx.tree_at(
        lambda m: (m.damping, m.stiffness, m.spring_reference), chain(5, seed=2),
        (jnp.full(5, 0.2), jnp.linspace(1.0, 5.0, 5), jnp.full(5, -0.4))),
}


def _states(model, batch, seed=0, dtype=np.float64):
    rng = np.random.default_rng(seed)
    return tuple(jnp.asarray(x, dtype) for x in (rng.uniform(-np.pi, np.pi, (batch, model.nv)),
                                                 rng.normal(size=(batch, model.nv)),
                                                 rng.normal(size=(batch, model.nv))))


def _relative(a, ref):
    return float(jnp.max(jnp.abs(a - ref)) / jnp.max(jnp.abs(ref)))


@pytest.mark.parametrize("name", list(MODELS))
def test_batched_equals_the_one_state_recursion(name):
    model = MODELS[name]()
    q, v, tau = _states(model, 33)
    reference = jax.jit(jax.vmap(forward_dynamics, in_axes=(None, 0, 0, 0)))(model, q, v, tau)
    assert _relative(jax.jit(batched_forward_dynamics)(model, q, v, tau), reference) < 1e-12


def test_a_batch_of_several_chunks_equals_the_one_state_recursion():
    """More states than CHUNK, not a multiple of it: the chunks and the padded last one."""
    model = chain(7, seed=3)
    q, v, tau = _states(model, 2 * CHUNK + 22, seed=2)
    # one state after another (lax.map does not batch, so no batched route is taken)
    reference = jax.jit(lambda q, v, tau: jax.lax.map(lambda x: aba(model, *x), (q, v, tau)))(q, v, tau)
    assert _relative(jax.jit(batched_forward_dynamics)(model, q, v, tau), reference) < 1e-12


def test_batched_matches_pinocchio():
    pin = pytest.importorskip("pinocchio")
    model = chain(7, seed=11)
    q, v, tau = _states(model, 16, seed=5)
    pmodel = pin.buildModelFromXML(to_urdf(model))
    data = pmodel.createData()
    reference = np.stack([pin.aba(pmodel, data, *map(np.asarray, x)).copy()
                          for x in zip(q, v, tau, strict=True)])
    assert _relative(batched_forward_dynamics(model, q, v, tau), reference) < 1e-10


def test_float32_runs_in_float32_and_stays_close():
    model = chain(7)
    q, v, tau = _states(model, 64)
    exact = batched_forward_dynamics(model, q, v, tau)
    single = batched_forward_dynamics(model, *(x.astype(jnp.float32) for x in (q, v, tau)))
    assert single.dtype == jnp.float32
    assert _relative(single, exact) < 1e-4


@pytest.mark.slow     # the checkpointed-gradient test differentiates batch_aba rollouts by default
def test_gradients_match_finite_differences_at_zero_rotation():
    model = chain(4, seed=2)
    q = jnp.zeros((4, 3))
    v = jnp.asarray(np.random.default_rng(0).normal(size=(4, 3)))
    check_grads(lambda q, v: batch_aba(model, q, v, jnp.zeros(4)), (q, v), order=1,
                modes=("fwd", "rev"), atol=1e-6, rtol=1e-6)
    masses = jax.grad(lambda m: jnp.sum(batch_aba(eqx.tree_at(lambda x: x.mass, model, m), q, v,
                                                  jnp.ones(4)) ** 2))(model.mass)
    assert bool(jnp.all(jnp.isfinite(masses)))


def test_bad_input_is_refused():
    sphere = Model([-1, 0], ("spherical", "revolute"), mass=[1.0, 1.0], inertia=np.eye(3))
    with pytest.raises(ValueError, match="revolute and prismatic"):
        batch_aba(sphere, jnp.zeros((4, 2)), jnp.zeros((3, 2)), jnp.zeros(3))
    with pytest.raises(ValueError, match="batch last"):
        batch_aba(chain(3), jnp.zeros((2, 3)), jnp.zeros((2, 3)), jnp.zeros(3))
    with pytest.raises(ValueError, match=r"\(B, nv\)"):
        batched_forward_dynamics(chain(3), jnp.zeros(3), jnp.zeros(3), jnp.zeros(3))


def test_batch_rollout_equals_vmapped_rollouts():
    model = chain(5, seed=1)
    q, v, _ = _states(model, 8, seed=2)
    tau = jnp.linspace(-1.0, 1.0, model.nv)
    batch = simulate(BatchTreeSystem(model, tau), RK4(), q.T, v.T, dt=2e-3, t1=0.2,
                     saveat=np.array([0.1, 0.2]))
    one = jax.jit(jax.vmap(lambda q0, v0: simulate(TreeSystem(model, tau), RK4(), q0, v0, dt=2e-3, t1=0.2,
                                                   saveat=np.array([0.1, 0.2]))))(q, v)
    assert _relative(batch.qs, jnp.moveaxis(one.qs, 0, -1)) < 1e-11
    assert _relative(batch.vs, jnp.moveaxis(one.vs, 0, -1)) < 1e-11
    # a status per copy, as the vmapped runs have
    assert batch.status.shape == (8,) and np.all(np.asarray(batch.status) == 0)
    np.testing.assert_array_equal(batch.status, one.status)
    np.testing.assert_allclose(batch.resolution, one.resolution, rtol=1e-9)


def test_one_diverging_copy_does_not_mark_the_others():
    """A batch whose third copy starts with a velocity that RK4 at this step cannot follow
    (it overflows within two steps): that copy alone fails, and says when; the others
    succeed."""
    model = chain(3, seed=1)
    q, v, _ = _states(model, 4, seed=2)
    v = v.at[2].set(1e4)
    sol = simulate(BatchTreeSystem(model), RK4(), q.T, v.T, dt=1e-2, t1=1.0, saveat=[1.0])
    ok = np.asarray(sol.ok)
    assert sol.status.shape == (4,) and ok.tolist() == [True, True, False, True]
    words = sol.messages()
    assert words == ["success", "success", "nonfinite (first at t = 0.02 s)", "success"]


# slow (25-35 s): the default suite checks the same gradient and memory slope in notebook 08 §4
@pytest.mark.slow
def test_checkpointed_gradient_is_the_same_in_sqrt_t_memory():
    model = chain(4, seed=7)
    q, v, _ = _states(model, 16, seed=3)
    system = BatchTreeSystem(model)

    def loss(q0, v0, checkpoint):
        sol = simulate(system, RK4(), q0, v0, dt=1e-3, t1=0.4, saveat=np.array([0.4]),
                       checkpoint=checkpoint)
        return jnp.sum(sol.qs[-1] ** 2)

    grads, memory = {}, {}
    for checkpoint in (False, True):
        compiled = jax.jit(jax.grad(loss, argnums=(0, 1)), static_argnums=2).lower(
            q.T, v.T, checkpoint).compile()
        grads[checkpoint] = compiled(q.T, v.T)
        memory[checkpoint] = compiled.memory_analysis().temp_size_in_bytes
    for a, b in zip(grads[False], grads[True], strict=True):
        assert _relative(b, a) < 1e-12
    # 400 steps: the plain gradient keeps every step's residuals, the checkpointed one a segment's
    # (20 steps) plus the 20 segment ends
    assert memory[True] < memory[False] / 5
    eps = 1e-6
    direction = jnp.zeros_like(q.T).at[0, 0].set(1.0)
    value = jax.jit(loss, static_argnums=2)
    fd = (value(q.T + eps * direction, v.T, True) - value(q.T - eps * direction, v.T, True)) / (2 * eps)
    assert abs(float(grads[True][0][0, 0]) - float(fd)) < 1e-6 * max(1.0, abs(float(fd)))
