"""The public dynamics of a tree: `forward_dynamics`, `inverse_dynamics`, `mass_matrix`.

`forward_dynamics(..., method=...)` runs either Anderson 1993's O(n) recursion ("recursive") or Jerkovsky
1978's transformation operator with a Cholesky solve ("dense", O(n^3)); "auto" picks the cheaper
for the model's size from the crossover measured by `mbjax bench rigid` (below it the dense form's
few array operations match the recursion's n sequential steps; above it O(n) wins, by 70x at
n = 300 in a loop).
"""

from functools import partial

import jax
from jax import Array

from mbjax._src import runtime
from mbjax._src.model import Model
from mbjax._src.rigid.aba import aba
from mbjax._src.rigid.adjoint import with_adjoint
from mbjax._src.rigid.batching import aba_vmappable
from mbjax._src.rigid.dense import dense_forward_dynamics
from mbjax._src.rigid.operator import mass_matrix as _mass_matrix
from mbjax._src.rigid.rnea import inverse_dynamics as _rnea

METHODS = ("auto", "recursive", "dense")

# Degrees of freedom from which method="auto" runs the recursion: the "crossover_nv_auto" of
# `mbjax bench rigid` (benchmarks/README.md; float64, 2-core x86_64 CPU), the first chain size
# from which the recursion is never more than 1.5x slower than the dense form in a jitted loop
# and faster at every batch size of jit(vmap(...)). Below it the two are within noise of each
# other (a few microseconds); from 15 on the recursion wins everywhere, by 70x at n = 300.
# Measured with XLA running loops kernel by kernel: where it compiles each loop as one kernel
# (`mbjax._src.runtime.hoisting`), the recursion wins at every size (a jitted 1000-step loop, us per
# evaluation, recursive against dense: n = 1 0.13 against 1.06, n = 4 0.75 against 5.4, n = 8
# 1.5 against 10.6; the dense form's Cholesky is a LAPACK call, which keeps its loop out).
CROSSOVER_NV = 5


def choose_method(model: Model) -> str:
    """What method="auto" runs for this model."""
    return "dense" if model.nv < CROSSOVER_NV and not runtime.hoisting() else "recursive"


def _check(model: Model, **arrays) -> None:
    sizes = {"q": (model.nq,), "q_dot": (model.nv,), "tau": (model.nv,), "q_ddot": (model.nv,),
             "f_ext": (model.n, 6)}
    for name, value in arrays.items():
        if name == "f_ext" and value is None:
            continue
        shape = getattr(value, "shape", None)
        if shape != sizes[name]:
            raise ValueError(f"{name} must have shape {sizes[name]} for this model "
                             f"(n = {model.n} bodies, nq = {model.nq}, nv = {model.nv}), got "
                             f"shape {shape}; use jax.vmap for batches")


@partial(jax.jit, static_argnames="method")
def forward_dynamics(model: Model, q: Array, q_dot: Array, tau: Array,
                     method: str = "auto", f_ext: Array | None = None) -> Array:
    """Joint accelerations at configuration q and velocity q_dot under joint forces tau, gravity
    and external wrenches.

    q_dot is the generalized velocity v (length nv): the joint rates for revolute, prismatic and
    universal joints, the body angular velocity (and origin velocity) for spherical and free ones.
    f_ext (n, 6), or None: one wrench per body, world-frame components (torque about the body's
    origin; force), as a force acting on the body at its origin.
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    _check(model, q=q, q_dot=q_dot, tau=tau, f_ext=f_ext)
    if method == "auto":
        method = choose_method(model)
    if method == "recursive":
        return recursive_forward_dynamics(model, q, q_dot, tau, f_ext)
    return dense_forward_dynamics(model, q, q_dot, tau, f_ext)


def _primal(model: Model, q: Array, v: Array, tau: Array, f_ext: Array | None) -> Array:
    if f_ext is None:                          # jax.vmap's fast routes (mbjax._src.rigid.batching)
        return aba_vmappable(model, q, v, tau)
    return aba(model, q, v, tau, f_ext)


# Anderson 1993's recursion, differentiated through the equations of motion (mbjax._src.rigid.adjoint):
# jax.grad of a 1000-step rollout of the 7-link chain costs 3x the rollout instead of 6x
recursive_forward_dynamics = with_adjoint(_primal)


@jax.jit
def inverse_dynamics(model: Model, q: Array, q_dot: Array, q_ddot: Array,
                     f_ext: Array | None = None) -> Array:
    """Joint forces that produce accelerations q_ddot at (q, q_dot) under gravity and external
    wrenches f_ext (as in `forward_dynamics`): the RNEA, O(n)."""
    _check(model, q=q, q_dot=q_dot, q_ddot=q_ddot, f_ext=f_ext)
    return _rnea(model, q, q_dot, q_ddot, f_ext)


@jax.jit
def mass_matrix(model: Model, q: Array) -> Array:
    """The generalized mass matrix mu_hat_ff (Jerkovsky 1978 eq 55), nv x nv."""
    _check(model, q=q)
    return _mass_matrix(model, q)
