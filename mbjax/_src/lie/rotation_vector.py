"""The rotation vector and its tangent map (Borri 1990, Appendix A).

A rotation vector r = phi e (angle phi, unit axis e) parametrizes R = exp(r x I) (eq A.6). The
angular velocity is spatial, omega x I = R_dot R^T (eq A.11), and is related to r_dot by
omega = Gamma(r) r_dot (eq A.16-A.17); the same Gamma maps variations to virtual rotations
(eq A.19). All functions take a single vector or matrix; use `jax.vmap` for batches.
"""

from functools import partial

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.lie import inputs as _inputs
from mbjax._src.lie.series import (
    GAMMA_INV_COEFF,
    ONE_MINUS_COS_OVER_PHI2,
    PHI_MINUS_SIN_OVER_PHI3,
    SIN_PHI_OVER_PHI,
    even_series,
)
from mbjax._src.lie.quaternion import quat_from_matrix, rotvec_from_quat


@jax.jit
def hat(v: Array) -> Array:
    """The skew matrix v x I, so that hat(v) @ w == cross(v, w).

    Args:
        v: a 3-vector, shape (3,).

    Returns:
        The skew-symmetric matrix of v, shape (3, 3).

    Raises:
        ValueError: v does not have shape (3,) (map a batch with `jax.vmap`).
        TypeError: v is complex or not numeric.
    """
    v = _inputs.real(v, (3,), "hat", "v", "a 3-vector")
    zero = jnp.zeros_like(v[0])
    return jnp.array([
        [zero, -v[2], v[1]],
        [v[2], zero, -v[0]],
        [-v[1], v[0], zero],
    ])


@jax.jit
def vee(S: Array) -> Array:
    """The vector of the skew part of S, the inverse of `hat` on skew matrices.

    Args:
        S: a matrix, shape (3, 3); its symmetric part is ignored.

    Returns:
        The vector v with hat(v) = (S - S^T) / 2, shape (3,).

    Raises:
        ValueError: S does not have shape (3, 3).
        TypeError: S is complex or not numeric.
    """
    S = _inputs.matrix(S, "vee", "S")
    return 0.5 * jnp.array([S[2, 1] - S[1, 2], S[0, 2] - S[2, 0], S[1, 0] - S[0, 1]])


def _coefficients(r: Array):
    """a_o, a_1, b_1 of eq A.23 as functions of phi2 = r . r."""
    phi2 = jnp.dot(r, r)
    a_o = even_series(phi2, lambda p2: jnp.sin(jnp.sqrt(p2)) / jnp.sqrt(p2), SIN_PHI_OVER_PHI)
    a_1 = even_series(phi2, lambda p2: 2.0 * jnp.sin(0.5 * jnp.sqrt(p2)) ** 2 / p2,
                      ONE_MINUS_COS_OVER_PHI2)
    b_1 = even_series(phi2, lambda p2: (jnp.sqrt(p2) - jnp.sin(jnp.sqrt(p2))) / (p2 * jnp.sqrt(p2)),
                      PHI_MINUS_SIN_OVER_PHI3)
    return a_o, a_1, b_1


@jax.jit
def exp(r: Array) -> Array:
    """The rotation matrix of a rotation vector: R = exp(r x I) (Borri 1990 eqs A.3, A.6).

    Evaluated as R = I + a_o (r x I) + a_1 (r x I)^2 with a_o = sin(phi) / phi and
    a_1 = (1 - cos phi) / phi^2 (eq A.23), phi = |r|; exact and differentiable at r = 0.

    Args:
        r: rotation vector phi e (angle phi [rad] about the unit axis e), shape (3,).

    Returns:
        The rotation matrix R, shape (3, 3).

    Raises:
        ValueError: r does not have shape (3,) (map a batch with `jax.vmap`).
        TypeError: r is complex or not numeric.
    """
    r = _inputs.rotation_vector(r, "exp")
    a_o, a_1, _ = _coefficients(r)
    K = hat(r)
    return jnp.eye(3, dtype=K.dtype) + a_o * K + a_1 * (K @ K)


@jax.jit
def gamma(r: Array) -> Array:
    """The tangent map Gamma(r), which gives the angular velocity omega = Gamma(r) r_dot.

    Gamma(r) = I + a_1 (r x I) + b_1 (r x I)^2 with a_1 = (1 - cos phi) / phi^2 and
    b_1 = (phi - sin phi) / phi^3 (Borri 1990 eqs 2.9, A.17, A.23); omega is the spatial
    angular velocity (eq A.11). The same Gamma maps variations of r to virtual rotations
    (eq A.19).

    Args:
        r: rotation vector, shape (3,).

    Returns:
        Gamma(r), shape (3, 3).

    Raises:
        ValueError: r does not have shape (3,).
        TypeError: r is complex or not numeric.
    """
    r = _inputs.rotation_vector(r, "gamma")
    _, a_1, b_1 = _coefficients(r)
    K = hat(r)
    return jnp.eye(3, dtype=K.dtype) + a_1 * K + b_1 * (K @ K)


@jax.jit
def gamma_inv(r: Array) -> Array:
    """The inverse tangent map Gamma(r)^-1, which gives r_dot = Gamma(r)^-1 omega.

    Gamma^-1 = I - (r x I)/2 + (1 - a_o / (2 a_1)) / phi^2 (r x I)^2 (Borri 1990 eq A.21).
    The paper prints a_o / (2 b_1); the consistent coefficient, which its eq A.57 uses as
    a_o / (2 b_o) with b_o = a_1, is a_o / (2 a_1) = (phi/2) cot(phi/2). Singular at
    phi = 2 pi n, n >= 1 (eq A.28); see `rescale`.

    Args:
        r: rotation vector, shape (3,); |r| must stay away from 2 pi n, n >= 1.

    Returns:
        Gamma(r)^-1, shape (3, 3).

    Raises:
        ValueError: r does not have shape (3,).
        TypeError: r is complex or not numeric.
    """
    r = _inputs.rotation_vector(r, "gamma_inv")
    phi2 = jnp.dot(r, r)

    def closed_form(p2):
        half = 0.5 * jnp.sqrt(p2)
        return (1.0 - half * jnp.cos(half) / jnp.sin(half)) / p2

    c = even_series(phi2, closed_form, GAMMA_INV_COEFF)
    K = hat(r)
    return jnp.eye(3, dtype=K.dtype) - 0.5 * K + c * (K @ K)


@jax.jit
def det_gamma(r: Array) -> Array:
    """The determinant of the tangent map, det Gamma(r) = 2 (1 - cos phi) / phi^2.

    Borri 1990 eq A.28; zero at phi = 2 pi n, n >= 1, where Gamma is singular.

    Args:
        r: rotation vector, shape (3,).

    Returns:
        det Gamma(r), a scalar.

    Raises:
        ValueError: r does not have shape (3,).
        TypeError: r is complex or not numeric.
    """
    r = _inputs.rotation_vector(r, "det_gamma")
    return 2.0 * _coefficients(r)[1]


@jax.jit
def rescale(r: Array) -> Array:
    """The rescaled rotation vector r_p = r - 2 pi n e of Borri 1990 eq A.29.

    Both describe the same rotation and Gamma(r_p) dr_p = Gamma(r) dr (eq A.36). The paper takes
    n = int(phi / 2 pi); here n is the nearest integer, which gives the principal vector
    (|r_p| <= pi) and so stays as far as possible from the singularity of Gamma at 2 pi.

    Args:
        r: rotation vector, shape (3,).

    Returns:
        The principal rotation vector of the same rotation, |r_p| <= pi, shape (3,).

    Raises:
        ValueError: r does not have shape (3,).
        TypeError: r is complex or not numeric.
    """
    r = _inputs.rotation_vector(r, "rescale")
    phi2 = jnp.dot(r, r)
    safe_phi = jnp.sqrt(jnp.where(phi2 > 0.0, phi2, 1.0))
    n = jnp.round(safe_phi / (2.0 * jnp.pi))
    scale = jnp.where(n == 0, 1.0, 1.0 - 2.0 * jnp.pi * n / safe_phi)
    return scale * r


def _rotation_tolerance(dtype) -> float:
    return max(1e-6, 1e4 * float(jnp.finfo(dtype).eps))


@partial(jax.jit, static_argnames="check")
def log(R: Array, check: bool = True) -> Array:
    """The principal rotation vector r (|r| <= pi) with exp(r) = R.

    Computed through the quaternion of R (Shepperd's method), which is accurate and
    differentiable at every angle, including 0 and pi.

    Args:
        R: rotation matrix, shape (3, 3).
        check: test that R is a rotation (R^T R = I and det R = 1 to round-off), also under
            `jit`. Pass False where R is a rotation by construction (a product of rotations):
            the run-time test is a host callback, which keeps a compiled program out of the
            persistent compilation cache and a loop around it from compiling as one kernel
            (see the `mbjax` module's runtime settings).

    Returns:
        The rotation vector r, |r| <= pi, shape (3,).

    Raises:
        ValueError: R does not have shape (3, 3).
        TypeError: R is complex or not numeric.
        equinox.EquinoxRuntimeError: with check=True, R is not a rotation (raised when the
            compiled program runs).
    """
    R = _inputs.matrix(R, "log")
    if check:
        tol = _rotation_tolerance(R.dtype)
        orthogonality = jnp.max(jnp.abs(R.T @ R - jnp.eye(3, dtype=R.dtype)))
        det_error = jnp.abs(jnp.dot(R[0], jnp.cross(R[1], R[2])) - 1.0)   # det R, the triple product
        R = eqx.error_if(R, ~((orthogonality <= tol) & (det_error <= tol)),
                         "mbjax.lie.log: the matrix is not a rotation (R^T R != I or det R != 1)")
    return rotvec_from_quat(quat_from_matrix(R))
