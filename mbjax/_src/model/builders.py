"""Ready-made models: serial chains and seeded random trees.

Random inertias are those of solid boxes with random side lengths and orientation, so they satisfy
the triangle inequality; every random draw comes from a `numpy.random.default_rng(seed)`.
"""

import numpy as np

from mbjax._src.model.model import Model


def _random_rotation(rng) -> np.ndarray:
    q = rng.normal(size=4)
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _box_inertia(rng, mass: float) -> np.ndarray:
    a, b, c = rng.uniform(0.05, 0.4, size=3)
    moments = mass / 12 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    R = _random_rotation(rng)
    return R @ np.diag(moments) @ R.T


def chain(n: int, *, joint_types="revolute", length: float = 0.3, mass: float = 1.0,
          seed: int | None = None, gravity=(0.0, 0.0, -9.81)) -> Model:
    """A serial chain of n links hanging from the ground, each `length` long along its z axis.

    seed=None gives a regular chain: uniform slender links (centre of mass mid-link), axes
    alternating between y and x. With a seed, axes, link offsets, masses, centres of mass and
    inertias are random (a generic chain for cross-checks against other engines): inertias of
    solid boxes with random sides and orientation, drawn from `numpy.random.default_rng(seed)`.

    Args:
        n: the number of links, at least 1.
        joint_types (str | Sequence[str]): the joints' type, one string for all (default "revolute")
            or n of them.
        length: link length [m] (with a seed, the scale of the random offsets).
        mass: each link's mass [kg] (regular chain only; random in [0.5, 2] with a seed).
        seed: None for the regular chain, or the random generator's seed.
        gravity (Array): the acceleration of gravity, shape (3,) [m/s^2].

    Returns:
        The `Model` of the chain, body k hanging from body k - 1.

    Raises:
        ValueError: n < 1, or an unknown joint type.
    """
    if n < 1:
        raise ValueError(f"a chain needs at least one link, got n = {n}")
    parents = np.arange(n) - 1
    if seed is None:
        axes = np.array([[0.0, 1.0, 0.0] if k % 2 == 0 else [1.0, 0.0, 0.0] for k in range(n)])
        offsets = np.array([[0.0, 0.0, 0.0]] + [[0.0, 0.0, -length]] * (n - 1))
        inertia = np.tile(np.diag([mass * length**2 / 12, mass * length**2 / 12,
                                   mass * length**2 / 120]), (n, 1, 1))
        return Model(parents, joint_types, mass=np.full(n, mass), inertia=inertia,
                     com=np.tile([0.0, 0.0, -length / 2], (n, 1)), axis=axes,
                     placement_translation=offsets, gravity=gravity)
    return _random_model(parents, joint_types, np.random.default_rng(seed), length, gravity)


def random_tree(n: int, *, seed: int = 0, joint_types=("revolute", "prismatic"),
                max_back: int = 4, length: float = 0.3, gravity=(0.0, 0.0, -9.81)) -> Model:
    """A random tree of n bodies, for cross-checks.

    Body k's parent is drawn among the `max_back` bodies before it (so the tree branches), and
    each joint type among `joint_types`; masses, centres of mass, box inertias, axes and
    placements are random, drawn from `numpy.random.default_rng(seed)`.

    Args:
        n: the number of bodies.
        seed: the random generator's seed.
        joint_types (str | Sequence[str]): the joint types to draw from, or one string for all.
        max_back: how far back a body's parent may be.
        length: the scale of the placements and centres of mass [m].
        gravity (Array): the acceleration of gravity, shape (3,) [m/s^2].

    Returns:
        The random `Model`.

    Raises:
        ValueError: an unknown joint type.
    """
    rng = np.random.default_rng(seed)
    parents = np.array([-1] + [int(rng.integers(max(0, k - max_back), k)) for k in range(1, n)])
    kinds = ([joint_types] * n if isinstance(joint_types, str)
             else [joint_types[int(i)] for i in rng.integers(0, len(joint_types), size=n)])
    return _random_model(parents, kinds, rng, length, gravity)


def _random_model(parents, joint_types, rng, length, gravity) -> Model:
    n = len(parents)
    mass = rng.uniform(0.5, 2.0, size=n)
    return Model(
        parents, joint_types, mass=mass,
        inertia=np.stack([_box_inertia(rng, m) for m in mass]),
        com=rng.uniform(-length / 2, length / 2, size=(n, 3)),
        axis=np.stack([a / np.linalg.norm(a) for a in rng.normal(size=(n, 3))]),
        axis2=np.stack([a / np.linalg.norm(a) for a in rng.normal(size=(n, 3))]),
        placement_rotation=np.stack([_random_rotation(rng) for _ in range(n)]),
        placement_translation=rng.uniform(-length, length, size=(n, 3)),
        gravity=gravity)

