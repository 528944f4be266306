"""`mbjax.trajopt.optimal_cost`: the envelope theorem's gradient of the arm's optimal reach cost
with respect to a link mass, against central differences of re-solved problems."""

import equinox as eqx
import jax
import jax.numpy as jnp

from mbjax.scenes import arm as scene
from mbjax.trajopt import ILQR, optimal_cost, solve

SOLVER = ILQR(iterations=400, tolerance=1e-12)       # solved tightly: differences of optima


def _build(mass):
    arm = scene.model()
    return scene.reach_problem(steps=40, arm=eqx.tree_at(lambda m: m.mass, arm,
                                                          arm.mass.at[3].set(mass)))


def test_optimal_cost_gradient_matches_differences_of_re_solved_problems():
    mass = jnp.asarray(float(scene.model().mass[3]))
    assert solve(_build(mass), SOLVER).messages() == ["success"]
    cost, grad = jax.jit(jax.value_and_grad(lambda m: optimal_cost(_build, m, SOLVER)))(mass)
    assert float(cost) == float(solve(_build(mass), SOLVER).cost)
    h = 1e-3 * float(mass)
    central = (float(optimal_cost(_build, mass + h, SOLVER))
               - float(optimal_cost(_build, mass - h, SOLVER))) / (2 * h)
    assert abs(float(grad)) > 1e-4                     # the design matters
    assert abs(float(grad) - central) < 1e-3 * abs(central)


def test_an_unconverged_optimum_raises_by_default_and_is_returned_with_throw_false():
    """The envelope theorem holds at the optimum only: a solve stopped after 2 iterations
    (status not converged) raises, naming it, under `jax.grad` too; throw=False returns the
    cost it reached, the solve's own."""
    import pytest

    mass = jnp.asarray(float(scene.model().mass[3]))
    early = ILQR(iterations=2)
    assert solve(_build(mass), early).messages() != ["success"]
    with pytest.raises(eqx.EquinoxRuntimeError, match="not converged"):
        jax.grad(lambda m: optimal_cost(_build, m, early))(mass)
    cost = optimal_cost(_build, mass, early, throw=False)
    assert float(cost) == float(solve(_build(mass), early).cost)
