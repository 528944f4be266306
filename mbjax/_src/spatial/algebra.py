"""Spatial vectors, Plucker transforms, cross products and rigid-body inertia (angular; linear).

The cross products are Anderson 1993's recursive kinematics (eqs 20-31) written once in 6-D: the
velocity-product acceleration of a joint is V x (S u) and the Euler-coupling force of a body is
V x* (I V) (Jerkovsky 1978 eq 6: omega x H).
"""

import jax
import jax.numpy as jnp
import numpy as np
from jax import Array


def skew(v: Array) -> Array:
    """The 3x3 matrix with skew(v) @ w = v x w (Jerkovsky 1978's tilde dyadic)."""
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    zero = jnp.zeros_like(x)
    return jnp.stack([jnp.stack([zero, -z, y], -1),
                      jnp.stack([z, zero, -x], -1),
                      jnp.stack([-y, x, zero], -1)], -2)


def plucker(E: Array, r: Array) -> Array:
    """Motion transform from frame A to frame B, where B has orientation E (x_B = E x_A) and origin
    r (in A coordinates): X = [[E, 0], [-E skew(r), E]]."""
    zero = jnp.zeros_like(E)
    return jnp.concatenate([jnp.concatenate([E, zero], -1),
                            jnp.concatenate([-E @ skew(r), E], -1)], -2)


def cross_motion(V: Array, m: Array) -> Array:
    """V x m for motion vectors: (w x m_w; w x m_v + v x m_w)."""
    w, v = V[..., :3], V[..., 3:]
    mw, mv = m[..., :3], m[..., 3:]
    return jnp.concatenate([jnp.cross(w, mw), jnp.cross(w, mv) + jnp.cross(v, mw)], -1)


def cross_force(V: Array, f: Array) -> Array:
    """V x* f for force vectors: (w x f_n + v x f_f; w x f_f)."""
    w, v = V[..., :3], V[..., 3:]
    fn, ff = f[..., :3], f[..., 3:]
    return jnp.concatenate([jnp.cross(w, fn) + jnp.cross(v, ff), jnp.cross(w, ff)], -1)


def shift_force(f: Array, x: Array) -> Array:
    """A force vector (torque about the point x; force) taken about the origin instead:
    (n + x x f; f). Same components; x in them."""
    return jnp.concatenate([f[..., :3] + jnp.cross(x, f[..., 3:]), f[..., 3:]], -1)


def inertia_matrix(mass: Array, com: Array, inertia: Array) -> Array:
    """6x6 spatial inertia about a frame's origin, from mass, centre of mass c and the 3x3 inertia
    about c (all in that frame): [[I_c + m c~ c~^T, m c~], [m c~^T, m 1]]."""
    C = skew(com)
    m = mass[..., None, None]
    eye = jnp.broadcast_to(jnp.eye(3, dtype=C.dtype), C.shape)
    return jnp.concatenate([jnp.concatenate([inertia - m * C @ C, m * C], -1),
                            jnp.concatenate([-m * C, m * eye], -1)], -2)


def check_inertia(inertia, name: str = "body") -> None:
    """Concrete validation of a 3x3 inertia: symmetric, positive-definite, triangle inequality."""
    if isinstance(inertia, jax.core.Tracer):
        return
    J = np.asarray(inertia, dtype=float)
    if J.shape != (3, 3):
        raise ValueError(f"{name}: inertia must be a 3x3 matrix, got shape {J.shape}")
    if not np.all(np.isfinite(J)):
        raise ValueError(f"{name}: inertia has non-finite entries\n{J}")
    if not np.allclose(J, J.T, rtol=1e-12, atol=1e-12 * np.abs(J).max()):
        raise ValueError(f"{name}: inertia must be symmetric, got\n{J}")
    moments = np.linalg.eigvalsh(J)
    if not moments[0] > 0:
        raise ValueError(f"{name}: inertia must be positive-definite; principal moments {moments}")
    if moments[0] + moments[1] < moments[2] * (1 - 1e-9):
        raise ValueError(f"{name}: principal moments {moments} violate the triangle inequality "
                         "J1 + J2 >= J3 that every mass distribution satisfies")
