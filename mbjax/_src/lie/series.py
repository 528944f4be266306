"""Even functions of the rotation angle that are exact, and exactly differentiable, at phi = 0.

The coefficients of exp, Gamma and Gamma^-1 (Borri 1990 eqs A.3, A.17, A.21, A.23) are ratios such
as (phi - sin phi) / phi^3 that lose all precision by cancellation near phi = 0 and are 0/0 at it.
Each is an even function of phi, so it is evaluated as a function of phi2 = r . r: the closed form
away from zero, its power series in phi2 below a cut-off. The closed form is fed a harmless phi2
on the branch it does not own (the "double where"), so neither branch ever produces inf or NaN
and forward and reverse derivatives of every order are finite at exactly r = 0.
"""

from collections.abc import Callable
from math import factorial

import jax.numpy as jnp
from jax import Array

# Below phi = 0.5 the series are used. With eight terms their truncation error is below 1e-18
# there, while the closed forms' cancellation error (about eps / phi^2) stays below 1e-15.
CUTOFF_PHI2 = 0.25
N_TERMS = 8


def even_series(phi2: Array, closed_form: Callable[[Array], Array], coefficients,
                cutoff: float = CUTOFF_PHI2) -> Array:
    """Evaluate f(phi) = closed_form(phi2) = sum_k coefficients[k] * phi2**k, safely near 0."""
    small = phi2 < cutoff
    safe_phi2 = jnp.where(small, cutoff, phi2)
    series = jnp.zeros_like(phi2)
    for c in reversed(coefficients):  # Horner; a fixed 8-term polynomial, not a loop over data
        series = series * phi2 + c
    return jnp.where(small, series, closed_form(safe_phi2))


def taylor(term: Callable[[int], float], n: int = N_TERMS) -> tuple[float, ...]:
    """The first n coefficients k -> term(k) of a power series in phi2."""
    return tuple(term(k) for k in range(n))


# sin(phi) / phi = sum (-1)^k phi^2k / (2k+1)!                                 (a_o, eq A.23)
SIN_PHI_OVER_PHI = taylor(lambda k: (-1) ** k / factorial(2 * k + 1))
# (1 - cos phi) / phi^2 = sum (-1)^k phi^2k / (2k+2)!                          (a_1, eq A.23)
ONE_MINUS_COS_OVER_PHI2 = taylor(lambda k: (-1) ** k / factorial(2 * k + 2))
# (phi - sin phi) / phi^3 = sum (-1)^k phi^2k / (2k+3)!                        (b_1, eq A.23)
PHI_MINUS_SIN_OVER_PHI3 = taylor(lambda k: (-1) ** k / factorial(2 * k + 3))
# cos(phi / 2) = sum (-1)^k (phi/2)^2k / (2k)!
COS_HALF = taylor(lambda k: (-1) ** k / (4 ** k * factorial(2 * k)))
# sin(phi / 2) / phi = sum (-1)^k phi^2k / (2^(2k+1) (2k+1)!)
SIN_HALF_OVER_PHI = taylor(lambda k: (-1) ** k / (2 ** (2 * k + 1) * factorial(2 * k + 1)))
# (1 - (phi/2) cot(phi/2)) / phi^2 = sum_k |B_2k+2| phi^2k / (2k+2)!, B the Bernoulli numbers
# (coefficient of (r x I)^2 in Gamma^-1, eq A.21).
_BERNOULLI_ABS = (1 / 6, 1 / 30, 1 / 42, 1 / 30, 5 / 66, 691 / 2730, 7 / 6, 3617 / 510)
GAMMA_INV_COEFF = taylor(lambda k: _BERNOULLI_ABS[k] / factorial(2 * k + 2))
