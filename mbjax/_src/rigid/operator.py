"""The transformation-operator formulation of Jerkovsky 1978 (§§III-V), dense, for rigid trees.

Primitive variables (§III): per body the angular velocity omega and the velocity of the centre of
mass v_c, sigma = (omega; v_c) (eq 6, stored body by body rather than all omegas first); the
primitive mass mu = diag(I_c, M 1) (eq 7a, world-frame inertia about the centre of mass); the
Euler coupling Y = (omega x I_c omega; 0) (eq 6); the applied force K (here gravity, (0; M g)).

Transformed variables (§IV): the relative velocities sigma_bar = (Omega^j; U^j) at the hinge h_j
(eqs 12-13, 16). The transformation operator A (eq 17) follows from the path matrix pi (eq 14):

    omega_k = sum_j pi_kj Omega^j,   v_ck = sum_j pi_kj (Omega^j x R_{c_k h_j} + U^j),

so its (k, j) block is pi_kj [[1, 0], [-R~_{c_k h_j}, 1]]. The induced mass is
mu_bar = A^T mu A (eq 18; its blocks are eq 22's composite inertias).

Free/constrained split (§V): sigma_bar = A_hat_f sigma_hat_f + A_hat_c sigma_hat_c (eq 49) with
A_hat_f the joint axes (Gamma_f, Delta_f of eq 43) in world coordinates; the joint rates are the
free velocities sigma_hat_f and sigma_hat_c = 0 for a tree. The generalized mass is
mu_hat_ff = A_hat_f^T mu_bar A_hat_f (eq 55).

`operator_terms` returns the operator alpha_f = A A_hat_f (eq 77, sigma = alpha_f v) and its rate
alpha_f_dot, built block by block from the path matrix (O(n^2) entries), which is all the velocity
form (eq 74), the momentum form (eqs 72-73) and the constraint forces (eqs 75-76) need.
"""

from typing import NamedTuple

import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.model import Model
from mbjax._src.rigid.kinematics import forward_kinematics
from mbjax._src.spatial import skew


class OperatorTerms(NamedTuple):
    A: Array           # (n, n, 6, 6) the operator of eq 17 in blocks: A[k, j] = pi_kj [[1,0],[-R~,1]]
    alpha: Array       # (n, 6, nv): sigma_k = alpha[k] @ v  (eq 77, alpha_f = A A_hat_f)
    alpha_dot: Array   # (n, 6, nv): its time derivative along the motion
    sigma: Array       # (n, 6) primitive velocities (omega; v_c), world frame
    mu: Array          # (n, 6, 6) primitive mass diag(I_c, M 1) (eq 7a), world frame
    Y: Array           # (n, 6) Euler coupling (omega x I_c omega; 0) (eq 6)
    K: Array           # (n, 6) applied primitive force: gravity (0; M g)
    A_hat: Array       # (n, 6, width) free axes (Gamma_f; Delta_f) at the hinges, world frame
    c: Array           # (n, 3) centres of mass c_k, world frame
    h: Array           # (n, 3) hinge points h_k (body-frame origins), world frame
    armature: Array    # (nv,) rotor inertias on the joint coordinates (model.armature)
    passive: Array     # (nv,) the joints' passive forces (`Model.passive_force`)


def _shift(r: Array) -> Array:
    """The block [[1, 0], [-r~, 1]] of A: it moves a motion vector from a hinge to a point at r."""
    eye = jnp.broadcast_to(jnp.eye(3, dtype=r.dtype), (*r.shape[:-1], 3, 3))
    zero = jnp.zeros_like(eye)
    return jnp.concatenate([jnp.concatenate([eye, zero], -1),
                            jnp.concatenate([-skew(r), eye], -1)], -2)


def _rate_of_shift(r_dot: Array) -> Array:
    """d/dt of _shift(r): [[0, 0], [-r_dot~, 0]]."""
    zero = jnp.zeros((*r_dot.shape[:-1], 3, 3), r_dot.dtype)
    return jnp.concatenate([jnp.concatenate([zero, zero], -1),
                            jnp.concatenate([-skew(r_dot), zero], -1)], -2)


def _rotate(R: Array, m: Array) -> Array:
    """blockdiag(R, R) applied to (n, 6, ...) motion vectors or matrices."""
    return jnp.concatenate([R @ m[..., :3, :], R @ m[..., 3:, :]], -2)


def path_operator(model: Model) -> Array:
    """The path matrix pi (Jerkovsky 1978 eq 1) as a float array, the sparsity of A (eq 14)."""
    return jnp.asarray(model.topology.path_matrix(), dtype=model.mass.dtype)


def _free_columns(model: Model) -> np.ndarray:
    """Which of the n * width padded joint columns are real velocity coordinates."""
    return np.flatnonzero(model.v_mask.reshape(-1))


def transformation_operator(model: Model, q: Array) -> tuple[Array, Array]:
    """Jerkovsky 1978's transformation operator A (eq 17) and free-axis matrix A_hat_f (eq 47) as
    explicit matrices.

    sigma = A sigma_bar maps the relative velocities at the hinges to the bodies' primitive
    velocities (omega; v_c), and sigma_bar = A_hat_f v the joint rates to the relative
    velocities (the formulation below). For display and checks: the dynamics use the block
    form (`operator_terms`).

    Args:
        model: the tree.
        q: configuration, shape (nq,).

    Returns:
        (A, A_hat_f): shapes (6n, 6n) and (6n, nv), rows body-major (omega_1, v_c1, omega_2,
            ...), world-frame components.

    The formulation (Jerkovsky 1978 §§III-V):
        Primitive variables (§III): per body the angular velocity omega and the velocity of the
        centre of mass v_c, sigma = (omega; v_c) (eq 6, stored body by body rather than all
        omegas first); the primitive mass mu = diag(I_c, M 1) (eq 7a, world-frame inertia about
        the centre of mass).

        Transformed variables (§IV): the relative velocities sigma_bar = (Omega^j; U^j) at the
        hinge h_j (eqs 12-13, 16). The transformation operator A (eq 17) follows from the path
        matrix pi (eq 14):

            omega_k = sum_j pi_kj Omega^j,   v_ck = sum_j pi_kj (Omega^j x R_{c_k h_j} + U^j),

        so its (k, j) block is pi_kj [[1, 0], [-R~_{c_k h_j}, 1]]. The induced mass is
        mu_bar = A^T mu A (eq 18; its blocks are eq 22's composite inertias).

        Free/constrained split (§V): sigma_bar = A_hat_f sigma_hat_f + A_hat_c sigma_hat_c
        (eq 49) with A_hat_f the joint axes (Gamma_f, Delta_f of eq 43) in world coordinates;
        the joint rates are the free velocities sigma_hat_f and sigma_hat_c = 0 for a tree. The
        generalized mass is mu_hat_ff = A_hat_f^T mu_bar A_hat_f (eq 55).
    """
    terms = operator_terms(model, q, jnp.zeros(model.nv, q.dtype))
    n, w = model.n, model.width
    A = terms.A.transpose(0, 2, 1, 3).reshape(6 * n, 6 * n)
    A_hat = jnp.zeros((n, 6, n, w), q.dtype).at[np.arange(n), :, np.arange(n), :].set(terms.A_hat)
    return A, A_hat.reshape(6 * n, n * w)[:, _free_columns(model)]


def inverse_operator(model: Model, q: Array) -> Array:
    """B = A^-1 (Jerkovsky 1978 eqs 15, 17) from the reference matrix rho, explicit 6n x 6n, body-major:
    Omega^i = sum_j rho_ij omega^j and U^i = sum_j rho_ij (R~_{c_j h_i} omega^j + v_cj), so the
    (i, j) block is rho_ij [[1, 0], [R~_{c_j h_i}, 1]]. Only 2n - 1 blocks are non-zero: rho is
    sparser than pi, as the paper notes after eq 26."""
    R, h = forward_kinematics(model, q)
    c = h + jnp.einsum("kij,kj->ki", R, model.com)
    rho = jnp.asarray(model.topology.reference_matrix(), dtype=q.dtype)
    blocks = rho[:, :, None, None] * _shift(h[:, None, :] - c[None, :, :])   # -R~ with R = h - c
    return blocks.transpose(0, 2, 1, 3).reshape(6 * model.n, 6 * model.n)


def primitive_inverse_mass(terms: OperatorTerms) -> Array:
    """nu = diag(J_c, W 1) = mu^-1 body by body (Jerkovsky 1978 eq 7b), (n, 6, 6), by 3x3 solves."""
    I_c, M = terms.mu[:, :3, :3], terms.mu[:, 3, 3]
    eye = jnp.broadcast_to(jnp.eye(3, dtype=I_c.dtype), I_c.shape)
    J_c = jnp.linalg.solve(I_c, eye)
    zero = jnp.zeros_like(J_c)
    return jnp.concatenate([jnp.concatenate([J_c, zero], -1),
                            jnp.concatenate([zero, eye / M[:, None, None]], -1)], -2)


def operator_terms(model: Model, q: Array, v: Array) -> OperatorTerms:
    """alpha_f = A A_hat_f and its rate from the path matrix, with mu, Y, K and sigma."""
    R, h = forward_kinematics(model, q)
    _, _, S, S_dot = model.joints(q, v)
    c = h + jnp.einsum("kij,kj->ki", R, model.com)
    pi = path_operator(model)
    vb = model.body_v(v)

    # Relative velocities at the hinges (eqs 39a, 49): sigma_bar_j = A_hat_f,j v_j.
    Sw = _rotate(R, S)                                              # (n, 6, width)
    sigma_bar = jnp.einsum("jiw,jw->ji", Sw, vb)
    # The operator of eq 17 in blocks and sigma = A sigma_bar (eq 14).
    A = pi[:, :, None, None] * _shift(c[:, None, :] - h[None, :, :])     # (k, j, 6, 6)
    sigma = jnp.einsum("kjab,jb->ka", A, sigma_bar)
    omega, v_c = sigma[:, :3], sigma[:, 3:]
    v_h = v_c - jnp.cross(omega, c - h)                             # hinge velocities

    # Rates: the axes turn with their body (Gamma_dot, Delta_dot of eq 66) and, for a universal
    # joint, with the joint itself; the shift blocks change as c_k and h_j move.
    omega_x = skew(omega)
    Sw_dot = jnp.concatenate([omega_x @ Sw[:, :3], omega_x @ Sw[:, 3:]], -2) + _rotate(R, S_dot)
    shift_dot = _rate_of_shift(v_c[:, None, :] - v_h[None, :, :])

    cols = _free_columns(model)

    def blocks(M):                                                  # (k, j, 6, w) -> (k, 6, nv)
        return M.transpose(0, 2, 1, 3).reshape(model.n, 6, -1)[:, :, cols]

    alpha = blocks(A @ Sw[None])
    alpha_dot = blocks(pi[:, :, None, None] * (shift_dot @ Sw[None]) + A @ Sw_dot[None])

    I_c = R @ model.inertia @ jnp.swapaxes(R, -1, -2)
    eye = jnp.eye(3, dtype=q.dtype)
    zero = jnp.zeros_like(I_c)
    mu = jnp.concatenate([jnp.concatenate([I_c, zero], -1),
                          jnp.concatenate([zero, model.mass[:, None, None] * eye], -1)], -2)
    Y = jnp.concatenate([jnp.cross(omega, jnp.einsum("kij,kj->ki", I_c, omega)),
                         jnp.zeros_like(omega)], -1)
    K = jnp.concatenate([jnp.zeros_like(c), model.mass[:, None] * model.gravity], -1)
    return OperatorTerms(A, alpha, alpha_dot, sigma, mu, Y, K, Sw, c, h, model.armature,
                         model.passive_force(q, v))


def with_external(terms: OperatorTerms, f_ext: Array | None) -> OperatorTerms:
    """The terms with external wrenches f_ext (n, 6) (world frame, (torque about body k's origin
    h_k; force), or None) added to the applied primitive forces K, which act about the centres
    of mass: (n + (h - c) x f; f)."""
    if f_ext is None:
        return terms
    torque = f_ext[:, :3] + jnp.cross(terms.h - terms.c, f_ext[:, 3:])
    return terms._replace(K=terms.K + jnp.concatenate([torque, f_ext[:, 3:]], -1))


def generalized_mass(terms: OperatorTerms) -> Array:
    """mu_hat_ff = A_hat_f^T A^T mu A A_hat_f (eqs 18, 55), plus the joints' armature."""
    return (jnp.einsum("kai,kab,kbj->ij", terms.alpha, terms.mu, terms.alpha)
            + jnp.diag(terms.armature))


def mass_matrix(model: Model, q: Array) -> Array:
    """The generalized mass matrix mu_hat_ff (nv x nv) of Jerkovsky 1978 eq 55."""
    return generalized_mass(operator_terms(model, q, jnp.zeros(model.nv, q.dtype)))
