"""Jerkovsky 1978's momentum formulation (eqs 72-73, 75) for a tree.

The state is (q, G_hat_f) with the free momenta G_hat_f = mu_hat_ff sigma_hat_f (eq 73,
sigma_hat_c = 0): p = alpha_f^T mu sigma = M(q) v. They obey eq 72,

    p_dot = K_hat_f - X_hat_f,   X_hat_f = -alpha_f_dot^T G,   K_hat_f = tau + alpha_f^T K,

where G = mu sigma is the primitive momentum (eq 8) and X = 0 for the primitive equations, so
X_hat_f = A_hat_f^T X_bar - A_hat_f_dot^T G_bar (eqs 27, 61) = -(A A_hat_f)_dot^T G. Integrating
p rather than v is what makes this form attractive: p_dot needs no mass-matrix solve, only
v = mu_hat_ff^-1 p does (one Cholesky per evaluation, as Jerkovsky 1978 notes after eq 73).

The constraint forces follow from eq 75, K_hat_c = G_hat_c_dot + X_hat_c, with
G_hat = A_hat^T A^T G the momentum of each outward system j-bar about its hinge (eq 19-20); its
time derivative is taken by forward-mode autodiff along the motion.
"""

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.model import Model
from mbjax._src.rigid.operator import generalized_mass, operator_terms, with_external


def momentum(model: Model, q: Array, v: Array) -> Array:
    """The free momenta G_hat_f = mu_hat_ff v (eq 73)."""
    return generalized_mass(operator_terms(model, q, v)) @ v


def velocity_from_momentum(model: Model, q: Array, p: Array) -> Array:
    """v = mu_hat_ff^-1 G_hat_f by Cholesky (eq 73 inverted)."""
    M = generalized_mass(operator_terms(model, q, jnp.zeros(model.nv, q.dtype)))
    return jax.scipy.linalg.cho_solve(jax.scipy.linalg.cho_factor(M), p)


def momentum_rate(model: Model, q: Array, v: Array, tau: Array, f_ext: Array | None = None) -> Array:
    """G_hat_f_dot = tau + alpha_f^T K + alpha_f_dot^T mu sigma (eq 72); external wrenches f_ext
    (n, 6) (world frame, torque about the body origins) join the applied forces K, and the joints'
    passive forces (`Model.passive_force`) join tau (armature is constant, so it adds nothing
    to the rate)."""
    terms = with_external(operator_terms(model, q, v), f_ext)
    G = jnp.einsum("kab,kb->ka", terms.mu, terms.sigma)
    return (tau + terms.passive + jnp.einsum("kan,ka->n", terms.alpha, terms.K)
            + jnp.einsum("kan,ka->n", terms.alpha_dot, G))


def system_momenta(model: Model, q: Array, v: Array) -> Array:
    """G_bar = A^T G (eqs 19-20): per joint (H^{j-bar} about h_j; P^{j-bar}), ground frame."""
    terms = operator_terms(model, q, v)
    G = jnp.einsum("kab,kb->ka", terms.mu, terms.sigma)
    return jnp.einsum("kjab,ka->jb", terms.A, G)


def constraint_forces_momentum(model: Model, q: Array, v: Array, a: Array) -> Array:
    """Each joint's transmitted wrench from eq 75 (before removing the free components):
    G_bar_dot + X_bar with X_bar = (v_h x P^{j-bar}; 0) (eq 29a). Ground frame, about the hinge,
    gravity included as an applied force. Compare `dense.joint_reactions` (eq 76)."""
    q_dot = model.q_dot(q, v)
    G_bar, G_bar_dot = jax.jvp(lambda q_, v_: system_momenta(model, q_, v_), (q, v), (q_dot, a))
    terms = operator_terms(model, q, v)
    omega, v_c = terms.sigma[:, :3], terms.sigma[:, 3:]
    v_h = v_c - jnp.cross(omega, terms.c - terms.h)
    X_bar = jnp.concatenate([jnp.cross(v_h, G_bar[:, 3:]), jnp.zeros_like(v_h)], -1)
    return G_bar_dot + X_bar - jnp.einsum("kjab,ka->jb", terms.A, terms.K)
