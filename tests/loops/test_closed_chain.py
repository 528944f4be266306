"""The (n/2)-body chain with both ends fixed (seed 002 §3.3): projection onto the constraints,
and seed 002's O(n + m^3) route against seed 001's coupled multipliers."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax.integrate import RK4, simulate
from mbjax.loops import LoopSystem, StabilizedLoopSystem
from mbjax.loops.coupled import numerical_rank
from mbjax.loops.projection import project_configuration, project_velocity
from mbjax.scenes import closed_chain


def test_projection_lands_on_the_constraints():
    loops, q0, v0 = closed_chain.build(8)
    assert float(jnp.abs(loops.phi(q0)).max()) < 1e-12
    assert float(jnp.abs(loops.rate(q0, v0)).max()) < 1e-11
    assert int(numerical_rank(loops.jacobian(q0) @ loops.jacobian(q0).T)) == loops.m == 4
    q, norm, iterations = project_configuration(loops, q0 + 0.05 * jnp.cos(jnp.arange(8.0)))
    assert float(norm) < 1e-12 and int(iterations) < 20
    v = project_velocity(loops, q, jnp.ones(8))
    np.testing.assert_allclose(loops.rate(q, v), 0.0, atol=1e-11)


def test_order_n_route_agrees_with_the_coupled_one_on_the_closed_chain():
    """Seed 002 reports its O(n) and O(n^3) codes "effectively identical"; here to round-off."""
    loops, q0, v0 = closed_chain.build(12)
    ts = np.linspace(0.0, 0.2, 5)
    dense = simulate(LoopSystem(loops), RK4(), q0, v0, dt=1e-3, t1=0.2, saveat=ts)
    recursive = simulate(StabilizedLoopSystem(loops), RK4(), q0, v0, dt=1e-3, t1=0.2, saveat=ts)
    assert dense.messages() == recursive.messages() == ["success"]
    np.testing.assert_allclose(recursive.qs, dense.qs, atol=1e-12)
    assert float(jnp.abs(jax.jit(lambda q: loops.phi(q))(dense.qs[-1])).max()) < 1e-8
    # the free chain (gravity only, ideal joints and closure) conserves its energy
    system = LoopSystem(loops)
    energies = np.asarray(jax.jit(jax.vmap(system.energy))(dense.qs, dense.us))
    np.testing.assert_allclose(energies, energies[0], rtol=0, atol=1e-9 * abs(energies[0]))


def test_bad_chain_size():
    with pytest.raises(ValueError, match="even number"):
        closed_chain.build(5)
