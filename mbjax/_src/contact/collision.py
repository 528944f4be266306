"""Contact detection between geoms, as pure functions of their world poses.

Each primitive pair gives a fixed number of candidate contacts (a contact that does not touch
is data: its distance is positive), each a signed distance (negative in penetration), a point
midway between the surfaces and the normal from the first geom towards the second, as
MuJoCo's narrow phase defines them (MuJoCo's `mjc_PlaneSphere`, `mjc_PlaneCapsule`,
`mjc_PlaneBox`, `mjc_SphereSphere`, `mjc_SphereCapsule`, `mjc_CapsuleCapsule`). The contact
frame's tangents follow `frame_from_normal` (MuJoCo's `mju_makeFrame`) or, for a capsule on a
plane, the capsule's axis.
"""

import jax.numpy as jnp
import numpy as np
from jax import Array

# the candidate contacts each detected pair gives
COUNT = {("plane", "sphere"): 1, ("plane", "capsule"): 2, ("plane", "box"): 8,
         ("sphere", "sphere"): 1, ("sphere", "capsule"): 1, ("capsule", "capsule"): 1}


def _normalize(x: Array) -> tuple[Array, Array]:
    """(x / |x|, |x|), with a zero vector left zero (its derivative finite)."""
    norm2 = jnp.sum(x * x, -1, keepdims=True)
    safe = jnp.where(norm2 > 0, norm2, 1.0)
    norm = jnp.where(norm2 > 0, jnp.sqrt(safe), 0.0)
    return x / jnp.sqrt(safe), norm[..., 0]


def _default_tangent(n: Array) -> Array:
    """y, or z where n is within 60 degrees of y (MuJoCo's `mju_makeFrame`)."""
    return jnp.where(jnp.abs(n[1]) < 0.5, jnp.array([0.0, 1.0, 0.0]), jnp.array([0.0, 0.0, 1.0]))


def frame_from_normal(n: Array, tangent: Array | None = None) -> Array:
    """The contact frame (3, 3), rows (normal, tangent, normal x tangent): the tangent is
    `tangent` made orthogonal to n, or `_default_tangent`'s."""
    if tangent is None:
        tangent = _default_tangent(n)
    t, _ = _normalize(tangent - n * jnp.dot(n, tangent))
    return jnp.stack([n, t, jnp.cross(n, t)])


def _plane_point(n, origin, centre, radius):
    dist = jnp.dot(centre - origin, n) - radius
    return dist, centre - n * (radius + 0.5 * dist)


def plane_sphere(plane, sphere):
    (R1, p1, _), (_, p2, s2) = plane, sphere
    n = R1[:, 2]
    dist, pos = _plane_point(n, p1, p2, s2[0])
    return dist[None], pos[None], frame_from_normal(n)[None]


def plane_capsule(plane, capsule):
    (R1, p1, _), (R2, p2, s2) = plane, capsule
    n, axis = R1[:, 2], R2[:, 2]
    along = axis - n * jnp.dot(n, axis)            # the capsule's axis in the plane
    tangent = jnp.where(jnp.dot(along, along) < 1e-20, _default_tangent(n), along)
    frame = frame_from_normal(n, tangent)
    ends = p2 + jnp.stack([axis, -axis]) * s2[1]
    dist, pos = (jnp.stack(x) for x in zip(*(_plane_point(n, p1, e, s2[0]) for e in ends)))
    return dist, pos, jnp.stack([frame, frame])


_CORNERS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)


def plane_box(plane, box):
    (R1, p1, _), (R2, p2, s2) = plane, box
    n = R1[:, 2]
    corners = p2 + (_CORNERS * s2) @ R2.T                  # (8, 3)
    dist = (corners - p1) @ n
    pos = corners - 0.5 * dist[:, None] * n
    return dist, pos, jnp.broadcast_to(frame_from_normal(n), (8, 3, 3))


def _spheres(c1, r1, c2, r2):
    n, d = _normalize(c2 - c1)
    n = jnp.where(d > 0, n, jnp.array([1.0, 0.0, 0.0]))
    dist = d - (r1 + r2)
    return dist[None], (c1 + n * (r1 + 0.5 * dist))[None], frame_from_normal(n)[None]


def sphere_sphere(a, b):
    (_, p1, s1), (_, p2, s2) = a, b
    return _spheres(p1, s1[0], p2, s2[0])


def _closest_on_segment(a: Array, b: Array, x: Array) -> Array:
    ab = b - a
    t = jnp.dot(x - a, ab) / jnp.maximum(jnp.dot(ab, ab), 1e-30)
    return a + jnp.clip(t, 0.0, 1.0) * ab


def sphere_capsule(sphere, capsule):
    (_, p1, s1), (R2, p2, s2) = sphere, capsule
    half = R2[:, 2] * s2[1]
    return _spheres(p1, s1[0], _closest_on_segment(p2 - half, p2 + half, p1), s2[0])


def capsule_capsule(a, b):
    (R1, p1, s1), (R2, p2, s2) = a, b
    d1, d2 = R1[:, 2] * s1[1], R2[:, 2] * s2[1]
    # the closest points of the two segments p1 + s d1, p2 + t d2 (s, t in [-1, 1])
    r = p1 - p2
    a11, a22, a12 = jnp.dot(d1, d1), jnp.dot(d2, d2), jnp.dot(d1, d2)
    b1, b2 = jnp.dot(d1, r), jnp.dot(d2, r)
    det = a11 * a22 - a12 * a12
    s = jnp.where(det > 1e-12 * a11 * a22, (a12 * b2 - a22 * b1) / jnp.where(det > 0, det, 1.0),
                  0.0)
    s = jnp.clip(s, -1.0, 1.0)
    t = jnp.clip((a12 * s + b2) / jnp.maximum(a22, 1e-30), -1.0, 1.0)
    s = jnp.clip((a12 * t - b1) / jnp.maximum(a11, 1e-30), -1.0, 1.0)
    return _spheres(p1 + s * d1, s1[0], p2 + t * d2, s2[0])


PAIRS = {("plane", "sphere"): plane_sphere, ("plane", "capsule"): plane_capsule,
         ("plane", "box"): plane_box, ("sphere", "sphere"): sphere_sphere,
         ("sphere", "capsule"): sphere_capsule, ("capsule", "capsule"): capsule_capsule}
