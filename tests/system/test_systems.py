"""The system layer every system builds on: the forward-dynamics strategies chosen once, the
driven-system fields checked once, and what trajectory optimisation asks of any system (its state
sizes, its number of controls, a copy with another control)."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import mbjax
from mbjax import Auto, Dense, Recursive
from mbjax.control import Constant
from mbjax.integrate import RK4
from mbjax.model import chain
from mbjax.rigid import BatchTreeSystem, TreeSystem
from mbjax.scenes import carpal_wrist, four_bar
from mbjax.trajopt import Problem


def test_auto_picks_a_route_once_by_size():
    assert isinstance(Auto(crossover_nv=5).resolve(4), Dense)
    assert isinstance(Auto(crossover_nv=5).resolve(5), Recursive)
    assert isinstance(Recursive().resolve(1), Recursive) and isinstance(Dense().resolve(100), Dense)
    # the default is fixed when the strategy is made, from the runtime `import mbjax` set up
    assert Auto().crossover_nv in (0, 5)
    with pytest.raises(TypeError, match=r"an instance, Dense\(\)"):
        mbjax.forward_dynamics(chain(2), jnp.zeros(2), jnp.zeros(2), jnp.zeros(2), method=Dense)


def test_every_route_gives_the_same_accelerations():
    """The strategies on functions and on systems: Auto() set to either side of the crossover is
    exactly the route it names."""
    model = chain(3, seed=1)
    rng = np.random.default_rng(0)
    q, v, tau = (jnp.asarray(rng.normal(size=3)) for _ in range(3))
    recursive = mbjax.forward_dynamics(model, q, v, tau, method=Recursive())
    dense = mbjax.forward_dynamics(model, q, v, tau, method=Dense())
    np.testing.assert_allclose(recursive, dense, rtol=1e-11, atol=1e-11)
    for method, expected in ((Auto(crossover_nv=10), dense), (Auto(crossover_nv=0), recursive)):
        np.testing.assert_array_equal(mbjax.forward_dynamics(model, q, v, tau, method=method),
                                      expected)
        system = TreeSystem(model, Constant(tau), method=method)
        np.testing.assert_allclose(jax.jit(TreeSystem.acceleration)(system, 0.0, q, v), expected,
                                   rtol=1e-12, atol=1e-12)


def test_driven_fields_have_one_shape_in_every_system():
    """external_point is one body-frame point per body, (n, 3), in every system (a single (3,)
    point is broadcast), and the same argument errors name the same argument."""
    tree = TreeSystem(chain(3), external=lambda t, q, v: jnp.zeros((3, 6)), external_point=(0.1, 0, 0))
    assert tree.external_point.shape == (3, 3)
    wrist = mbjax.wrist.WristSystem(carpal_wrist.wrist(), external=lambda t, q, v: jnp.zeros((1, 6)),
                                    external_point=(0.0, 0.0, 0.01))
    assert wrist.external_point.shape == (1, 3)
    body = mbjax.rigid.RigidBody(1.0, jnp.eye(3), external_point=(0.0, 0.0, 0.1))
    assert body.external_point.shape == (1, 3)
    for make in (lambda **k: TreeSystem(chain(3), **k),
                 lambda **k: mbjax.wrist.WristSystem(carpal_wrist.wrist(), **k),
                 lambda **k: mbjax.rigid.RigidBody(1.0, jnp.eye(3), **k)):
        with pytest.raises(ValueError, match="external_point must be one body-frame point per body"):
            make(external_point=jnp.zeros((5, 3)))
        with pytest.raises(ValueError, match="actuation must be distinct indices"):
            make(actuation=[0, 0])


def test_what_trajectory_optimisation_asks_of_any_system():
    tree = TreeSystem(chain(3), actuation=[0, 2])
    assert tree.state_sizes() == (3, 3) and tree.n_controls == 2
    assert tree.with_control(Constant(jnp.ones(2))).control.value.tolist() == [1.0, 1.0]
    closed, q0, v0 = four_bar.build()
    assert closed.state_sizes() == (3, 3) and closed.n_controls == 3     # u is checked too
    driven = closed.with_control(Constant(jnp.ones(3)))
    assert driven.tree.control is not None and closed.tree.control is None
    problem = Problem(closed, q0, v0, dt=0.01, horizon=2, running=lambda q, v, u: u,
                      terminal=lambda q, v: v, integrator=RK4())
    assert problem.nu == 3
    wrist = mbjax.wrist.WristSystem(carpal_wrist.wrist())
    assert wrist.state_sizes() == (3, 3) and wrist.n_controls == 3
    with pytest.raises(TypeError, match="has no control to optimise"):
        Problem(BatchTreeSystem(chain(2)), jnp.zeros((2, 1)).ravel(), jnp.zeros(2), dt=0.1,
                horizon=1, running=lambda q, v, u: u, terminal=lambda q, v: v)
    with pytest.raises(ValueError, match=r"q0 must have shape \(3,\) for this system"):
        Problem(tree, jnp.zeros(2), jnp.zeros(3), dt=0.1, horizon=1,
                running=lambda q, v, u: u, terminal=lambda q, v: v)
