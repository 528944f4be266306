"""Contact detection between geoms, as pure functions of their world poses.

Each primitive pair gives a fixed number of candidate contacts (a contact that does not touch
is data: its distance is positive), each a signed distance (negative in penetration), a point
midway between the surfaces and the normal from the first geom towards the second, as
MuJoCo's narrow phase defines them (MuJoCo's `mjc_PlaneSphere`, `mjc_PlaneCapsule`,
`mjc_PlaneCylinder`, `mjc_PlaneBox`, `mjc_SphereSphere`, `mjc_SphereCapsule`,
`mjc_CapsuleCapsule`; an ellipsoid on a plane at its support point, as MuJoCo's convex
collider finds it). The contact frame's tangents follow `frame_from_normal` (MuJoCo's
`mju_makeFrame`) or, for a capsule on a plane, the capsule's axis.

Boxes against spheres, capsules and boxes are exact signed distances with contact sets
written here: a sphere at the box point nearest its centre (the face of least penetration
inside); a capsule at its segment's point nearest the box (a convex function of the
segment's parameter, minimised by golden-section search) and, over a face, at the ends of the
segment clipped to the face; a box
pair along the separating-axis test's axis of least penetration (15 axes), with the contact
polygon of the two faces (the incident face's corners over the reference face, the reference
face's corners under the incident face, and their edges' crossings) or, on an edge-edge axis,
the edges' closest points. MuJoCo's own box colliders give the same distances and normals, and
at most 2 (capsule) or 8 (box) points of the same contact polygon.
"""

import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.model.geoms import DETECTED

# the candidate contacts each detected pair gives
COUNT = {("plane", "sphere"): 1, ("plane", "capsule"): 2, ("plane", "ellipsoid"): 1,
         ("plane", "cylinder"): 4, ("plane", "box"): 8, ("sphere", "sphere"): 1,
         ("sphere", "capsule"): 1, ("sphere", "box"): 1, ("capsule", "capsule"): 1,
         ("capsule", "box"): 3, ("box", "box"): 24}
# the distance given to a candidate that is not a contact of its pair (a corner off the contact
# polygon), so that it never pushes [m]
AWAY = 1.0
# the golden-section search's iterations along a capsule's segment (0.618^40: 4e-9 of its length)
SEARCH_ITERATIONS = 40


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
    c1, c2 = _closest_points(p1 - d1, p1 + d1, p2 - d2, p2 + d2)
    return _spheres(c1, s1[0], c2, s2[0])


def plane_ellipsoid(plane, ellipsoid):
    (R1, p1, _), (R2, p2, s2) = plane, ellipsoid
    n = R1[:, 2]
    # the support point towards the plane: the unit sphere's, stretched by the semi-axes
    direction, _ = _normalize(-(R2.T @ n) * s2)
    point = p2 + R2 @ (direction * s2)
    dist = jnp.dot(point - p1, n)
    return dist[None], (point - 0.5 * dist * n)[None], frame_from_normal(n)[None]


def plane_cylinder(plane, cylinder):
    """MuJoCo's four: the near disc's rim point nearest the plane, the far disc's, and two more
    on the near rim a third of a turn either side."""
    (R1, p1, _), (R2, p2, s2) = plane, cylinder
    n = R1[:, 2]
    radius, half = s2[0], s2[1]
    along = jnp.dot(n, R2[:, 2])
    axis = jnp.where(along > 0, -1.0, 1.0) * R2[:, 2]        # towards the plane
    along = -jnp.abs(along)
    dist0 = jnp.dot(p2 - p1, n)
    rim = axis * along - n
    direction, length = _normalize(rim)
    vec = jnp.where(length >= 1e-15, direction * radius, R2[:, 0] * radius)
    side, _ = _normalize(jnp.cross(vec, axis))
    side = side * radius * np.sqrt(3.0) / 2
    down, out = axis * half, jnp.dot(vec, n)
    dist = jnp.stack([dist0 + along * half + out, dist0 - along * half + out,
                      dist0 + along * half - out / 2, dist0 + along * half - out / 2])
    points = p2 + jnp.stack([vec + down, vec - down, side + down - vec / 2,
                             -side + down - vec / 2])
    pos = points - 0.5 * dist[:, None] * n
    return dist, pos, jnp.broadcast_to(frame_from_normal(n), (4, 3, 3))


def _point_box(x: Array, R: Array, p: Array, h: Array):
    """(signed distance, the box's surface point nearest x, the outward normal there) of a point
    x and a box (axes R, centre p, half extents h); inside, the face of least penetration."""
    c = R.T @ (x - p)
    inside = jnp.all(jnp.abs(c) <= h)
    outward, outside = _normalize(c - jnp.clip(c, -h, h))
    depth = h - jnp.abs(c)
    face = jax.nn.one_hot(jnp.argmin(depth), 3, dtype=x.dtype) * jnp.where(c >= 0, 1.0, -1.0)
    dist = jnp.where(inside, -jnp.min(depth), outside)
    normal = jnp.where(inside, face, outward)
    surface = jnp.where(inside, c + face * jnp.min(depth), jnp.clip(c, -h, h))
    return dist, p + R @ surface, R @ normal


def _ball_box(x: Array, radius, box):
    """A ball's contact with a box: (distance, point, normal from the ball to the box)."""
    R, p, h = box
    dist, surface, outward = _point_box(x, R, p, h)
    return dist - radius, surface + outward * 0.5 * (dist - radius), -outward


def sphere_box(sphere, box):
    (_, p1, s1) = sphere
    dist, pos, n = _ball_box(p1, s1[0], box)
    return dist[None], pos[None], frame_from_normal(n)[None]


def capsule_box(capsule, box):
    """Where the capsule's nearest point lies over a face of the box, the two ends of its
    segment clipped to that face (depths along the face's normal), and the nearest point
    itself where it is deeper than both; elsewhere (over an edge or a corner) the nearest
    point alone."""
    (R1, p1, s1), (R2, p2, s2) = capsule, box
    radius = s1[0]
    a, b = p1 - R1[:, 2] * s1[1], p1 + R1[:, 2] * s1[1]

    def depth(t):            # signed distance from the box: convex along the segment
        return _point_box(a + t * (b - a), R2, p2, s2)[0]

    ratio = (np.sqrt(5.0) - 1) / 2

    def step(_, bounds):     # golden-section search; comparisons only, so t has no derivative
        lo, hi = bounds
        t1, t2 = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
        left = depth(t1) < depth(t2)
        return jnp.where(left, lo, t1), jnp.where(left, t2, hi)

    lo, hi = jax.lax.fori_loop(0, SEARCH_ITERATIONS, step, (jnp.zeros_like(radius),
                                                            jnp.ones_like(radius)))
    t = jax.lax.stop_gradient(0.5 * (lo + hi))
    dist, pos, n = _ball_box(a + t * (b - a), radius, box)
    # the face under the nearest point, if its normal is a face's: the segment clipped to it
    local = R2.T @ -n                                        # the box's outward normal there
    k = jnp.argmax(jnp.abs(local))
    over_face = jnp.abs(local[k]) > 1 - 1e-9
    ca, cb = R2.T @ (a - p2), R2.T @ (b - p2)
    span = cb - ca
    others = jnp.arange(3) != k
    safe = jnp.where(jnp.abs(span) > 1e-15, span, 1.0)
    enter = jnp.where(jnp.abs(span) > 1e-15, jnp.minimum((-s2 - ca) / safe, (s2 - ca) / safe),
                      -jnp.inf)
    leave = jnp.where(jnp.abs(span) > 1e-15, jnp.maximum((-s2 - ca) / safe, (s2 - ca) / safe),
                      jnp.inf)
    t_lo = jax.lax.stop_gradient(jnp.maximum(0.0, jnp.max(jnp.where(others, enter, -jnp.inf))))
    t_hi = jax.lax.stop_gradient(jnp.minimum(1.0, jnp.min(jnp.where(others, leave, jnp.inf))))
    ends = jnp.stack([t_lo, t_hi])
    points = a + ends[:, None] * (b - a)
    face_point = p2 + R2[:, k] * jnp.sign(local[k]) * s2[k]
    end_dist = (points - face_point) @ -n - radius
    end_pos = points + n * (radius + 0.5 * end_dist[:, None])
    end_on = over_face & (t_lo <= t_hi)
    deeper = dist < jnp.min(end_dist) - 1e-9
    dist = jnp.concatenate([jnp.where(end_on, end_dist, AWAY),
                            jnp.where(end_on & ~deeper, AWAY, dist)[None]])
    pos = jnp.concatenate([end_pos, pos[None]])
    return dist, pos, jnp.broadcast_to(frame_from_normal(n), (3, 3, 3))


_SQUARE = np.array([[1, 1], [-1, 1], [-1, -1], [1, -1]], float)     # a face's corners, in turn


def _face(R: Array, p: Array, h: Array, normal: Array):
    """The face of a box (axes R as columns, centre p, half extents h) whose outward normal is
    nearest `normal`: (centre, its in-plane axes (2, 3) scaled by the half extents, its outward
    unit normal)."""
    k = jnp.argmax(jnp.abs(R.T @ normal))
    sign = jnp.where(jnp.dot(R[:, k], normal) >= 0, 1.0, -1.0)
    order = jnp.array([[1, 2], [2, 0], [0, 1]])[k]
    axes = (R[:, order] * h[order]).T
    return p + sign * R[:, k] * h[k], axes, sign * R[:, k]


def _face_contacts(reference, incident, m: Array):
    """The contact polygon of two faces, as 24 candidates (distance along m, point): the
    incident face's 4 corners over the reference face, the reference face's 4 corners under the
    incident face, and the 16 crossings of their edges seen along m; candidates off the
    polygon are moved `AWAY`."""
    (c_r, axes_r, _), (c_i, axes_i, f) = reference, incident
    extent = jnp.linalg.norm(axes_r, axis=-1)
    u = axes_r / extent[:, None]                                         # unit in-plane axes

    def plane(x):                                       # x's in-plane coordinates and height
        return u @ (x - c_r), jnp.dot(x - c_r, m)

    corners_i = c_i + _SQUARE @ axes_i                                   # (4, 3)
    xy, height = jax.vmap(plane)(corners_i)
    on_i = jnp.all(jnp.abs(xy) <= extent * (1 + 1e-9), axis=-1)
    corners_r = c_r + _SQUARE @ axes_r
    lift = jnp.dot(c_i - corners_r, f) / jnp.dot(m, f)          # along m to the incident face
    under = corners_r + lift[:, None] * m
    span = jnp.linalg.norm(axes_i, axis=-1)
    local = (under - c_i) @ (axes_i / span[:, None]).T
    on_r = jnp.all(jnp.abs(local) < span * (1 - 1e-9), axis=-1)
    # the edges: reference edge P0 -> P1 (in-plane), incident edge Q0 -> Q1 (seen along m)
    P0, P1 = _SQUARE * extent, np.roll(_SQUARE, -1, axis=0) * extent
    Q0, Q1 = xy, jnp.roll(xy, -1, axis=0)
    d1, d2 = (P1 - P0)[:, None], (Q1 - Q0)[None]                        # (4, 1, 2), (1, 4, 2)
    det = d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]              # (4, 4)
    safe = jnp.where(jnp.abs(det) > 1e-12, det, 1.0)
    r = Q0[None] - P0[:, None]
    alpha = (r[..., 0] * d2[..., 1] - r[..., 1] * d2[..., 0]) / safe
    beta = (r[..., 0] * d1[..., 1] - r[..., 1] * d1[..., 0]) / safe
    crossing = ((jnp.abs(det) > 1e-12) & (alpha > 1e-9) & (alpha < 1 - 1e-9) & (beta > 1e-9)
                & (beta < 1 - 1e-9))
    E0, E1 = corners_i, jnp.roll(corners_i, -1, axis=0)
    points = E0[None] + beta[..., None] * (E1 - E0)[None]                # on the incident edge
    across = jnp.einsum("abi,i->ab", points - c_r, m)
    dist = jnp.concatenate([height, lift, across.reshape(-1)])
    on = jnp.concatenate([on_i, on_r, crossing.reshape(-1)])
    point = jnp.concatenate([corners_i, under, points.reshape(-1, 3)])
    pos = point - 0.5 * dist[:, None] * m
    return jnp.where(on, dist, AWAY), pos


def _closest_points(a0, a1, b0, b1):
    """The closest points of segments a0 a1 and b0 b1."""
    da, db, r = a1 - a0, b1 - b0, a0 - b0
    aa, bb, ab = jnp.dot(da, da), jnp.dot(db, db), jnp.dot(da, db)
    ar, br = jnp.dot(da, r), jnp.dot(db, r)
    det = aa * bb - ab * ab
    s = jnp.where(det > 1e-12 * aa * bb, (ab * br - bb * ar) / jnp.where(det > 0, det, 1.0), 0.0)
    s = jnp.clip(s, 0.0, 1.0)
    t = jnp.clip((ab * s + br) / jnp.maximum(bb, 1e-30), 0.0, 1.0)
    s = jnp.clip((ab * t - ar) / jnp.maximum(aa, 1e-30), 0.0, 1.0)
    return a0 + s * da, b0 + t * db


def box_box(a, b):
    (RA, pA, hA), (RB, pB, hB) = a, b
    d = pB - pA
    crossed = jnp.cross(RA.T[:, None], RB.T[None]).reshape(9, 3)
    unit, size = jax.vmap(_normalize)(crossed)
    axes = jnp.concatenate([RA.T, RB.T, unit])                           # (15, 3)
    valid = jnp.concatenate([jnp.ones(6, bool), size > 1e-6])
    separation = jnp.abs(axes @ d) - jnp.abs(axes @ RA) @ hA - jnp.abs(axes @ RB) @ hB
    separation = jnp.where(valid, separation, -jnp.inf)
    # the axis of least penetration, a face's unless an edge pair's is clearly better (MuJoCo's
    # rule: a face manifold is better for the solver, and a resting stack must not flip)
    face = jnp.argmax(separation[:6])
    cross_best = 6 + jnp.argmax(separation[6:])
    s_face, s_edge = separation[face], separation[cross_best]
    aliased = ((jnp.abs(jnp.dot(axes[cross_best], axes[face])) > 0.99)
               & (s_edge < s_face + 0.05 * jnp.abs(s_face) + 1e-15))
    edge_wins = (s_edge - 1e-6 * jnp.abs(s_edge) > s_face) & ~aliased
    k = jnp.where(edge_wins, cross_best, face)
    n = axes[k] * jnp.where(jnp.dot(axes[k], d) >= 0, 1.0, -1.0)        # from A towards B
    face_a, face_b = _face(RA, pA, hA, n), _face(RB, pB, hB, -n)
    dist_a, pos_a = _face_contacts(face_a, face_b, n)                    # A's face the reference
    dist_b, pos_b = _face_contacts(face_b, face_a, -n)
    # an edge-edge axis: the two edges nearest each other along n
    i, j = (k - 6) // 3, (k - 6) % 3

    def edge(R, p, h, axis_index, towards):
        centre = p + R @ (h * jnp.where(R.T @ towards >= 0, 1.0, -1.0)
                          * (jnp.arange(3) != axis_index))
        half = R[:, axis_index] * h[axis_index]
        return centre - half, centre + half

    qa, qb = _closest_points(*edge(RA, pA, hA, i, n), *edge(RB, pB, hB, j, -n))
    edge_dist = jnp.dot(qb - qa, n)
    on_edge = jnp.zeros(24, bool).at[0].set(True)
    dist_e = jnp.where(on_edge, edge_dist, AWAY)
    pos_e = jnp.broadcast_to(0.5 * (qa + qb), (24, 3))
    dist = jnp.where(k < 3, dist_a, jnp.where(k < 6, dist_b, dist_e))
    pos = jnp.where(k < 3, pos_a, jnp.where(k < 6, pos_b, pos_e))
    return dist, pos, jnp.broadcast_to(frame_from_normal(n), (24, 3, 3))


PAIRS = {("plane", "sphere"): plane_sphere, ("plane", "capsule"): plane_capsule,
         ("plane", "ellipsoid"): plane_ellipsoid, ("plane", "cylinder"): plane_cylinder,
         ("plane", "box"): plane_box, ("sphere", "sphere"): sphere_sphere,
         ("sphere", "capsule"): sphere_capsule, ("sphere", "box"): sphere_box,
         ("capsule", "capsule"): capsule_capsule, ("capsule", "box"): capsule_box,
         ("box", "box"): box_box}
assert set(PAIRS) == DETECTED, "the model's list of detected pairs is this module's"
