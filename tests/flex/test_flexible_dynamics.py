"""Flexible bodies in the tree dynamics (Anderson 1993 eqs 20-86): the modal body's coefficients
against direct sums over its mass points, the O(n) recursion against the dense Lagrangian route
(an independent derivation from the energies), energy conservation, gradients through a rollout
against finite differences, and the bad-input errors."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax import Recursive, Dense
from mbjax.flex import (Beam, FlexibleModel, FlexibleSystem, ModalBody, beam_body, craig_bampton,
                        forward_dynamics)
from mbjax._src.flex import energy, flexible_aba
from mbjax._src.flex.body import mass_matrix
from mbjax.integrate import RK4, simulate
from mbjax.lie import exp
from mbjax.loops import ClosedSystem, Coupled, Momentum, Prescribed, Stabilized
from mbjax.model import Model
from mbjax._src.spatial import skew


class Points(eqx.Module):
    mass: jax.Array
    position: jax.Array
    phi: jax.Array
    psi: jax.Array
    inertia: jax.Array


def random_points(key, P=6, mu=3):
    k = jax.random.split(key, 5)
    return Points(jax.random.uniform(k[0], (P,), minval=0.5, maxval=1.5),
                  jax.random.normal(k[1], (P, 3)) * 0.3 + jnp.array([0.5, 0.0, 0.0]),
                  jax.random.normal(k[2], (P, 3, mu)) * 0.2, jax.random.normal(k[3], (P, 3, mu)) * 0.2,
                  jnp.broadcast_to(jnp.diag(jnp.array([0.01, 0.02, 0.03])), (P, 3, 3)))


def random_body(key, P=6, mu=3, H=2, stiffening=True):
    """Random coefficients; with stiffening, random (symmetric) inertial and distal unit-load
    matrices, so the distal terms of every load at a grid point are exercised in both routes."""
    k = jax.random.split(key, 7)
    Kr = jax.random.normal(k[0], (mu, mu))
    Ks = jax.random.normal(k[1], (21, mu, mu)) * 0.1
    Kd = jax.random.normal(k[6], (H, 6, mu, mu)) * 0.1
    nodes = (jax.random.normal(k[2], (H, 3)) * 0.3, jax.random.normal(k[3], (H, 3, mu)) * 0.2,
             jax.random.normal(k[4], (H, 3, mu)) * 0.2)
    return ModalBody.from_points(random_points(k[5], P, mu), Kr @ Kr.T + mu * jnp.eye(mu),
                                 inertial_stiffening=Ks + jnp.swapaxes(Ks, 1, 2) if stiffening else None,
                                 distal_stiffening=Kd + jnp.swapaxes(Kd, 2, 3) if stiffening else None,
                                 nodes=nodes, damping=0.1 * jnp.eye(mu))


def random_tree(stiffening=True, gravity=(0.0, 0.0, -9.81)):
    """Revolute, prismatic, universal joints; bodies 1 and 3 flexible (3 and 2 modes), bodies 2, 3
    and 4 attached at grid points of flexible parents."""
    rng = np.random.default_rng(0)
    parents, n = (-1, 0, 1, 1, 3), 5
    k1, k2 = jax.random.split(jax.random.PRNGKey(1))
    flexible = {1: random_body(k1, 6, 3, 2, stiffening), 3: random_body(k2, 5, 2, 2, stiffening)}
    mass = np.ones(n)
    mass[[1, 3]] = [float(flexible[1].mass), float(flexible[3].mass)]   # the ModalBodies' own
    rigid = Model(parents, ("revolute", "revolute", "prismatic", "revolute", "universal"),
                  mass=mass, inertia=np.tile(np.eye(3) * 0.1, (n, 1, 1)),
                  com=rng.normal(size=(n, 3)) * 0.2, axis=rng.normal(size=(n, 3)),
                  axis2=rng.normal(size=(n, 3)), placement_translation=rng.normal(size=(n, 3)) * 0.5,
                  placement_rotation=np.stack([np.asarray(exp(jnp.asarray(rng.normal(size=3))))
                                               for _ in range(n)]), gravity=gravity)
    return FlexibleModel(rigid, flexible, attach={2: 0, 3: 1, 4: 1})


def test_modal_mass_matrix_is_the_sum_over_mass_points():
    """M(q) from the time-invariant coefficients equals sum_p L_p^T m_p L_p + J_p^T I_p J_p with
    each point's velocity Jacobian built directly (v_p = v - xi_p~ omega + phi_p u,
    omega_p = omega + psi_p u, xi_p = rho_p + phi_p q)."""
    pts = random_points(jax.random.PRNGKey(3), P=7, mu=4)
    body = ModalBody.from_points(pts, jnp.eye(4))
    q = jnp.array([0.3, -0.2, 0.5, 0.1])
    xi = pts.position + jnp.einsum("pis,s->pi", pts.phi, q)
    eye = jnp.broadcast_to(jnp.eye(3), (7, 3, 3))
    L = jnp.concatenate([-skew(xi), eye, pts.phi], -1)
    J = jnp.concatenate([eye, jnp.zeros((7, 3, 3)), pts.psi], -1)
    direct = (jnp.einsum("p,pia,pib->ab", pts.mass, L, L)
              + jnp.einsum("pia,pij,pjb->ab", J, pts.inertia, J))
    np.testing.assert_allclose(mass_matrix(body, q), direct, rtol=0, atol=1e-13)


@pytest.mark.parametrize("stiffening", [True, pytest.param(False, marks=pytest.mark.slow)])
def test_recursion_matches_the_lagrangian_route(stiffening):
    """Anderson 1993's O(n) recursion with modal blocks, attachments and Table 1 stiffening (inertial,
    and distal: the children's reactions at the grid points) against Lagrange's equations from
    the energies (no shared partial velocities), at a random state."""
    model = random_tree(stiffening)
    rng = np.random.default_rng(1)
    q = jnp.asarray(rng.normal(size=model.nq)) * 0.5
    v, tau = jnp.asarray(rng.normal(size=model.nv)), jnp.asarray(rng.normal(size=model.nv))
    recursive = forward_dynamics(model, q, v, tau, method=Recursive())
    dense = forward_dynamics(model, q, v, tau, method=Dense())
    np.testing.assert_allclose(recursive, dense, rtol=1e-11, atol=1e-11)


def test_energy_is_conserved_without_stiffening():
    """Gravity, elasticity and the coupling of the swinging beam and its tip pendulum conserve
    T + V (geometric stiffening, a linearized prestress, is not conservative); RK4's energy error
    falls like dt^4."""
    model = cantilever().without_stiffening()
    system = FlexibleSystem(model)
    q0 = model.neutral().at[0].set(0.3).at[1].set(-0.5)
    errors = []
    for dt in (5e-4, 2.5e-4):
        sol = simulate(system, RK4(), q0, jnp.zeros(model.nv), dt=dt, t1=0.1, saveat=[0.0, 0.1])
        E = jax.jit(jax.vmap(energy, (None, 0, 0)))(model, sol.qs, sol.vs)
        errors.append(abs(float(E[1] - E[0])) / abs(float(E[0])))
    assert errors[1] < 1e-7 and 10 < errors[0] / errors[1] < 25      # fourth order: ratio ~ 16


def cantilever_body(E=7e10, n_elements=4, n_modes=2) -> ModalBody:
    """The cantilever's beam: 1 m of aluminium, 2 cm round, clamped at its hinge."""
    structure = Beam.round(1.0, 0.02, E, 2700.0, nu=0.33, n_elements=n_elements)
    basis = craig_bampton(structure, n_modes=n_modes, planar="xz")
    return beam_body(structure, basis, nodes=(n_elements,))


def cantilever(E=7e10, n_elements=4, n_modes=2):
    """A 1 m aluminium cantilever on a revolute hinge (about y), with a rigid pendulum attached at
    its last grid point through a revolute joint (about y); its fastest mode is 1.7e3 rad/s, so
    RK4 needs dt < 1.6 ms."""
    body = cantilever_body(E, n_elements, n_modes)
    rigid = Model([-1, 0], ["revolute", "revolute"], mass=[0.85, 0.5],
                  com=[[0.5, 0, 0], [0.05, 0, 0]],
                  inertia=[np.diag([1e-5, 0.07, 0.07]), np.diag([1e-4, 1e-3, 1e-3])],
                  axis=[[0, 1, 0], [0, 1, 0]], placement_translation=[[0, 0, 0], [1.0, 0, 0]])
    return FlexibleModel(rigid, {0: body}, attach={1: 0})


@pytest.mark.parametrize("t1, mode", [(0.02, jax.jacfwd),
                                      pytest.param(0.1, jax.grad, marks=pytest.mark.slow)])
def test_gradient_through_a_flexible_rollout_matches_finite_differences(t1, mode):
    """d(tip angle at t1)/dE through the whole pipeline: beam matrices, the eigenproblem, the
    modal coefficients and the geometric stiffening (distal load of the tip body), the recursion
    and the rollout: by default 40 steps in forward mode (a third of the compilation); reverse
    mode over 200 steps in the slow run."""
    def tip(E):
        model = cantilever(E)
        q0 = model.neutral().at[0].set(0.2)
        sol = simulate(FlexibleSystem(model), RK4(), q0, jnp.zeros(model.nv), dt=5e-4, t1=t1,
                       saveat=[t1])
        return sol.qs[-1, 1]

    E, h = 7e10, 7e5
    grad = mode(tip)(E)
    fd = (tip(E + h) - tip(E - h)) / (2 * h)
    assert np.isfinite(grad) and grad != 0
    np.testing.assert_allclose(grad, fd, rtol=1e-5)


def test_a_child_is_its_reaction_at_the_grid_point():
    """The recursion's distal-load stiffening (eq 33's F^J terms) is that of the child's
    reaction: the cantilever without its pendulum, loaded at the same grid point (a marker) by the
    pendulum's reaction F from Newton-Euler on the pendulum alone, moves exactly as with it, hinge
    and modes alike, on both routes (an applied load stiffens as a child does); and the reaction
    does stiffen the beam (the same load without the grid
    point's second-order displacement gives different modal accelerations)."""
    model = cantilever()
    rng = np.random.default_rng(2)
    q = model.neutral().at[0].set(0.4).at[1].set(-0.3).at[2:].set(jnp.asarray(rng.normal(size=2)) * 1e-3)
    v = jnp.asarray(rng.normal(size=model.nv))
    v_dot = jax.jit(flexible_aba)(model, q, v, jnp.zeros(model.nv))
    from mbjax._src.flex.lagrange import _body_motion
    R, _, omega, _, alpha, a = jax.jit(_body_motion)(model, q, v, v_dot)
    child = model.model
    m, c, Ic = child.mass[1], child.com[1], child.inertia[1]
    w, al, acc = omega[1], alpha[1], a[1]                     # body-frame, gravity folded into a
    a_com = acc + jnp.cross(al, c) + jnp.cross(w, jnp.cross(w, c))
    force_on_child = m * a_com                                # body 1's frame
    moment_on_child = Ic @ al + jnp.cross(w, Ic @ w) + jnp.cross(c, m * a_com)   # about its origin
    F = -jnp.concatenate([R[1] @ moment_on_child, R[1] @ force_on_child])        # world, on the beam

    def alone(beam_body, method=Recursive()):
        rigid = Model([-1], ["revolute"], mass=[0.85], com=[[0.5, 0, 0]],
                      inertia=[np.diag([1e-5, 0.07, 0.07])], axis=[[0, 1, 0]])
        beam = FlexibleModel(rigid, {0: beam_body}, markers=((0, 0),))
        system = FlexibleSystem(beam, external=lambda t, q_, v_: jnp.stack([jnp.zeros(6), F]),
                                method=method)
        keep = np.r_[0, 2:model.nv]
        accelerate = eqx.filter_jit(lambda s_, q_, v_: s_.acceleration(0.0, q_, v_))
        return accelerate(system, q[keep], v[keep]), keep

    loaded, keep = alone(cantilever_body())
    np.testing.assert_allclose(loaded, v_dot[keep], rtol=1e-10, atol=1e-10 * float(jnp.max(jnp.abs(v_dot))))
    # the Lagrangian route takes the load at the marker through the same virtual work
    np.testing.assert_allclose(alone(cantilever_body(), Dense())[0], loaded, rtol=1e-10,
                               atol=1e-10 * float(jnp.max(jnp.abs(v_dot))))
    linear, _ = alone(cantilever_body().without_stiffening())
    assert float(jnp.max(jnp.abs(linear[1:] - loaded[1:]))) > 1e-3 * float(jnp.max(jnp.abs(loaded[1:])))


def test_a_rigid_mass_the_flexible_body_replaces_is_not_dropped_unseen():
    """The rigid model's mass of a flexible body is not used (the ModalBody's is): where they
    differ, a warning says so; the dynamics are the ModalBody's either way."""
    model = cantilever()
    heavier = eqx.tree_at(lambda m: m.mass, model.model, model.model.mass.at[0].set(5.0))
    with pytest.warns(UserWarning, match="body 0's mass in the rigid model, 5, is not used"):
        other = FlexibleModel(heavier, {0: cantilever_body()}, attach={1: 0})
    q, v = model.neutral().at[0].set(0.3), jnp.ones(model.nv)
    np.testing.assert_allclose(jax.jit(flexible_aba)(other, q, v, jnp.zeros(model.nv)),
                               jax.jit(flexible_aba)(model, q, v, jnp.zeros(model.nv)), rtol=1e-12)


def test_bad_input_is_a_clear_error():
    body = random_body(jax.random.PRNGKey(0), H=1)
    rigid = Model([-1, 0], "revolute", mass=[float(body.mass), 1.0],
                  inertia=[np.eye(3), np.eye(3)])
    with pytest.raises(ValueError, match="attach"):
        FlexibleModel(rigid, {0: body})
    with pytest.raises(ValueError, match="grid point 3"):
        FlexibleModel(rigid, {0: body}, attach={1: 3})
    with pytest.raises(ValueError, match="no flexible body"):
        FlexibleModel(rigid, {})
    with pytest.raises(ValueError, match="marker"):
        FlexibleModel(rigid, {0: body}, attach={1: 0}, markers=((1, 0),))
    model = FlexibleModel(rigid, {0: body}, attach={1: 0})
    for method in (Coupled(), Momentum()):
        with pytest.raises(TypeError, match="Stabilized"):
            ClosedSystem(FlexibleSystem(model), [Prescribed(0)], method)
    closed = ClosedSystem(FlexibleSystem(model), [Prescribed(0)])
    assert isinstance(closed.method, Stabilized)
    with pytest.raises(TypeError, match="method must be mbjax.Recursive"):
        FlexibleSystem(model, method="fast")


def test_closed_loop_routes_agree_with_the_constraint_load_stiffening():
    """The flexible slider-crank (Anderson 1993 §3.1, one element) at a deformed, moving state: the
    stabilized route's accelerations from the O(n) recursion and from the dense Lagrangian route
    (its load responses solved from the mass matrix) agree, the slider's constraint load included;
    and that load stiffens the rod: without the grid point's second-order displacement the modal
    accelerations differ."""
    from mbjax.scenes import flexible_slider_crank as scene

    system, q0, v0, _ = scene.build(1)
    rng = np.random.default_rng(4)
    q = q0.at[2:].set(jnp.asarray(rng.normal(size=3)) * 1e-4)
    v = v0.at[2:].set(jnp.asarray(rng.normal(size=3)))
    dense = eqx.tree_at(lambda s: s.loops.tree, system,
                        FlexibleSystem(system.tree.model, method=Dense()))
    accelerate = eqx.filter_jit(lambda s_, q_, v_: s_.acceleration(0.003, q_, v_))
    recursive = accelerate(system, q, v)
    np.testing.assert_allclose(accelerate(dense, q, v), recursive, rtol=1e-9,
                               atol=1e-9 * float(jnp.max(jnp.abs(recursive))))
    linear, _, _, _ = scene.build(1, stiffening=False)
    unstiffened = accelerate(linear, q, v)
    assert float(jnp.max(jnp.abs(unstiffened[2:] - recursive[2:]))) > 1e-3 * float(jnp.max(jnp.abs(recursive[2:])))
