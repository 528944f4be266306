"""`mbjax.gaits`: Crocoddyl's gait builders written on mbjax's knots. The problems are
Crocoddyl's own (the quasi-static guess equals its `quasiStatic`; `tests/trajopt/test_gaits.py`
checks every step, impulse and cost of the walk, the jump and Talos's step against Crocoddyl and
their optima against FDDP's, through `mbjax_harness.crocoddyl.gaits`, which builds its mbjax side
with these builders); here the schedules, the weights' layout and the errors."""

import jax.numpy as jnp
import numpy as np
import pytest

from mbjax.gaits import BIPED, QUADRUPED, Gait, Weights, jump, trot, walk
from mbjax.model import chain, state_from_pinocchio
from mbjax.rigid import frame_pose
from mbjax.trajopt import knot_wrenches, quasi_static
from mbjax_harness.crocoddyl.terms import crocoddyl_working

FEET = ("LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT")


@pytest.fixture(scope="module")
def anymal():
    example_robot_data = pytest.importorskip("example_robot_data")
    import mbjax

    robot = example_robot_data.load("anymal")
    model = mbjax.load_urdf(robot.urdf, floating_base=True)
    q_pin = robot.model.referenceConfigurations["standing"]
    q0, _ = state_from_pinocchio(model, q_pin, np.zeros(robot.model.nv))
    return robot, model, q_pin, q0


def _down(problem, us):
    """Which feet carry the robot at each knot, at the standing state under `us`."""
    held = knot_wrenches(problem, jnp.broadcast_to(problem.x0, (problem.horizon, problem.nx)), us)
    return np.asarray(held)[:, :, 5] > 0


def test_weights_are_crocoddyls_layout_in_mbjaxs_tangent_order():
    """Crocoddyl's state (base linear, base angular, joints; the velocity alike) reordered to
    mbjax's (a free joint's angular part first)."""
    w = Weights(base=(1, 2, 3, 4, 5, 6), joints=(7, 8), base_velocity=(9, 10, 11, 12, 13, 14),
                joint_velocity=15).tangent(8)
    np.testing.assert_array_equal(w, [4, 5, 6, 1, 2, 3, 7, 8, 12, 13, 14, 9, 10, 11, 15, 15])
    # the builders' defaults: SimpleQuadrupedalGaitProblem's and SimpleBipedGaitProblem's
    np.testing.assert_array_equal(QUADRUPED[0].tangent(8), [500] * 3 + [0] * 3 + [0.01] * 2
                                  + [10] * 6 + [1] * 2)
    np.testing.assert_array_equal(BIPED[1].tangent(7), [1] * 6 + [0.1] + [10] * 7)


def test_the_trot_is_crocoddyls_schedule_and_guess(anymal):
    """The trot's knots: 2 of double support, RF-LH half a step (n knots and an impulse), 2 of
    double support, LF-RH a full step; two compiled phases; the feet that carry the robot under
    the quasi-static guess are those the schedule puts down, their forces summing to m g, and the
    guess is Crocoddyl's `quasiStatic` of its own trot."""
    robot, model, q_pin, q0 = anymal
    gait = Gait(model, q0, FEET)
    problem = trot(gait, step_knots=3, support_knots=2)
    assert problem.horizon == 2 + 4 + 2 + 4 and problem.n_phases == 2
    us0 = quasi_static(problem)
    down = _down(problem, us0)
    all_four, diagonal, other = [True] * 4, [True, False, False, True], [False, True, True, False]
    expected = [all_four] * 2 + [diagonal] * 3 + [[False] * 4] + [all_four] * 2 + [other] * 3 \
        + [[False] * 4]
    assert down.tolist() == expected
    if crocoddyl_working() is None:
        from crocoddyl.utils.quadruped import SimpleQuadrupedalGaitProblem

        x0 = np.concatenate([q_pin, np.zeros(robot.model.nv)])
        croc = SimpleQuadrupedalGaitProblem(robot.model, *FEET).createTrottingProblem(
            x0, 0.25, 0.15, 1e-2, 3, 2)
        guess = croc.quasiStatic([croc.x0] * croc.T)
        for mine, theirs, m in zip(np.asarray(us0), guess, croc.runningModels, strict=True):
            np.testing.assert_allclose(mine[:m.nu], theirs, atol=1e-9)


def test_steps_move_the_swinging_feet_and_the_centre_of_mass(anymal):
    _, model, _, q0 = anymal
    gait = Gait(model, q0, FEET)
    knots, com, feet = gait.steps(gait.com, gait.positions, ["RF_FOOT"], 0.2, 0.1, 4)
    assert len(knots) == 5 and type(knots[-1]).__name__ == "Impulse"
    np.testing.assert_allclose(feet["RF_FOOT"] - gait.positions["RF_FOOT"], [0.2, 0, 0])
    np.testing.assert_array_equal(feet["LF_FOOT"], gait.positions["LF_FOOT"])
    np.testing.assert_allclose(com - gait.com, [0.05, 0, 0])          # a quarter of the feet
    np.testing.assert_allclose(gait.positions["RF_FOOT"], frame_pose(model, q0, "RF_FOOT")[1])


def test_the_walk_and_the_jump_have_their_schedules(anymal):
    _, model, _, q0 = anymal
    gait = Gait(model, q0, FEET)
    walking = walk(gait, step_knots=2, support_knots=1)
    # 1 support, RH and RF half steps, 1 support, LH and LF: each step 2 knots and an impulse
    assert walking.horizon == 1 + 3 + 3 + 1 + 3 + 3 and walking.n_phases == 2
    jumping = jump(gait, ground_knots=2, flying_knots=2)
    assert jumping.horizon == 2 + 2 + 2 + 1 + 1 and jumping.n_phases == 2
    assert jumping.jumps().tolist() == [False] * 6 + [True, False]


def test_bad_gaits_are_refused_by_name(anymal):
    _, model, _, q0 = anymal
    with pytest.raises(ValueError, match="feet"):
        Gait(model, q0, "LF_FOOT")
    with pytest.raises(ValueError, match="q0"):
        Gait(model, q0[:7], FEET)
    with pytest.raises(ValueError, match="floating base"):
        Gait(chain(3), jnp.zeros(3), ("link2",))
    with pytest.raises(ValueError, match="trot is written for 4 feet"):
        trot(Gait(model, q0, FEET[:2]))
    with pytest.raises(ValueError, match="jump_length"):
        jump(Gait(model, q0, FEET), jump_length=(0.3, 0.0))
