"""Forward dynamics in Jerkovsky 1978's velocity formulation, dense: eq 74 solved by Cholesky.

    mu_hat_ff sigma_hat_f_dot + Y_hat_f = K_hat_f                       (eq 74, sigma_hat_c = 0)
    Y_hat_f = A_hat_f^T A^T (Y + mu (A_dot sigma_bar + A A_hat_f_dot sigma_hat_f))   (eq 63)
            = alpha_f^T (Y + mu alpha_f_dot v)
    K_hat_f = tau + alpha_f^T K                   (joint forces plus the applied forces, eq 81)

and the constraint forces of eq 76 at each joint,

    K_hat_c = A_hat_c^T A^T (mu sigma_dot + Y - K):

A^T (mu sigma_dot + Y - K) is, joint by joint, the wrench (torque about the hinge h_j; force) the
joint transmits to its outward system j-bar (eqs 20, 35); its free components are tau and its
constrained ones K_hat_c. Cost O(n^2) to build and O(n^3) to factor: `method=Dense()` of
`mbjax.forward_dynamics`.
"""

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.model import Model
from mbjax._src.rigid.operator import OperatorTerms, generalized_mass, operator_terms, with_external


def _bias(terms: OperatorTerms, v: Array) -> Array:
    """Y_hat_f - alpha_f^T K: everything in eq 74 that is not mass times acceleration or tau
    (the joints' passive forces included)."""
    remainder = jnp.einsum("kan,n->ka", terms.alpha_dot, v)
    force = jnp.einsum("kab,kb->ka", terms.mu, remainder) + terms.Y - terms.K
    return jnp.einsum("kan,ka->n", terms.alpha, force) - terms.passive


def dense_forward_dynamics(model: Model, q: Array, v: Array, tau: Array,
                           f_ext: Array | None = None) -> Array:
    """Joint accelerations from eq 74 with mu_hat_ff factored by Cholesky; external wrenches
    f_ext (n, 6) (world frame, torque about the body origins) join the applied forces K."""
    return dense_responses(model, q, v, tau, jnp.zeros((0, model.nv), q.dtype), f_ext)[0]


def dense_responses(model: Model, q: Array, v: Array, tau: Array, loads: Array,
                    f_ext: Array | None = None) -> tuple[Array, Array]:
    """As `mbjax._src.rigid.aba.aba_responses`, from eq 74: the accelerations under every force, and
    mu_hat_ff^-1 of each row of `loads` (m, nv), from one Cholesky factorization."""
    terms = with_external(operator_terms(model, q, v), f_ext)
    factor = jax.scipy.linalg.cho_factor(generalized_mass(terms))
    rhs = jnp.concatenate([(tau - _bias(terms, v))[:, None], loads.T], -1)
    out = jax.scipy.linalg.cho_solve(factor, rhs).T
    return out[0], out[1:]


def _reactions(terms: OperatorTerms, v: Array, a: Array) -> Array:
    sigma_dot = (jnp.einsum("kan,n->ka", terms.alpha, a)
                 + jnp.einsum("kan,n->ka", terms.alpha_dot, v))
    force = jnp.einsum("kab,kb->ka", terms.mu, sigma_dot) + terms.Y - terms.K
    return jnp.einsum("kjab,ka->jb", terms.A, force)


def joint_reactions(model: Model, q: Array, v: Array, a: Array) -> Array:
    """A^T (mu sigma_dot + Y - K) for accelerations a: per joint the transmitted wrench (n, 6),
    ground-frame components, torque about the hinge."""
    return _reactions(operator_terms(model, q, v), v, a)


def constraint_forces(model: Model, q: Array, v: Array, a: Array) -> Array:
    """The joints' constraint forces K_hat_c of Jerkovsky 1978 eq 76.

    Each joint's reaction wrench, A^T (mu sigma_dot + Y - K) (eqs 20, 35: what the joint
    transmits to its outward system), with its free components removed: its components on the
    constrained axes Gamma_c, Delta_c, the orthonormal complements of the joint axes, so this
    is an orthogonal projection. Gravity counts as an applied force; the joint forces tau are
    the free components that are removed.

    Args:
        model: the tree.
        q: configuration, shape (nq,).
        v: generalized velocity, shape (nv,).
        a: generalized acceleration, shape (nv,) (e.g. from `mbjax.forward_dynamics`).

    Returns:
        One wrench per joint, shape (n, 6): (torque about the hinge [N m]; force [N]), ground
            (world) frame components.
    """
    terms = operator_terms(model, q, v)
    W = _reactions(terms, v, a)
    pad = (~model.v_mask).astype(q.dtype)
    gram = jnp.einsum("kaw,kax->kwx", terms.A_hat, terms.A_hat) + jax.vmap(jnp.diag)(pad)
    free = jnp.linalg.solve(gram, jnp.einsum("kaw,ka->kw", terms.A_hat, W)[..., None])[..., 0]
    return W - jnp.einsum("kaw,kw->ka", terms.A_hat, free)
