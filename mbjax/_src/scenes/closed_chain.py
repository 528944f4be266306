"""The (n/2)-body chain with both ends fixed (Anderson 1993 §3.3, Fig. 7A).

n/2 slender links, 0.3 m and 1 kg each, hang between two ground points at the same height, a
horizontal SPAN fraction of the chain's length apart; every joint is a two-dof Hooke (universal)
joint with axes x then y. The tree is the chain hanging from the first point (n dof, Fig. 7B);
the joint at the second point is cut: a universal cut joint, 4 equations. Gravity along -z.
The initial state is the V-shaped chain projected onto the constraints, at rest, plus a small
velocity projected onto them too.
"""

import jax.numpy as jnp
import numpy as np

from mbjax._src.loops import GROUND, ClosedSystem, CutJoint, consistent_state, project_velocity
from mbjax._src.model.closures import Universal
from mbjax._src.model import Model
from mbjax._src.rigid import TreeSystem

LINK = 0.3
MASS = 1.0
SPAN = 0.6
DURATION = 1.0


def build(n: int):
    """The scene: the chain of n/2 Hooke-jointed links with both ends fixed (Anderson 1993 Fig. 7A).

    The system is a `ClosedSystem` with the coupled multipliers (rebuild it from `system.tree`
    and `system.closures` for another method); the start is on the constraints.

    Args:
        n: the tree's degrees of freedom (n/2 bodies), even and at least 4.

    Returns:
        system: the `ClosedSystem`.
        q0: the V-shaped chain projected onto the constraints [rad], shape (n,).
        v0: a small velocity projected onto them [rad/s], shape (n,).

    Raises:
        ValueError: n is odd or below 4.
    """
    if n < 4 or n % 2:
        raise ValueError(f"n must be an even number >= 4 (two dof per Hooke joint), got {n}")
    bodies = n // 2
    inertia = np.diag([MASS * LINK**2 / 12, MASS * LINK**2 / 12, MASS * LINK**2 / 120])
    model = Model(np.arange(bodies) - 1, "universal", mass=np.full(bodies, MASS),
                  inertia=np.tile(inertia, (bodies, 1, 1)), com=(0.0, 0.0, -LINK / 2),
                  axis=(1.0, 0.0, 0.0), axis2=(0.0, 1.0, 0.0),
                  placement_translation=np.array([[0.0, 0.0, 0.0]]
                                                 + [[0.0, 0.0, -LINK]] * (bodies - 1)))
    end = (SPAN * bodies * LINK, 0.0, 0.0)
    system = ClosedSystem(TreeSystem(model), [CutJoint(Universal(), bodies - 1, GROUND,
                                                       origin_a=(0.0, 0.0, -LINK), origin_b=end)])
    alpha = float(np.arcsin(SPAN))
    guess = np.zeros((bodies, 2))
    guess[0, 1] = -alpha                               # down toward the far point ...
    guess[bodies // 2, 1] = 2 * alpha - np.pi          # ... then up to it: a V
    q0, _ = consistent_state(system, guess.ravel(), np.zeros(n))
    v0 = project_velocity(system.loops, q0, 0.1 * jnp.sin(jnp.arange(n, dtype=float)))
    return system, q0, v0
