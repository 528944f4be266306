"""A status says what tripped it (issue 43): the joint whose limit, the time, the copy; and bad
rotations and mismatched data are refused where they enter."""

import equinox as eqx
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax import Status, simulate
from mbjax.flex import Beam, beam_body, craig_bampton
from mbjax.integrate import RK4
from mbjax.model import chain
from mbjax.rigid import TreeSystem
from mbjax.trajopt import Problem

LIMIT = 0.5


def test_a_limit_is_named_by_its_joint_and_the_time_it_was_first_exceeded():
    """The middle joint of a hanging chain, started at 0.3 rad and 3 rad/s with limits of
    +-0.5 rad, passes its upper limit first: the words name it and the first saved state
    beyond it, found here from the saved states themselves."""
    model = eqx.tree_at(lambda m: (m.lower, m.upper), chain(3),
                        (jnp.full(3, -LIMIT), jnp.full(3, LIMIT)))
    sol = simulate(TreeSystem(model), RK4(), jnp.array([0.0, 0.3, 0.0]),
                   jnp.array([0.0, 3.0, 0.0]), dt=0.01, t1=1.0)
    beyond = np.abs(np.asarray(sol.qs)) > LIMIT
    step, joint = np.argwhere(beyond)[0]
    assert Status(int(sol.status)) == Status.LIMIT_EXCEEDED and bool(sol.ok)
    assert sol.messages() == [f"limit exceeded (joint '{model.joint_names[joint]}' position; "
                              f"first at t = {float(sol.ts[step]):.4g} s)"]


def test_a_quaternion_start_that_is_not_a_unit_quaternion_is_refused():
    system = TreeSystem(chain(2, joint_types="spherical"))
    q0 = jnp.array([1.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0])     # the second of norm 2
    with pytest.raises(ValueError, match=r"q0\[4:8\] \(the quaternion of joint 'joint1'\) must be a "
                                         r"unit quaternion .* got norm 2"):
        simulate(system, RK4(), q0, jnp.zeros(6), dt=0.01, t1=0.1)
    sol = simulate(system, RK4(), q0.at[4].set(1.0), jnp.zeros(6), dt=0.01, t1=0.1)
    assert sol.messages() == ["success"]
    with pytest.raises(ValueError, match=r"q0\[4:8\] \(the quaternion of joint 'joint1'\)"):
        Problem(system, q0, jnp.zeros(6), dt=0.01, horizon=3,
                running=lambda q, v, u: jnp.sum(u**2), terminal=lambda q, v: jnp.sum(v**2))


def test_a_basis_built_for_another_beam_is_refused():
    beam = Beam(1.0, 7e10, 2.6e10, 2700.0, 1e-4, 1e-9, 1e-9, 2e-9, n_elements=4)
    other = Beam(1.0, 7e10, 2.6e10, 2700.0, 1e-4, 1e-9, 1e-9, 2e-9, n_elements=6)
    basis = craig_bampton(other, n_modes=2)
    with pytest.raises(ValueError, match="basis has shapes for 7 nodes .* but beam has 5"):
        beam_body(beam, basis)
    with pytest.raises(ValueError, match=r"damping must be the modal damping matrix of shape "
                                         r"\(2, 2\)"):
        beam_body(beam, craig_bampton(beam, n_modes=2), damping=jnp.ones(2))
