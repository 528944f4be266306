"""`linear_map`: a function linear in one array argument, as a JAX primitive with its own batching
rule.

The derivative rule of `forward_dynamics` (`mbjax._src.rigid.adjoint`) applies linear maps to its
tangents: the RNEA's derivative along (dq, dv) and M(q)^-1. Applied to one vector, each is a few
O(n) passes over the tree; `jax.jacfwd` maps them over a basis of directions at one state, where
forming the map's matrix once and multiplying is several times cheaper (Carpentier and Mansard 2018
form the matrices, as Pinocchio's `computeABADerivatives` does). A rule cannot see how JAX will use
it (a jitted function's derivative is traced before it is batched), so the choice is left to the
batching rule of a primitive: a batch of x at one state goes to `batched`, anything else is the
passes mapped. The transpose (reverse mode) is JAX's transpose of the passes, O(n) from the
state alone, and the derivatives in the fixed arguments are JAX's own derivatives of `apply`, so
every order of differentiation stays exact.
"""

from collections.abc import Callable
from functools import partial

import jax
import jax.numpy as jnp
from jax import Array
from jax.extend.core import Primitive
from jax.interpreters import ad, batching, mlir


def linear_map(name: str, apply: Callable, batched: Callable) -> Callable:
    """f(fixed, x) = apply(fixed, x), linear in the array x (fixed: any pytree of arrays), whose
    batching rule computes batched(fixed, xs) for a batch xs (B, ...) of x at unbatched `fixed`."""

    def impl(*args, treedef):
        return apply(jax.tree.unflatten(treedef, args[:-1]), args[-1])

    def abstract(*avals, treedef):
        out = jax.eval_shape(partial(impl, treedef=treedef), *avals)
        return jax.core.ShapedArray(out.shape, out.dtype)

    def jvp(primals, tangents, *, treedef):
        *fixed, x = primals
        out = primitive.bind(*primals, treedef=treedef)
        # linear in x: its tangent is the map itself (a batch of them, the batched rule)
        tangent = (jnp.zeros(out.shape, out.dtype) if type(tangents[-1]) is ad.Zero
                   else primitive.bind(*fixed, tangents[-1], treedef=treedef))
        if any(type(t) is not ad.Zero for t in tangents[:-1]):
            moved = jax.jvp(lambda *f: impl(*f, x, treedef=treedef), tuple(fixed),
                            tuple(ad.instantiate_zeros(t) for t in tangents[:-1]))[1]
            tangent = tangent + moved
        return out, tangent

    def transpose(cotangent, *args, treedef):
        *fixed, x = args                                    # x is the undefined (linear) one
        if type(cotangent) is ad.Zero:
            return [None] * len(fixed) + [ad.Zero(x.aval)]
        _, pullback = jax.vjp(partial(impl, *fixed, treedef=treedef),
                              jnp.zeros(x.aval.shape, x.aval.dtype))
        return [None] * len(fixed) + list(pullback(cotangent))

    def batch(args, dims, *, treedef):
        if all(d is None for d in dims[:-1]):                # a batch of x at one point
            fixed = jax.tree.unflatten(treedef, args[:-1])
            return batched(fixed, jnp.moveaxis(args[-1], dims[-1], 0)), 0
        size = next(x.shape[d] for x, d in zip(args, dims, strict=True) if d is not None)
        return jax.vmap(partial(impl, treedef=treedef), in_axes=list(dims),
                        axis_size=size)(*args), 0

    primitive = Primitive(name)
    primitive.def_impl(impl)
    primitive.def_abstract_eval(abstract)
    ad.primitive_jvps[primitive] = jvp
    ad.primitive_transposes[primitive] = transpose
    batching.primitive_batchers[primitive] = batch
    mlir.register_lowering(primitive, mlir.lower_fun(impl, multiple_results=False))

    def f(fixed, x: Array) -> Array:
        leaves, treedef = jax.tree.flatten(fixed)
        return primitive.bind(*leaves, x, treedef=treedef)

    f.__doc__ = apply.__doc__
    return f
