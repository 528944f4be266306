"""`jax.grad` and `jax.jacfwd` through `simulate` for every system, every integrator and every
loop method, projection included, against central finite differences (relative 1e-5, float64).

Each cell differentiates one scalar of a short rollout with respect to three parameters at once:
p[0] perturbs the initial state, p[1] scales a control parameter (a gain, a spline's knots, a
constant torque) and p[2] a model parameter (a mass, a modal stiffness, the wrist's tool mass).
The matrix covers every system with RK4, every integrator on a quaternion tree and on a
projected closed loop, and every loop method with and without projection.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax.control import PD, Constant, CubicSpline
from mbjax.flex import Beam, FlexibleModel, FlexibleSystem, beam_body, craig_bampton
from mbjax.integrate import INTEGRATORS, RK4, simulate
from mbjax.loops import ClosedSystem, Coupled, Momentum, Stabilized
from mbjax.model import Model, chain
from mbjax.rigid import RigidBody, TreeSystem
from mbjax.scenes import carpal_wrist as cw
from mbjax.scenes import flexible_slider_crank as fsc
from mbjax.scenes import four_bar
from mbjax.wrist import WristSystem

H = 1e-5                              # central differences: truncation ~1e-10, round-off ~1e-11
P0 = jnp.array([0.0, 0.0, 0.0])


def _scalar(sol):
    """A smooth scalar of the final state that every coordinate enters."""
    q, u = sol.qs[-1], sol.us[-1]
    return jnp.sum(jnp.sin(q) * jnp.arange(1, q.shape[0] + 1)) + 0.1 * jnp.sum(u**2)


def _run(system, integrator, q0, u0, dt, steps):
    t1 = dt * steps
    return _scalar(simulate(system, integrator, q0, u0, dt=dt, t1=t1, saveat=[t1]))


# -- the systems ------------------------------------------------------------------------------------

def rigid_body(p, integrator):
    """A heavy top (quaternion) under a constant body torque."""
    body = RigidBody(1.0 + p[2], np.diag([0.3, 0.4, 0.2]), com=(0.02, 0.01, 0.1), fixed_point=True,
                     control=Constant(jnp.array([0.1, -0.2, 0.05]) * (1.0 + p[1])))
    q0, u0 = body.initial_state(np.eye(3), jnp.array([0.5 + p[0], 0.2, 8.0]))
    return _run(body, integrator, q0, u0, 0.01, 10)


def tree(p, integrator):
    """A random revolute chain under a PD servo."""
    model = chain(3, seed=1)
    model = eqx.tree_at(lambda m: m.mass, model, model.mass.at[1].multiply(1.0 + p[2]))
    system = TreeSystem(model, PD(5.0 * (1.0 + p[1]), 0.5, jnp.zeros(3)))
    return _run(system, integrator, jnp.array([0.3 + p[0], -0.2, 0.1]), jnp.zeros(3), 0.01, 10)


QUATERNION_TREE = chain(2, joint_types=("spherical", "revolute"), seed=2)


def quaternion_tree(p, integrator):
    """A spherical root joint (quaternion, retracted in RKMK4's chart) carrying a hinge, under a
    PD on the hinge and an external force on the last body."""
    model = eqx.tree_at(lambda m: m.mass, QUATERNION_TREE,
                        QUATERNION_TREE.mass.at[1].multiply(1.0 + p[2]))
    push = jnp.zeros((2, 6)).at[1, 3].set(0.5)
    system = TreeSystem(model, PD(2.0 * (1.0 + p[1]), 0.1, jnp.zeros(1), q_index=[4], v_index=[3]),
                        actuation=[3], external=lambda t, q, v: push * (1.0 + t))
    q0 = model.retract(model.neutral(), jnp.array([0.2 + p[0], -0.1, 0.3, 0.4]))
    return _run(system, integrator, q0, jnp.array([0.5, 0.0, -0.3, 0.2]), 0.01, 10)


def _flexible_model():
    beam = Beam.round(1.0, 0.02, E=7e10, rho=2700.0, nu=0.33, n_elements=2)
    body = beam_body(beam, craig_bampton(beam, n_modes=2, planar="xz"))
    hinge = Model([-1], ["revolute"], mass=[0.85], com=[[0.5, 0, 0]], inertia=[np.eye(3) * 0.07],
                  axis=[[0, 1, 0]], gravity=(0.0, 0.0, -9.81))
    return FlexibleModel(hinge, {0: body})


FLEXIBLE = _flexible_model()


def flexible(p, integrator):
    """A beam on a hinge driven by a torque spline, geometric stiffening on."""
    model = eqx.tree_at(lambda m: m.bodies.stiffness, FLEXIBLE,
                        FLEXIBLE.bodies.stiffness * (1.0 + p[2]))
    spline = CubicSpline(jnp.array([[0.0], [2.0], [-1.0], [0.5], [1.0]]) * (1.0 + p[1]), 0.02)
    system = FlexibleSystem(model, spline, actuation=[0])
    q0 = jnp.zeros(model.nq).at[1].set(1e-3 * (1.0 + p[0]))
    return _run(system, integrator, q0, jnp.zeros(model.nv), 2e-4, 10)


SERVOED, THETA0, _ = cw.servo()


def wrist(p, integrator):
    """The Carpal Wrist under its servo plus a torque spline."""
    servoed, theta0 = SERVOED, THETA0
    w = eqx.tree_at(lambda w: w.tool_mass, servoed.wrist, servoed.wrist.tool_mass * (1.0 + p[2]))
    feedforward = CubicSpline(jnp.array([[0.1, -0.1, 0.0], [0.3, 0.0, -0.2], [0.0, 0.2, 0.1],
                                         [-0.1, 0.1, 0.0]]) * (1.0 + p[1]), 0.1)
    system = WristSystem(w, servoed.control + feedforward)
    return _run(system, integrator, theta0.at[0].add(p[0]), jnp.zeros(3), 0.01, 10)


FOUR_BAR, FB_Q0, FB_V0 = four_bar.build()
FB_DIRECTION = FB_V0 / four_bar.OMEGA0


def closed(method, projection):
    """The four-bar driven by a constant crank torque, closed by `method`."""
    def loss(p, integrator):
        model = FOUR_BAR.tree.model
        model = eqx.tree_at(lambda m: m.mass, model, model.mass.at[1].multiply(1.0 + p[2]))
        tree = TreeSystem(model, Constant(jnp.array([0.2 * (1.0 + p[1])])), actuation=[0])
        system = ClosedSystem(tree, FOUR_BAR.closures, method, projection)
        v0 = FB_DIRECTION * (four_bar.OMEGA0 + p[0])
        return _run(system, integrator, FB_Q0, system.initial_state(FB_Q0, v0), 1e-3, 10)
    return loss


FSC, FSC_Q0, FSC_V0, _ = fsc.build(n_elements=1)


def closed_flexible(projection):
    """The flexible slider-crank (driven crank, the slider at a marker of the rod) closed by
    seed 002's route, a torque on the rod's joint."""
    def loss(p, integrator):
        model = FSC.tree.model
        model = eqx.tree_at(lambda m: m.bodies.stiffness, model, model.bodies.stiffness * (1.0 + p[2]))
        tree = FlexibleSystem(model, Constant(jnp.array([0.05 * (1.0 + p[1])])), actuation=[1])
        system = ClosedSystem(tree, FSC.closures, Stabilized(), projection)
        u0 = FSC_V0.at[2].add(p[0])
        return _run(system, integrator, FSC_Q0, u0, 1e-5, 10)
    return loss


# -- the matrix -------------------------------------------------------------------------------------

CELLS = {
    **{f"quaternion tree, {name}": (quaternion_tree, name) for name in INTEGRATORS},
    "rigid body, rkmk4": (rigid_body, "rkmk4"),
    "tree, rk4": (tree, "rk4"),
    "flexible, rk4": (flexible, "rk4"),
    "wrist, rk4": (wrist, "rk4"),
    **{f"closed {label}, projection {proj}, rk4": (closed(method, proj), "rk4")
       for label, method in (("coupled", Coupled()), ("baumgarte", Coupled(baumgarte=(20.0, 20.0))),
                             ("momentum", Momentum()), ("stabilized", Stabilized()),
                             ("epsilon", Stabilized(epsilon=1.0, kappa=10.0)))
       for proj in (False, True)},
    **{f"closed coupled, projection True, {name}": (closed(Coupled(), True), name)
       for name in INTEGRATORS if name != "rk4"},
    **{f"closed flexible, projection {proj}, rk4": (closed_flexible(proj), "rk4")
       for proj in (False, True)},
}


@pytest.mark.parametrize("cell", list(CELLS))
def test_gradients_match_central_differences(cell):
    fn, integrator_name = CELLS[cell]
    integrator = INTEGRATORS[integrator_name]()

    def loss(p):
        return fn(p, integrator)

    @jax.jit
    def everything(p):
        steps = H * jnp.concatenate([jnp.eye(3), -jnp.eye(3)])
        values = jax.vmap(loss)(p + steps)
        return jax.grad(loss)(p), jax.jacfwd(loss)(p), (values[:3] - values[3:]) / (2 * H)

    grad, jacfwd, fd = everything(P0)
    assert bool(jnp.all(jnp.isfinite(grad)) & jnp.all(jnp.isfinite(jacfwd))), (grad, jacfwd)
    scale = float(jnp.abs(fd).max())
    assert scale > 1e-6, fd                            # the loss does depend on the parameters
    for derivative in (grad, jacfwd):
        np.testing.assert_allclose(derivative, fd, rtol=1e-5, atol=1e-7 * scale)
