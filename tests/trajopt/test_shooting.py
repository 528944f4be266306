"""`Shooting`'s optimizer strategy (issue 60): `optax.lbfgs()` and `cosine_adam` take the same
steps as the string options they replace (`Shooting("lbfgs")`, `Shooting("adam",
learning_rate=...)`), whose costs on the linear-quadratic slider are recorded below, and a string
is refused by name. The LQR optimum itself: `tests/trajopt/test_ilqr.py` (slow)."""

import numpy as np
import optax
import pytest

from mbjax.trajopt import Shooting, cosine_adam, solve
from tests.trajopt.test_ilqr import _slider_problem

# the cost after each of 12 iterations from zero controls, by the string options' code path
# before they were replaced
LBFGS_COSTS = [102.0, 68.76056302223066, 6.224020345559601, 4.869948017729197, 0.8816956422985224,
               0.8754851553187181, 0.8682113108833891, 0.8577806987430232, 0.8297824111412225,
               0.7894790166427239, 0.7518423383254006, 0.7384725287931286, 0.7368561824692684]
# Shooting("adam", iterations=12, learning_rate=0.5)
ADAM_COSTS = [102.0, 28.97302610699343, 10.015181779364434, 22.89204787087378, 35.4508611827619,
              35.85535491527649, 28.925996473234488, 20.862853355572845, 14.652170472330969,
              10.762935760757305, 8.608665283763457, 7.475041543394824, 6.84943218151566]


def test_lbfgs_and_cosine_adam_take_the_steps_of_the_old_string_options():
    lbfgs = solve(_slider_problem(), Shooting(iterations=12))      # optax.lbfgs(), the default
    np.testing.assert_allclose(lbfgs.costs, LBFGS_COSTS, rtol=1e-9)
    assert int(lbfgs.iterations) == 12 and lbfgs.messages()[0].startswith("not converged")
    adam = solve(_slider_problem(), Shooting(cosine_adam(0.5, 12), iterations=12))
    np.testing.assert_allclose(adam.costs, ADAM_COSTS, rtol=1e-9)
    np.testing.assert_allclose(adam.us[[0, 1, -1], 0],
                               [1.17852035433177, 1.1729965492605656, -1.7694039098967616],
                               rtol=1e-9)


def test_a_string_or_an_uncalled_optimizer_is_refused_by_name():
    for old in ("lbfgs", "adam"):
        with pytest.raises(TypeError, match=r"optimizer must be an optax optimizer such as "
                                            r"optax.lbfgs\(\)"):
            Shooting(old)
    with pytest.raises(TypeError, match=r"call it: optax.lbfgs\(\), not optax.lbfgs"):
        Shooting(optimizer=optax.lbfgs)
    with pytest.raises(TypeError, match="learning_rate"):
        Shooting(learning_rate=0.1)                  # Adam's rate is the optimizer's now
