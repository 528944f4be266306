"""The derivative rule of `mbjax._src.rigid.adjoint`: forward dynamics differentiated through the RNEA
and the articulated-body factor of M, against differentiating the recursion itself, the dense mass
matrix, and central differences."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax import Recursive
from mbjax.model import random_tree
from mbjax.rigid import forward_dynamics, mass_matrix
from mbjax._src.rigid.aba import aba, aba_factored, solve
from mbjax._src.rigid.dynamics import recursive_forward_dynamics
from mbjax._src.rigid.rnea import inverse_dynamics
from mbjax._src.rigid.rnea_derivatives import applies, rnea_jvp


def _with_joint_data(model):
    rng = np.random.default_rng(7)
    sprung = model.spring_index() >= 0          # springs on revolute, prismatic, universal joints
    return eqx.tree_at(lambda m: (m.damping, m.armature, m.stiffness, m.spring_reference), model,
                       (jnp.asarray(rng.uniform(0.0, 0.5, model.nv)),
                        jnp.asarray(rng.uniform(0.0, 0.1, model.nv)),
                        jnp.asarray(rng.uniform(0.0, 3.0, model.nv) * sprung),
                        jnp.asarray(rng.uniform(-1.0, 1.0, model.nq))))


# every joint type, a branching tree, joint damping, springs and armature
MODEL = _with_joint_data(
    random_tree(5, seed=4, joint_types=("free", "spherical", "universal", "revolute", "prismatic")))
# the joints whose RNEA derivatives in (q, v) are written out (`rnea_derivatives`): revolute and
# prismatic only, and with spherical and free joints (quaternions) too
HINGES = _with_joint_data(random_tree(6, seed=2))
BALLS = _with_joint_data(
    random_tree(6, seed=8, joint_types=("free", "spherical", "revolute", "prismatic")))


def _state(model, seed):
    rng = np.random.default_rng(seed)
    q = model.normalize(jnp.asarray(rng.standard_normal(model.nq)))
    v, tau = (jnp.asarray(rng.standard_normal(model.nv)) for _ in range(2))
    f_ext = jnp.asarray(rng.standard_normal((model.n, 6)))
    return q, v, tau, f_ext


def _relative(a, b):
    if not jnp.size(b):
        return 0.0
    return float(jnp.max(jnp.abs(a - b)) / jnp.maximum(jnp.max(jnp.abs(b)), 1.0))


def test_solve_with_the_factor_is_the_inverse_mass_matrix():
    """aba.solve(factor, b) = M^-1 b, M from the composite-rigid-body algorithm (equal to
    Jerkovsky 1978 eq 55's operator form: tests/rigid/test_tree_dynamics.py)."""
    q, v, tau, _ = _state(MODEL, 0)
    b = jnp.asarray(np.random.default_rng(1).standard_normal(MODEL.nv))

    @jax.jit
    def both(q, b):
        _, factor = aba_factored(MODEL, q, v, tau)
        return solve(MODEL, factor, b), jnp.linalg.solve(mass_matrix(MODEL, q), b)

    ours, reference = both(q, b)
    assert _relative(ours, reference) < 1e-12


# the spherical joints' variant is slow: "every joint" has spherical joints too
@pytest.mark.parametrize(("model", "wrenches"), [(MODEL, True), (HINGES, False),
                                                 pytest.param(BALLS, False, marks=pytest.mark.slow)],
                         ids=["every joint, f_ext", "hinges", "balls"])
def test_first_derivatives_are_the_recursions(model, wrenches):
    """jacfwd and jacrev in q, v, tau (and the external wrenches), at a random state and at
    q = neutral, v = 0 (zero rotations), against those of `aba` itself: through JAX's
    derivative of the RNEA (a universal joint, external wrenches) and through the RNEA's
    derivatives written out (trees of hinges; with free and spherical joints)."""
    q, v, tau, f_ext = _state(model, 2)
    neutral = (model.neutral(), jnp.zeros(model.nv), tau, f_ext)
    if not wrenches:
        f_ext, neutral = None, neutral[:3] + (None,)
    assert applies(model) == (model is not MODEL)

    def ours(*x):
        return recursive_forward_dynamics(model, *x)

    def recursion(*x):
        return aba(model, *x)

    argnums = (0, 1, 2, 3) if wrenches else (0, 1, 2)
    want = jax.jit(jax.jacfwd(recursion, argnums=argnums))
    for transform in (jax.jacfwd, jax.jacrev):
        got = jax.jit(transform(ours, argnums=argnums))
        for args in ((q, v, tau, f_ext), neutral):
            for g, w in zip(got(*args), want(*args), strict=True):
                assert np.all(np.isfinite(g))
                assert _relative(g, w) < 1e-11


@pytest.mark.parametrize("model", [MODEL, pytest.param(BALLS, marks=pytest.mark.slow)],
                         ids=["every joint", "balls"])
def test_model_gradient_is_the_recursions(model):
    """Reverse mode in every model leaf (masses, inertias, placements, axes, gravity, damping,
    armature) and q together against the recursion's, and forward mode along one random model
    direction against that gradient's projection. An inertia's gradient is meaningful up to its
    antisymmetric part: the symmetric parts are compared, and the direction's inertias are
    symmetric. The tree without universal joints, with no external wrench, takes the
    written-out (q, v) derivatives beside the model's by autodiff."""
    q, v, tau, f_ext = _state(model, 3)
    f_ext = f_ext if model is MODEL else None

    def loss(fd):
        return lambda m, q=q: jnp.sum(jnp.sin(fd(m, q, v, tau, f_ext)))

    got, got_q = jax.jit(jax.grad(loss(recursive_forward_dynamics), argnums=(0, 1)))(model, q)
    want, want_q = jax.jit(jax.grad(loss(aba), argnums=(0, 1)))(model, q)
    assert _relative(got_q, want_q) < 1e-10
    got, want = (eqx.tree_at(lambda m: m.inertia, g, (g.inertia + jnp.swapaxes(g.inertia, -1, -2)) / 2)
                 for g in (got, want))
    for g, w in zip(jax.tree.leaves(got), jax.tree.leaves(want), strict=True):
        assert _relative(g, w) < 1e-10

    rng = np.random.default_rng(5)
    direction = jax.tree.map(lambda x: jnp.asarray(rng.standard_normal(x.shape)), model)
    direction = eqx.tree_at(lambda m: m.inertia, direction,
                            direction.inertia + jnp.swapaxes(direction.inertia, -1, -2))
    along = jax.jit(lambda m, d: jax.jvp(loss(recursive_forward_dynamics), (m,), (d,))[1])(
        model, direction)
    expected = sum(jnp.vdot(w, d) for w, d in zip(jax.tree.leaves(want),
                                                   jax.tree.leaves(direction), strict=True))
    assert _relative(along, expected) < 1e-10


def test_second_derivatives_against_central_differences():
    """jit(hessian) of a scalar of the accelerations (the rule differentiated again) against
    central differences of its gradient, and symmetric. (XLA 0.10.2's CPU dot emitter aborts the
    process compiling jit(hessian) on some trees, with or without this rule: random_tree(3,
    seed=0) does, a layout check on a batched dot; this tree compiles.)"""
    model = random_tree(5, seed=0)
    rng = np.random.default_rng(0)
    q, v, tau = (jnp.asarray(rng.standard_normal(model.nv)) for _ in range(3))

    def f(q):
        return jnp.sum(forward_dynamics(model, q, v, tau, method=Recursive()) ** 3)

    H = jax.jit(jax.hessian(f))(q)
    grad, eps = jax.jit(jax.grad(f)), 1e-6
    central = jnp.stack([(grad(q + eps * e) - grad(q - eps * e)) / (2 * eps)
                         for e in jnp.eye(model.nv)])
    assert _relative(H, central) < 1e-7
    assert _relative(H, H.T) < 1e-12


@pytest.mark.parametrize("model", [HINGES, BALLS], ids=["hinges", "balls"])
@pytest.mark.parametrize("where", ["random", "zero rotation", "half turns"])
def test_rnea_jvp_is_the_rneas_derivative(model, where):
    """`rnea_jvp` (the RNEA's (q, v) derivative written out) against `jax.jvp` of the RNEA
    itself, damping and armature included, at a random state (quaternions off the unit sphere,
    as the RNEA reads them normalized), at the neutral configuration and at half turns of every
    revolute joint and quaternion; and its transpose (reverse mode, what the adjoint runs)
    against `jax.vjp`."""
    rng = np.random.default_rng(11)
    q, dq = (jnp.asarray(rng.standard_normal(model.nq)) for _ in range(2))
    v, a, dv, lam = (jnp.asarray(rng.standard_normal(model.nv)) for _ in range(4))
    half_turn = np.full(model.nq, np.pi)
    for w in np.flatnonzero(np.asarray(model.neutral()) == 1.0):     # quaternions (0, 1, 0, 0)
        half_turn[w:w + 4] = (0.0, 1.0, 0.0, 0.0)
    q = {"random": 0.5 * q + model.neutral(), "zero rotation": model.neutral(),
         "half turns": jnp.asarray(half_turn)}[where]

    got, want, got_t, want_t = _rnea_derivatives(model, q, v, a, dq, dv, lam)
    assert _relative(got, want) < 1e-12
    for g, w in zip(got_t, want_t, strict=True):
        assert _relative(g, w) < 1e-12


@jax.jit
def _rnea_derivatives(model, q, v, a, dq, dv, lam):
    """(rnea_jvp, jax.jvp of the RNEA, rnea_jvp's transpose at lam, jax.vjp of the RNEA at lam),
    one compiled program per model."""
    def rnea(q, v):
        return inverse_dynamics(model, q, v, a)

    _, want = jax.jvp(rnea, (q, v), (dq, dv))
    _, vjp = jax.vjp(rnea, q, v)
    _, transpose = jax.vjp(lambda dq, dv: rnea_jvp(model, q, v, a, dq, dv), dq, dv)
    return rnea_jvp(model, q, v, a, dq, dv), want, transpose(lam), vjp(lam)
