"""The composite-rigid-body algorithm: the mass matrix from the bodies' composite inertias
(Featherstone, Rigid Body Dynamics Algorithms §6.2), equal to Jerkovsky 1978 eq 55's
mu_hat_ff = A_hat_f^T A^T mu A A_hat_f without forming the operator's (n, 6, nv) blocks."""

import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.model import Model
from mbjax._src.rigid.kinematics import body_kinematics
from mbjax._src.tree import outward_sum


def coordinate_paths(model: Model) -> tuple[np.ndarray, np.ndarray]:
    """(path, outward), (nv, nv) NumPy masks: [r, c] is 1 where coordinate c's body is on the
    path of coordinate r's (its own included), and where it is strictly outward of it."""
    body = model.dof_body()
    path = model.topology.path_matrix()[np.ix_(body, body)]
    return path, path.T * (body[:, None] != body[None, :])


def assemble(model: Model, inner: Array) -> Array:
    """M from inner[r, c] = s_r^T Ic_r s_c: the entries on r's path, their transposes outward,
    the armature on the diagonal (also `rnea_derivatives.rnea_partials`' M)."""
    path, outward = coordinate_paths(model)
    return path * inner + outward * inner.T + jnp.diag(model.armature)


def composite_mass_matrix(model: Model, q: Array) -> Array:
    """M(q), (nv, nv): M[r, c] = s_r^T Ic_r s_c for coordinate c on the path of coordinate r's
    body (its own joint's included), and its transpose, with s the coordinates' world motion
    columns and Ic_r the spatial inertia of everything outward of r's body, itself included;
    the joints' armature on the diagonal."""
    kin = body_kinematics(model, q, jnp.zeros(model.nv, q.dtype))
    composite = outward_sum(model.topology, kin.I)                       # (n, 6, 6)
    s = jax.vmap(model.flat_v, in_axes=1, out_axes=1)(kin.S)             # (nv, 6)
    inner = jnp.einsum("ri,rij,cj->rc", s, composite[model.dof_body()], s)   # s_r^T Ic_r s_c
    return assemble(model, inner)
