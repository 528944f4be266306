"""Bad input on the contact and model surfaces (issue 60's probe): each case a clear error that
names the argument, where it was silent (a broadcast, a quaternion of norm 2 taken as it is) or
opaque (a reshape's or a division's message). Nothing here compiles: every check runs before."""

import jax.numpy as jnp
import pytest

from mbjax.contact import PointContact, impulse, simulate_schedule, stance
from mbjax.integrate import SemiImplicitEuler
from mbjax.model import Model
from mbjax.rigid import TreeSystem
from mbjax.scenes import arm

ARM = arm.model()
# a free body held at its origin: a floating base in two lines
BODY = Model([-1], "free", mass=[2.0], inertia=[jnp.diag(jnp.array([0.1, 0.2, 0.3]))])
FOOT = [PointContact("body0")]


@pytest.mark.parametrize("call, match", [
    (lambda: ARM.integrate(ARM.neutral(), jnp.zeros(1)), r"v must have shape \(7,\) \(nv\)"),
    (lambda: ARM.difference(ARM.neutral(), jnp.zeros(1)), r"q1 must have shape \(7,\) \(nq\)"),
    (lambda: BODY.integrate(BODY.neutral(), jnp.zeros(3)), r"v must have shape \(6,\) \(nv\)"),
    (lambda: BODY.difference(jnp.zeros(3), BODY.neutral()), r"q0 must have shape \(7,\) \(nq\)"),
    (lambda: stance(TreeSystem(BODY), jnp.zeros(3), FOOT), r"q must have shape \(7,\) \(nq\)"),
    (lambda: impulse(BODY, jnp.zeros(3), jnp.zeros(6), FOOT), r"q must have shape \(7,\) \(nq\)"),
    (lambda: impulse(BODY, BODY.neutral(), jnp.zeros(3), FOOT), r"v must have shape \(6,\) \(nv\)"),
    (lambda: impulse(BODY, BODY.neutral().at[3].set(2.0), jnp.zeros(6), FOOT),
     r"q\[3:7\] \(the quaternion of joint .*\) must be a unit quaternion .* got norm 2"),
    (lambda: stance(TreeSystem(BODY), BODY.neutral().at[3].set(2.0), FOOT),
     "must be a unit quaternion"),
    (lambda: simulate_schedule(TreeSystem(BODY), SemiImplicitEuler(), BODY.neutral(),
                               jnp.zeros(6), [(FOOT, 0.01)], dt=0), "dt must be a positive step"),
])
def test_wrong_shapes_and_values_are_named(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_a_phase_that_is_not_a_pair_and_a_string_flag_are_named():
    with pytest.raises(TypeError, match=r"schedule\[0\] must be a pair \(contacts, duration\)"):
        simulate_schedule(TreeSystem(BODY), SemiImplicitEuler(), BODY.neutral(), jnp.zeros(6),
                          [FOOT], dt=0.01)
    with pytest.raises(TypeError, match="active must be True or False, got the string 'yes'"):
        PointContact("body0", active="yes")


def test_a_batch_is_refused_with_the_vmap_hint_not_broadcast():
    with pytest.raises(ValueError, match="use jax.vmap for batches"):
        ARM.integrate(jnp.zeros((2, 7)), jnp.zeros((2, 7)))


def test_a_contact_that_knows_its_ground_is_not_held_in_the_air():
    """The probe's foot 0.5 m above the ground, held there carrying the weight: with the ground's
    height the stance and the impulse refuse it, naming the contact and the gap; on the ground
    the stance is the one without a height."""
    up = BODY.neutral().at[2].set(0.5)
    grounded = [PointContact("body0", height=0.0)]
    with pytest.raises(ValueError, match=r"contacts\[0\] \('body0'\) is 0.5 m above its ground"):
        stance(TreeSystem(BODY), up, grounded)
    with pytest.raises(ValueError, match="is 0.5 m above its ground"):
        impulse(BODY, up, jnp.zeros(6), grounded)
    tilted = [PointContact("body0", normal=(0.0, 1.0, 1.0), height=-0.1)]
    with pytest.raises(ValueError, match=r"is 0.1 m above"):
        stance(TreeSystem(BODY), BODY.neutral(), tilted)
    assert float(PointContact("body0", height=0.2).clearance(BODY, up)) == pytest.approx(0.3)
    held = stance(TreeSystem(BODY), BODY.neutral(), grounded)
    free = stance(TreeSystem(BODY), BODY.neutral(), FOOT)
    assert jnp.allclose(held.closures[0].origin_b, free.closures[0].origin_b)
    stance(TreeSystem(BODY), up, [PointContact("body0", active=False, height=0.0)])  # in the air
    with pytest.raises(ValueError, match="height must be a scalar"):
        PointContact("body0", height=[0.0, 1.0])
