"""A 7-link revolute chain falling under gravity: the first rigid-body tree of the tour.

`mbjax.model.chain(7)`: uniform slender links 0.3 m long and 1 kg, hanging from the ground with
joint axes alternating between y and x, so that the motion is three-dimensional. It starts at
rest from a bent configuration Q0 (the first joint 1.2 rad from hanging) and falls for DURATION
seconds, a chaotic motion that sorts integrators by accuracy quickly.
"""

import jax.numpy as jnp

from mbjax._src.model import chain

N_LINKS = 7
LINK_LENGTH = 0.3
GRAVITY = 9.81
Q0 = (1.2, 0.3, -0.2, 0.1, 0.2, -0.1, 0.3)
DURATION = 2.0


def build():
    """The scene: the 7-link chain at rest in the bent configuration Q0.

    Returns:
        model: the chain's `Model` (wrap it in `TreeSystem(model)` to simulate).
        q0: Q0 [rad], shape (7,).
        v0: zeros, shape (7,).
    """
    model = chain(N_LINKS, length=LINK_LENGTH, gravity=(0.0, 0.0, -GRAVITY))
    return model, jnp.asarray(Q0), jnp.zeros(N_LINKS)
