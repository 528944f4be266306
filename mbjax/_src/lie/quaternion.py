"""Unit quaternions q = (w, x, y, z), w the scalar part, and their conversions.

q = (cos(phi/2), sin(phi/2) e) for the rotation vector r = phi e, so that quat_to_matrix(q) ==
exp(r). Products follow Hamilton's convention: quat_to_matrix(p * q) == quat_to_matrix(p) @
quat_to_matrix(q).
"""

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.lie import inputs as _inputs
from mbjax._src.lie.series import COS_HALF, SIN_HALF_OVER_PHI, even_series


@jax.jit
def quat_multiply(p: Array, q: Array) -> Array:
    """The Hamilton product p * q of two quaternions (w, x, y, z).

    quat_to_matrix(p * q) == quat_to_matrix(p) @ quat_to_matrix(q) for unit quaternions.

    Args:
        p: the left factor, shape (4,).
        q: the right factor, shape (4,).

    Returns:
        The product, shape (4,).

    Raises:
        ValueError: p or q does not have shape (4,).
        TypeError: p or q is complex or not numeric.
    """
    p, q = _inputs.quaternion(p, "quat_multiply", "p"), _inputs.quaternion(q, "quat_multiply")
    pw, pv = p[0], p[1:]
    qw, qv = q[0], q[1:]
    return jnp.concatenate([
        jnp.atleast_1d(pw * qw - jnp.dot(pv, qv)),
        pw * qv + qw * pv + jnp.cross(pv, qv),
    ])


@jax.jit
def quat_conjugate(q: Array) -> Array:
    """The conjugate (w, -x, -y, -z): the inverse rotation of a unit quaternion.

    Args:
        q: quaternion (w, x, y, z), shape (4,).

    Returns:
        The conjugate quaternion, shape (4,).

    Raises:
        ValueError: q does not have shape (4,).
        TypeError: q is complex or not numeric.
    """
    q = _inputs.quaternion(q, "quat_conjugate")
    return q * jnp.array([1.0, -1.0, -1.0, -1.0], dtype=q.dtype)


@jax.jit
def quat_normalize(q: Array) -> Array:
    """q scaled to unit length (projected onto the unit sphere).

    Args:
        q: a nonzero quaternion (w, x, y, z), shape (4,).

    Returns:
        q / |q|, shape (4,).

    Raises:
        ValueError: q does not have shape (4,).
        TypeError: q is complex or not numeric.
    """
    q = _inputs.quaternion(q, "quat_normalize")
    return q / jnp.linalg.norm(q)


@jax.jit
def quat_to_matrix(q: Array) -> Array:
    """The rotation matrix of a unit quaternion.

    Args:
        q: unit quaternion (w, x, y, z), w the scalar part, shape (4,). It is not normalized
            here: normalize a drifted one first (`quat_normalize`).

    Returns:
        The rotation matrix, equal to exp(r) for q = (cos(phi/2), sin(phi/2) e), shape (3, 3).

    Raises:
        ValueError: q does not have shape (4,).
        TypeError: q is complex or not numeric.
    """
    q = _inputs.quaternion(q, "quat_to_matrix")
    w, x, y, z = q
    return jnp.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


@jax.jit
def quat_from_rotvec(r: Array) -> Array:
    """The unit quaternion of a rotation vector: q = (cos(phi/2), sin(phi/2) / phi r).

    Exact and differentiable at r = 0 (power series below phi = 0.5).

    Args:
        r: rotation vector phi e (angle phi [rad] about the unit axis e), shape (3,).

    Returns:
        The unit quaternion (w, x, y, z), shape (4,).

    Raises:
        ValueError: r does not have shape (3,).
        TypeError: r is complex or not numeric.
    """
    r = _inputs.rotation_vector(r, "quat_from_rotvec")
    phi2 = jnp.dot(r, r)
    w = even_series(phi2, lambda p2: jnp.cos(0.5 * jnp.sqrt(p2)), COS_HALF)
    s = even_series(phi2, lambda p2: jnp.sin(0.5 * jnp.sqrt(p2)) / jnp.sqrt(p2), SIN_HALF_OVER_PHI)
    return jnp.concatenate([jnp.atleast_1d(w), s * r])


@jax.jit
def rotvec_from_quat(q: Array) -> Array:
    """The principal rotation vector of a unit quaternion: r = 2 atan2(|v|, w) v / |v|.

    q and -q are the same rotation; the one with w >= 0 is used, so that |r| <= pi.
    Differentiable to every order at the identity and at a half turn.

    Args:
        q: unit quaternion (w, x, y, z) = (w, v), shape (4,).

    Returns:
        The rotation vector r, |r| <= pi, shape (3,).

    Raises:
        ValueError: q does not have shape (4,).
        TypeError: q is complex or not numeric.
    """
    q = _inputs.quaternion(q, "rotvec_from_quat")
    q = jnp.where(q[0] < 0, -q, q)  # q and -q are the same rotation; w >= 0 picks |r| <= pi
    w, v = q[0], q[1:]
    s2 = jnp.dot(v, v)
    # atan2(s, w) / s; below s = 1e-2 its series in s2 / w^2 (arctan(x)/x) is exact to round-off.
    # Each branch is fed a safe value where the other owns the result (w ~ 1 on the series'
    # branch; w = 0 at a half turn on atan2's), so derivatives of every order stay finite.
    small = s2 < 1e-4
    safe_s2 = jnp.where(small, 1.0, s2)
    safe_w = jnp.where(small, w, 1.0)
    x2 = s2 / (safe_w * safe_w)
    series = 1.0 + x2 * (-1 / 3 + x2 * (1 / 5 + x2 * (-1 / 7 + x2 * (1 / 9 - x2 / 11))))
    ratio = jnp.where(small, series / safe_w,
                      jnp.arctan2(jnp.sqrt(safe_s2), w) / jnp.sqrt(safe_s2))
    return 2.0 * ratio * v


@jax.jit
def quat_from_matrix(R: Array) -> Array:
    """The unit quaternion of a rotation matrix, by Shepperd's method.

    Of the four equivalent formulas the one with the largest pivot 4 q_k^2 (>= 1) is used, so
    the square root and the division are always well conditioned; the others are fed a safe
    value so that their (discarded) derivatives stay finite.

    Args:
        R: rotation matrix, shape (3, 3). It is not checked to be a rotation (`log` checks).

    Returns:
        A unit quaternion (w, x, y, z) of R, shape (4,); its sign is that of the formula
            chosen (q and -q are the same rotation).

    Raises:
        ValueError: R does not have shape (3, 3).
        TypeError: R is complex or not numeric.
    """
    R = _inputs.matrix(R, "quat_from_matrix")
    tr = R[0, 0] + R[1, 1] + R[2, 2]
    d = jnp.array([1 + tr, 1 + 2 * R[0, 0] - tr, 1 + 2 * R[1, 1] - tr, 1 + 2 * R[2, 2] - tr])
    s = jnp.sqrt(jnp.where(d > 0.1, d, 1.0))  # s_k = 2 |q_k| on the chosen branch (d_k >= 1)
    a = jnp.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])  # 4 w (x, y, z)
    b = jnp.array([R[0, 1] + R[1, 0], R[0, 2] + R[2, 0], R[1, 2] + R[2, 1]])  # 4 (xy, xz, yz)
    candidates = 0.5 * jnp.array([
        [s[0], a[0] / s[0], a[1] / s[0], a[2] / s[0]],
        [a[0] / s[1], s[1], b[0] / s[1], b[1] / s[1]],
        [a[1] / s[2], b[0] / s[2], s[2], b[2] / s[2]],
        [a[2] / s[3], b[1] / s[3], b[2] / s[3], s[3]],
    ])
    return candidates[jnp.argmax(d)]
