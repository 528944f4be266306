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

# largest block written out; larger ones loop over their columns (the written-out graph grows
# like w^3)
UNROLL = 6


def spd_solve(A: Array, b: Array, unroll: int = UNROLL) -> Array:
    """A^-1 b for a symmetric positive-definite A.

    A division for w = 1, Cholesky written out for w <= unroll, else `cholesky` and
    `cho_solve` (a loop over the columns, no LAPACK call).

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
        return cho_solve(cholesky(A), b)
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


# `cholesky` and `cho_solve` run their loops unrolled up to this size: a loop of a few steps
# costs more in launches (and in reverse mode, in saved carries) than its straight-line code
UNROLL_LOOP = 8


def cholesky(A: Array) -> Array:
    """The lower Cholesky factor L of symmetric positive-definite matrices, A = L L^T, by a loop
    over the columns (L[:, j] = (A[:, j] - L L[j]^T) / sqrt(.)), with no LAPACK call.

    Under `jax.vmap` a LAPACK factorization or triangular solve becomes one batched library call,
    which jaxlib 0.10.2 splits over XLA's CPU thread pool and waits for: two such calls at once
    on a two-thread pool wait for each other forever (benchmarks/README.md, the gaits' hang).
    This loop batches into elementwise operations instead. A zero pivot (a column of zeros, a
    constraint let go) gives a zero column, not NaN, so the solves below leave its unknowns 0.

    Args:
        A: symmetric positive-(semi)definite matrices, shape (..., n, n).

    Returns:
        L, lower triangular, shape (..., n, n).
    """
    n = A.shape[-1]
    index = jnp.arange(n)

    def column(j, L):
        c = jnp.take(A, j, axis=-1) - (L * jnp.take(L, j, axis=-2)[..., None, :]).sum(-1)
        pivot = jnp.take(c, j, axis=-1)[..., None]
        root = jnp.sqrt(jnp.where(pivot > 0, pivot, 1.0))
        col = jnp.where((index > j) & (pivot > 0), c / root, 0.0)
        col = jnp.where(index == j, jnp.where(pivot > 0, root, 0.0), col)
        return jax.lax.dynamic_update_index_in_dim(jnp.swapaxes(L, -1, -2), col, j, -2).swapaxes(-1, -2)

    return jax.lax.fori_loop(0, n, column, jnp.zeros_like(A), unroll=n <= UNROLL_LOOP)


def cho_solve(L: Array, b: Array) -> Array:
    """(L L^T)^-1 b from `cholesky`'s factor by forward and back substitution, a loop over the
    rows with no LAPACK call; unknowns of a zero pivot are 0 (the least-norm answer where a
    column of A was zero).

    Args:
        L: lower Cholesky factors, shape (..., n, n).
        b: right-hand sides, shape (..., n) or (..., n, k).

    Returns:
        The solution, b's shape.
    """
    if b.ndim < L.ndim:
        return cho_solve(L, b[..., None])[..., 0]
    n = L.shape[-1]
    diagonal = jnp.diagonal(L, axis1=-2, axis2=-1)[..., None]
    inverse = jnp.where(diagonal > 0, 1.0 / jnp.where(diagonal > 0, diagonal, 1.0), 0.0)

    def forward(i, y):
        row = jnp.take(L, i, axis=-2)[..., :, None]
        value = (jnp.take(b, i, axis=-2) - (row * y).sum(-2)) * jnp.take(inverse, i, axis=-2)
        return jax.lax.dynamic_update_index_in_dim(y, value, i, -2)

    def backward(k, x):
        i = n - 1 - k
        col = jnp.take(L, i, axis=-1)[..., :, None]
        value = (jnp.take(y, i, axis=-2) - (col * x).sum(-2)) * jnp.take(inverse, i, axis=-2)
        return jax.lax.dynamic_update_index_in_dim(x, value, i, -2)

    unroll = n <= UNROLL_LOOP
    y = jax.lax.fori_loop(0, n, forward, jnp.zeros_like(b), unroll=unroll)
    return jax.lax.fori_loop(0, n, backward, jnp.zeros_like(b), unroll=unroll)
