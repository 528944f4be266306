"""The gradient strategies of the Carpal Wrist's descents (issue 60): `ForwardMode()` and
`ReverseMode()` give the steps the strings "forward" and "reverse" gave (recorded below) and the
same gradient as each other; a string is refused by name, by `train_controller` too."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax._src.synthesis.descent import adam_descent
from mbjax.wrist import ForwardMode, NeuralController, ReverseMode, train_controller

# adam_descent(loss, X0, learning_rate=0.1, iterations=10, final_fraction=0.05,
# gradient="forward") before the strings were replaced ("reverse" agreed to 1e-16)
X_FINAL = [0.340201723642743, 0.25102167287518395, 0.02942837138479404]
LOSSES = [0.5137, 0.39270000133517075, 0.31391658237164055, 0.26351946983751134,
          0.2386131283425229, 0.2302628284690572, 0.2270247687079678, 0.22319282105168156,
          0.21887151881832137, 0.2154393917743918]
X0 = jnp.array([0.3, -0.2, 0.5])


def loss(x):
    return jnp.sum((x[1:] - x[:-1] ** 2) ** 2) + 0.1 * jnp.sum((1 - x) ** 2)


def test_forward_and_reverse_mode_descend_as_the_strings_did():
    x = jnp.array([0.7, -1.3, 0.4])
    value, forward = ForwardMode().value_and_grad(loss, x)
    np.testing.assert_allclose(ReverseMode().value_and_grad(loss, x)[1], forward, rtol=1e-14)
    assert float(value) == pytest.approx(float(loss(x)), rel=1e-15)
    for gradient in (ForwardMode(), ReverseMode()):
        x, losses = jax.jit(lambda x0, g=gradient: adam_descent(
            loss, x0, learning_rate=0.1, iterations=10, final_fraction=0.05, gradient=g))(X0)
        np.testing.assert_allclose(x, X_FINAL, rtol=1e-12)
        np.testing.assert_allclose(losses, LOSSES, rtol=1e-12)


def test_a_string_is_refused_by_name():
    for old in ("forward", "reverse"):
        with pytest.raises(TypeError, match=r"gradient must be a gradient strategy, ForwardMode\(\) "
                                            r"or ReverseMode\(\)"):
            adam_descent(loss, X0, learning_rate=0.1, iterations=2, final_fraction=0.05,
                         gradient=old)
    with pytest.raises(TypeError, match=r"an instance: ReverseMode\(\), not ReverseMode"):
        adam_descent(loss, X0, learning_rate=0.1, iterations=2, final_fraction=0.05,
                     gradient=ReverseMode)
    # train_controller refuses it before it rolls anything out (no wrist or episodes needed)
    controller = NeuralController(jax.random.PRNGKey(0), 1.8, jnp.zeros(3))
    with pytest.raises(TypeError, match="gradient must be a gradient strategy"):
        train_controller(controller, None, None, gradient="forward")
