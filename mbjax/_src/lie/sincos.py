"""Sine and cosine together, in float arithmetic XLA's CPU backend vectorizes.

XLA's CPU backend emits `jnp.sin` and `jnp.cos` of float64 as calls into the C library, one
element at a time; inside a loop it compiles as one kernel (`mbjax._src.runtime`) they cost more still,
and their cost depends on the argument. `sincos` computes both from one range reduction and two
polynomials, multiplies and adds only, which XLA fuses and vectorizes with the code around them;
in the batched forward dynamics the library calls were a large share of the time (see
benchmarks/README.md).

The method is Cephes' (S. L. Moshier, Methods and Programs for Mathematical Functions, 1989;
Cephes 2.8 `sin.c`): |x| is reduced by the nearest even multiple k of pi/4 in three parts
(DP1 + DP2 + DP3 = pi/4, DP1 and DP2 with trailing zero bits, so k DP1 and k DP2 are exact), to
z in [-pi/4, pi/4]; sin z = z + z^3 P(z^2) and cos z = 1 - z^2/2 + z^4 Q(z^2) with Cephes'
coefficients; the quadrant k/2 mod 4 picks and signs them. Relative error about 2e-16 for
|x| < 2^30 (Cephes' table); beyond that the reduction loses digits, so there (a whole array with
any |x| >= 2^30, or a non-finite x) `jnp.sin` and `jnp.cos` answer instead (a `lax.cond`, which
`jax.vmap` turns into running both). float32 and other dtypes go to `jnp.sin` and `jnp.cos`
directly. Derivatives are exact: d sin = cos dx, d cos = -sin dx, from the same pair.
"""

import jax
import jax.numpy as jnp
from jax import Array

# pi/4 in three parts (Cephes sin.c)
_DP1, _DP2, _DP3 = 7.85398125648498535156e-1, 3.77489470793079817668e-8, 2.69515142907905952645e-15
# sin z = z + z^3 P(z^2), cos z = 1 - z^2 / 2 + z^4 Q(z^2) on [-pi/4, pi/4], highest power first
_P = (1.58962301576546568060e-10, -2.50507477628578072866e-8, 2.75573136213857245213e-6,
      -1.98412698295895385996e-4, 8.33333333332211858878e-3, -1.66666666666666307295e-1)
_Q = (-1.13585365213876817300e-11, 2.08757008419747316778e-9, -2.75573141792967388112e-7,
      2.48015872888517045348e-5, -1.38888888888730564116e-3, 4.16666666666665929218e-2)
LIMIT = 2.0 ** 30        # the reduction is exact below this |x|


def _horner(coefficients, x):
    out = jnp.full_like(x, coefficients[0])
    for c in coefficients[1:]:      # unrolled: six multiply-adds
        out = out * x + c
    return out


def _polynomial(x: Array) -> tuple[Array, Array]:
    a = jnp.abs(x)
    k = jnp.floor(a * (4.0 / jnp.pi))
    k = k + jnp.mod(k, 2.0)                              # the nearest even octant
    z = ((a - k * _DP1) - k * _DP2) - k * _DP3           # in [-pi/4, pi/4]
    zz = z * z
    s = z + z * zz * _horner(_P, zz)
    c = 1.0 - 0.5 * zz + zz * zz * _horner(_Q, zz)
    quadrant = jnp.mod(0.5 * k, 4.0)                     # 0, 1, 2, 3
    odd, upper = jnp.mod(quadrant, 2.0) == 1.0, quadrant >= 2.0
    sin_a = jnp.where(odd, c, s) * jnp.where(upper, -1.0, 1.0)
    cos_a = jnp.where(odd, s, c) * jnp.where(upper ^ odd, -1.0, 1.0)
    return jnp.where(jnp.signbit(x), -sin_a, sin_a), cos_a


def _library(x: Array) -> tuple[Array, Array]:
    return jnp.sin(x), jnp.cos(x)


@jax.custom_jvp
@jax.jit
def sincos(x) -> tuple[Array, Array]:
    """Sine and cosine of x together, elementwise (see the module for the method).

    Args:
        x: angles [rad], any shape; float64 takes the polynomial route, other dtypes
            `jnp.sin` and `jnp.cos`.

    Returns:
        (sin x, cos x), each of x's shape and dtype.
    """
    x = jnp.asarray(x)
    if x.dtype != jnp.float64:
        return _library(x)
    fast = jnp.all(jnp.abs(x) < LIMIT)                  # False for inf and NaN too
    return jax.lax.cond(fast, _polynomial, _library, x)


@sincos.defjvp
def _sincos_jvp(primals, tangents):
    (x,), (dx,) = primals, tangents
    s, c = sincos(x)
    return (s, c), (c * dx, -s * dx)
