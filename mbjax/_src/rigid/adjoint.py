"""Derivatives of the forward dynamics through the equations of motion, not through the recursion.

The accelerations u_dot = M^-1 (tau - h) of Anderson 1993's recursion (`aba`) are the root of the
inverse dynamics, RNEA(model, q, v, u_dot) = tau (`rnea`; Jerkovsky 1978 eq 55's mu_hat u_dot + h).
Differentiating that identity at the solved u_dot gives every derivative of the forward dynamics:

    M du_dot = dtau - d_RNEA/d(model, q, v, f_ext) . (dmodel, dq, dv, df_ext)

one JVP of the O(n) RNEA and one solve with the mass matrix. The solve reuses the recursion's own
elimination: step (ii)'s articulated inertias are a sparse L D L^T factorization of M (Anderson 1993
eqs 48-50; `aba.Factor`), so M^-1 b is two vector passes (`aba.solve`), a twentieth of a
recursion. Reverse mode transposes the rule: the adjoint lambda = M^-1 u_dot_bar (M is symmetric,
so the solve is its own transpose), then tau_bar = lambda and
(model, q, v, f_ext)_bar = -RNEA_VJP(lambda), the RNEA's reverse pass at the solved accelerations.
This is the analytic-derivative route of Carpentier and Mansard (RSS 2018, "Analytical
derivatives of rigid body dynamics algorithms") that Pinocchio takes. For trees of revolute,
prismatic, spherical and free joints with no external wrench, the RNEA's derivative in (q, v)
is written out (`rnea_derivatives`: two vector passes, which reverse mode runs the other way);
for universal joints, for the model's parameters and for the external wrenches it is JAX's own
derivative of the RNEA. Either is recomputed in the reverse pass (`jax.checkpoint`), so
`jax.grad` through a rollout keeps per step only (q, v, u_dot) and the factor, not every
intermediate of the recursion: recomputing them costs less than storing them. With each loop
compiled as one kernel (`mbjax._src.runtime`; the rule's passes hold no gather or scatter in
either direction, `mbjax._src.tree.take`), reverse mode through the adjoint rule costs about 3x
the forward pass, about half of what differentiating the recursion itself costs; see
benchmarks/README.md.

`with_adjoint(fd)` gives `fd` (any function computing the forward dynamics of a tree: `aba`, or
its vmappable form) this rule as a `jax.custom_jvp`. Its tangent, M^-1 (dtau - dRNEA . (dq, dv)),
is a `linear_map`: along one direction and in reverse mode (JAX transposes it) it is the
RNEA's two vector passes and the factor's two; for a batch of directions at one state
(`jax.jacfwd`, every step Jacobian of `mbjax.trajopt`) the RNEA's partial derivatives and M are
formed once (`rnea_derivatives.rnea_partials`) and M Cholesky-factorized, as Pinocchio's
`computeABADerivatives` does. Higher orders follow from JAX's own derivatives of the passes, and
agree with differentiating `aba` itself to rounding (tests/rigid/test_adjoint.py,
tests/rigid/test_aba_derivatives.py). A gradient with respect to a body's `inertia` is defined
up to its antisymmetric part (only symmetric inertias are meaningful); its symmetric part agrees.
"""

from collections.abc import Callable
from functools import partial

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.linalg import spd_solve
from mbjax._src.linear_map import linear_map
from mbjax._src.model import Model
from mbjax._src.rigid import rnea_derivatives
from mbjax._src.rigid.aba import aba_factored, mass_solve, solve
from mbjax._src.rigid.kinematics import increments_matrix
from mbjax._src.rigid.rnea import inverse_dynamics
from mbjax._src.rigid.tangents import instantiate, is_zero


def with_adjoint(fd: Callable) -> Callable:
    """`fd(model, q, v, tau, f_ext)` with the derivative rule of the module: its tangents come
    from the RNEA's JVP at the solved accelerations and a solve with M's articulated-body
    factor. Symbolic-zero tangents (an argument not differentiated) cost nothing."""

    @jax.custom_jvp
    def forward(model: Model, q: Array, v: Array, tau: Array, f_ext: Array | None) -> Array:
        return fd(model, q, v, tau, f_ext)

    def _jvp(primals, tangents):
        model, q, v, tau, f_ext = primals
        u_dot, factor = aba_factored(model, q, v, tau, f_ext)
        # the RNEA's JVP in the arguments that carry a tangent; the others are held fixed
        args, dargs = [model, q, v, f_ext], list(tangents[:3]) + [tangents[4]]
        live = [i for i, t in enumerate(dargs) if not is_zero(t)]

        def rnea(*moving):
            full = list(args)
            for i, x in zip(live, moving, strict=True):
                full[i] = x
            model_, q_, v_, f_ext_ = full
            return inverse_dynamics(model_, q_, v_, u_dot, f_ext_)

        rhs = tangents[3]
        rhs = jnp.zeros_like(u_dot) if is_zero(rhs) else rhs
        if f_ext is None and rnea_derivatives.applies(model) and {1, 2} & set(live):
            # the (q, v) directions written out (`rnea_derivatives`), the model's by autodiff
            dq, dv = (instantiate(t, x) for t, x in ((dargs[1], q), (dargs[2], v)))
            dqv, live = jnp.concatenate([dq, dv]), [i for i in live if i not in (1, 2)]
        else:
            dqv = None
        if live:
            _, d_rnea = jax.jvp(jax.checkpoint(rnea), [args[i] for i in live],
                                [instantiate(dargs[i], args[i]) for i in live])
            rhs = rhs - d_rnea
        if dqv is None:
            return u_dot, mass_solve(model, factor, rhs)
        return u_dot, _fd_tangent((model, q, v, u_dot, factor), jnp.concatenate([dqv, rhs]))

    forward.defjvp(_jvp, symbolic_zeros=True)
    return forward


def _tangent(fixed: tuple, x: Array) -> Array:
    """The accelerations' tangent M^-1 (dtau - d RNEA / d(q, v) . (dq, dv)) for x = (dq, dv,
    dtau), at the solved accelerations: the RNEA's two vector passes and the factor's two."""
    model, q, v, u_dot, factor = fixed
    dq, dv, dtau = jnp.split(x, [model.nq, model.nq + model.nv])
    return solve(model, factor, dtau - rnea_derivatives.rnea_jvp(model, q, v, u_dot, dq, dv))


def _tangents(fixed: tuple, xs: Array) -> Array:
    """`_tangent` for a batch xs (B, nq + 2 nv) at one state (`jax.jacfwd`): from a few
    directions on, the RNEA's partial derivatives and M once (`rnea_partials`), one Cholesky
    factorization of M and a solve, as Pinocchio's `computeABADerivatives` forms them; the passes
    per direction below."""
    model, q, v, u_dot, _ = fixed
    if xs.shape[0] < DENSE_FROM:
        return jax.vmap(partial(_tangent, fixed))(xs)
    D_e, D_v, M = rnea_derivatives.rnea_partials(model, q, v, u_dot)
    D_q = D_e @ increments_matrix(model, q, v)                         # per coordinate of q
    dq, dv, dtau = jnp.split(xs, [model.nq, model.nq + model.nv], axis=1)
    rhs = dtau - dq @ D_q.T - dv @ D_v.T
    # M^-1 formed, then a product: XLA would fuse a solve of the right-hand sides into what
    # consumes it, each output column re-running the written-out substitutions (a step
    # Jacobian's 2 nv columns; benchmarks/README.md, speed)
    return rhs @ spd_solve(M, jnp.eye(model.nv, dtype=M.dtype), unroll=WRITTEN_OUT)


# directions from which the matrices beat the passes: for the 7-link chain `rnea_partials` costs
# 4.1 us, one direction's `rnea_jvp` 1.9 us and its solve 0.3 us (in a loop, 2026-11-27)
DENSE_FROM = 4
# M's Cholesky written out up to this size (`linalg.spd_solve`), so that a loop holding the
# derivatives (`jax.jacfwd` through a rollout) still compiles as one kernel; LAPACK's beyond
WRITTEN_OUT = 16
_fd_tangent = linear_map("forward_dynamics_tangent", _tangent, _tangents)
