"""Small dense linear algebra written out, so that loops holding it compile as one kernel.

A LAPACK solve (`jnp.linalg.solve`, `jax.scipy.linalg.cho_solve`) is a library call, which keeps
XLA from compiling the loop around it as one function of straight-line code (`mbjax._src.runtime`):
the loop then runs kernel by kernel. The blocks mbjax solves inside its loops are small (a joint's
D of Anderson 1993 eq 48, at most 6 x 6; the Carpal Wrist's 3 x 3 A of Canfield 1997 eq 6.21), and for
those Cholesky written out over the columns is a few dozen scalar operations that XLA fuses.
(The flexible recursion's joint blocks are not symmetric where geometric stiffening couples the
accelerations, so `mbjax._src.flex.aba` keeps a general solve.) Loops that hold such solves run
markedly faster this way; see benchmarks/README.md.
"""

import jax
import jax.numpy as jnp
from jax import Array

# largest block written out; larger ones go to LAPACK (the written-out graph grows like w^3)
UNROLL = 6


def spd_solve(A: Array, b: Array, unroll: int = UNROLL) -> Array:
    """A^-1 b for a symmetric positive-definite A.

    A division for w = 1, Cholesky written out for w <= unroll, else LAPACK's Cholesky.

    Args:
        A: symmetric positive-definite matrices, shape (..., w, w).
        b: right-hand sides, shape (..., w) or (..., w, k).
        unroll: the largest w whose Cholesky is written out.

    Returns:
        A^-1 b, b's shape; NaN where A is not positive definite.
    """
    w = A.shape[-1]
    if w == 1:
        return b / (A[..., 0] if b.ndim < A.ndim else A)
    if b.ndim < A.ndim:                          # a vector
        return spd_solve(A, b[..., None], unroll)[..., 0]
    if w > unroll:
        return jax.scipy.linalg.cho_solve(jax.scipy.linalg.cho_factor(A), b)
    L = [[None] * w for _ in range(w)]
    for j in range(w):                           # A = L L^T, column by column
        L[j][j] = jnp.sqrt(A[..., j, j] - sum(L[j][k] ** 2 for k in range(j)))
        for i in range(j + 1, w):
            L[i][j] = (A[..., i, j] - sum(L[i][k] * L[j][k] for k in range(j))) / L[j][j]
    y = [None] * w
    for i in range(w):                           # L y = b
        y[i] = (b[..., i, :] - sum(L[i][k][..., None] * y[k] for k in range(i))) / L[i][i][..., None]
    x = [None] * w
    for i in reversed(range(w)):                 # L^T x = y
        x[i] = (y[i] - sum(L[k][i][..., None] * x[k] for k in range(i + 1, w))) / L[i][i][..., None]
    return jnp.stack(x, -2)


# the largest product (rows x inner x columns) `small_dot` writes out elementwise: beyond it the
# broadcast intermediate stops fitting a loop compiled as one kernel (measured, 14 x 14 x 14 in,
# 21 x 21 x 21 out; see benchmarks/README.md)
SMALL_DOT = 14**3


def small_dot(a: Array, b: Array) -> Array:
    """a @ b for a matrix a (m, k) and a matrix or vector b (k, ...), as a broadcast product and
    a sum where it is at most `SMALL_DOT` multiplications: XLA's CPU backend emits a dot of more
    than 6 x 6 as a library call, which keeps a loop around it (the Riccati pass of
    `mbjax.trajopt.ILQR`) from compiling as one kernel, 4-6x slower per step at 8-14 columns."""
    columns = b.shape[1] if b.ndim == 2 else 1
    if a.shape[0] * a.shape[1] * columns > SMALL_DOT:
        return a @ b
    if b.ndim == 1:
        return (a * b).sum(-1)
    return (a[:, :, None] * b[None]).sum(1)


def unrolled_dot(a: Array, b: Array) -> Array:
    """a @ b over a short contraction (a spatial vector's 6 components, a joint's few columns),
    written as one broadcast product per contracted index and their sum.

    XLA's CPU backend runs a batch of small products (a 6 x 6 block per body, per state and per
    direction under `jax.vmap` and `jax.jacfwd`) as a batched `dot_general` several times slower
    than these elementwise products, which it fuses with their neighbours (benchmarks/README.md,
    speed: the derivatives' batched rules). `small_dot` is the form for one product of up to
    14 x 14 x 14 inside a loop compiled as one kernel (the Riccati pass); this one is for short
    contractions over batch axes.

    Args:
        a: matrices, shape (..., m, k), k small.
        b: matrices (..., k, n) or vectors (..., k), broadcasting with a's leading axes.

    Returns:
        a @ b, shape (..., m, n) or (..., m).
    """
    if b.ndim == a.ndim - 1:
        return sum(a[..., i] * b[..., i, None] for i in range(a.shape[-1]))
    return sum(a[..., :, i, None] * b[..., None, i, :] for i in range(a.shape[-1]))
