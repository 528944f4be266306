"""The (n/2)-body chain with both ends fixed (Anderson 1993 §3.3): projection onto the constraints,
and Anderson 1993's O(n + m^3) route against Jerkovsky 1978's coupled multipliers."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax.integrate import RK4, simulate
from mbjax.loops import ClosedSystem, Stabilized, project_configuration, project_velocity
from mbjax._src.loops import numerical_rank
from mbjax.scenes import closed_chain


def test_projection_lands_on_the_constraints():
    """The scene's start is on Phi = 0 and A v + B = 0; a drift of 5e-3 rad in every joint is
    projected back along the constraint normals to round-off."""
    system, q0, v0 = closed_chain.build(8)
    loops = system.loops
    assert float(jnp.abs(loops.phi(q0)).max()) < 1e-12
    assert float(jnp.abs(loops.rate(q0, v0)).max()) < 1e-11
    assert int(numerical_rank(loops.jacobian(q0) @ loops.jacobian(q0).T)) == loops.m == 4

    @jax.jit
    def project(q, v):
        q, norm = project_configuration(loops, q)
        return q, norm, project_velocity(loops, q, v)

    q, norm, v = project(q0 + 5e-3 * jnp.cos(jnp.arange(8.0)), jnp.ones(8))
    assert float(norm) < 1e-12
    np.testing.assert_allclose(loops.rate(q, v), 0.0, atol=1e-11)


def test_order_n_route_agrees_with_the_coupled_one_on_the_closed_chain():
    """Anderson 1993 reports its O(n) and O(n^3) codes "effectively identical"; here to round-off."""
    dense_system, q0, v0 = closed_chain.build(12)
    loops = dense_system.loops
    ts = np.linspace(0.0, 0.2, 5)
    dense = simulate(dense_system, RK4(), q0, v0, dt=1e-3, t1=0.2, saveat=ts)
    stabilized = ClosedSystem(dense_system.tree, dense_system.closures, Stabilized())
    recursive = simulate(stabilized, RK4(), q0, v0, dt=1e-3, t1=0.2, saveat=ts)
    assert dense.messages() == recursive.messages() == ["success"]
    np.testing.assert_allclose(recursive.qs, dense.qs, atol=1e-12)
    assert float(jnp.abs(jax.jit(lambda q: loops.phi(q))(dense.qs[-1])).max()) < 1e-8
    # the free chain (gravity only, ideal joints and closure) conserves its energy
    energies = np.asarray(jax.jit(jax.vmap(dense_system.energy))(dense.qs, dense.vs))
    np.testing.assert_allclose(energies, energies[0], rtol=0, atol=1e-9 * abs(energies[0]))


def test_bad_chain_size():
    with pytest.raises(ValueError, match="even number"):
        closed_chain.build(5)
