"""The contact model solved each step: MuJoCo's convex soft constraints (`SoftConstraints`),
behind a strategy base (`AbstractContactModel`).

Why this formulation: it is the one MuJoCo and MJX users compare with, its parameters are the
MJCF's own (`solref`, `solimp`, `friction`, `impratio`), and it is a strictly convex
problem, so its solution is unique, continuous in the state and parameters, and its
derivative exists wherever the set of pushing constraint rows does not change (Todorov 2014,
"Convex and analytically-invertible dynamics with contacts and constraints"; MuJoCo's
documentation, Computation). A complementarity time-stepping (Stewart and Trinkle 1996) has
neither uniqueness nor a derivative at contact changes; a compliant spring-damper needs steps
small enough for its stiffness.
"""

import abc
import functools

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.linalg import cho_solve, cholesky

# MuJoCo's bounds on the impedance and its smallest value
MIN_IMPEDANCE, MAX_IMPEDANCE, MIN_VALUE = 1e-4, 0.9999, 1e-15
# the line search stops where the cost's slope is below this fraction of its slope at the start
LINE_TOLERANCE = 1e-3


class AbstractContactModel(eqx.Module):
    """How a `ContactSystem` turns its constraint rows into accelerations: a strategy passed
    to `ContactSystem(method=...)`."""

    @abc.abstractmethod
    def rows(self, jacobian: Array, position: Array, velocity: Array, invweight: Array,
             solref: Array, solimp: Array, frictional: Array,
             timestep: float) -> tuple[Array, Array]:
        """(D, aref): each row's weight and reference acceleration.

        Args:
            jacobian: the rows' Jacobians J, (m, nv).
            position: each row's distance past its margin (negative: violated), (m,).
            velocity: J v, (m,).
            invweight: each row's inverse inertia scale (MuJoCo's `invweight0`), (m,).
            solref, solimp: each row's parameters, (m, 2), (m, 5).
            frictional: whether each row is a friction cone's (a pyramid edge), (m,).
            timestep: the simulation's step [s].
        """

    @abc.abstractmethod
    def solve(self, mass: Array, free: Array, jacobian: Array, weight: Array,
              reference: Array) -> tuple[Array, Array]:
        """(a, forces): the accelerations and each row's force.

        Args:
            mass: M, (nv, nv).
            free: the unconstrained accelerations M^-1 (tau - bias), (nv,).
            jacobian: J, (m, nv).
            weight: D, (m,).
            reference: aref, (m,).
        """

    def converged(self, mass: Array, free: Array, jacobian: Array, weight: Array,
                  reference: Array) -> Array:
        """Whether `solve` met its tolerance at these arguments (a boolean scalar); True for a
        model solved in closed form (the default)."""
        return jnp.array(True)

    def resolved(self, solref: Array, timestep: float) -> Array:
        """Whether each row's transient spans at least two steps, (m,) booleans; True for a
        model without one (the default).

        Args:
            solref: each row's parameters, (m, 2).
            timestep: the simulation's step [s].
        """
        return jnp.ones(solref.shape[:-1], bool)


def impedance(solimp: Array, position: Array) -> Array:
    """MuJoCo's impedance d(r) in [dmin, dmax]: a sigmoid of |r| / width with midpoint `mid`
    and power `power` (MuJoCo's documentation, Solver parameters). Finite derivatives at r = 0
    and in every parameter."""
    dmin, dmax, width, mid, power = (solimp[..., i] for i in range(5))
    dmin = jnp.clip(dmin, MIN_IMPEDANCE, MAX_IMPEDANCE)
    dmax = jnp.clip(dmax, MIN_IMPEDANCE, MAX_IMPEDANCE)
    width = jnp.maximum(width, MIN_VALUE)
    mid = jnp.clip(mid, MIN_IMPEDANCE, MAX_IMPEDANCE)
    power = jnp.maximum(power, 1.0)
    x = jnp.abs(position) / width

    def pow_(base, exponent):                  # base ** exponent, 0 at base 0 with finite slope
        safe = jnp.where(base > 0, base, 1.0)
        return jnp.where(base > 0, jnp.exp(exponent * jnp.log(safe)), 0.0)

    rising = pow_(x, power) / pow_(mid, power - 1)
    falling = 1 - pow_(1 - jnp.minimum(x, 1.0), power) / pow_(1 - mid, power - 1)
    y = jnp.where(x < mid, rising, falling)
    return jnp.where(x >= 1.0, dmax, jnp.clip(dmin + y * (dmax - dmin), jnp.minimum(dmin, dmax),
                                               jnp.maximum(dmin, dmax)))


class SoftConstraints(AbstractContactModel):
    """MuJoCo's soft constraints: the accelerations minimize

    ```text
    1/2 (a - a0)^T M (a - a0) + 1/2 sum_i D_i min(J_i a - aref_i, 0)^2
    ```

    with a0 the unconstrained accelerations, one row per pyramid edge of a frictional contact
    (J_n + mu_k J_tk and J_n - mu_k J_tk), per frictionless contact or per joint limit, so that
    every row pushes only (a force -D (J a - aref) >= 0). The reference acceleration aref =
    -b J v - k d(r) r and the weight D = d / ((1 - d) invweight) come from `solref`
    (timeconst, dampratio: b = 2 / (dmax timeconst), k = 1 / (dmax^2 timeconst^2 dampratio^2);
    or -stiffness, -damping) and `solimp` (the impedance d(r) of the penetration r), as in
    MuJoCo (Todorov 2014; MuJoCo's documentation, Computation and Solver parameters). The
    problem is strictly convex and piecewise quadratic; Newton's method with an exact line
    search solves it (MuJoCo's Newton solver, pyramidal cones).

    The derivative of the solution is the implicit function theorem's at the rows that push
    (their set held): H da = -(d of the gradient along the parameters' and the state's
    tangents), H = M + J_A^T D_A J_A, the same factorization's matrix as the last Newton step.
    Where a row starts or stops pushing the solution is continuous but its derivative jumps;
    the derivative given there is the one on the side of the pushing set found.

    Args:
        iterations: the most Newton iterations (static).
        tolerance: stop when the cost improves by less than tolerance times its scale.
        impratio: MuJoCo's ratio of the frictional to the normal rows' impedance (1: the same).
        refsafe: keep the time constant at least two steps (MuJoCo's default).

    Raises:
        ValueError: iterations below 1, a nonpositive tolerance or impratio.
    """

    iterations: int = eqx.field(static=True, default=50)
    tolerance: float = eqx.field(static=True, default=1e-12)
    impratio: float = eqx.field(static=True, default=1.0)
    refsafe: bool = eqx.field(static=True, default=True)

    def __check_init__(self):
        if not (isinstance(self.iterations, int) and self.iterations >= 1):
            raise ValueError(f"iterations must be a positive int, got {self.iterations!r}")
        if not self.tolerance > 0:
            raise ValueError(f"tolerance must be positive, got {self.tolerance!r}")
        if not self.impratio > 0:
            raise ValueError(f"impratio must be positive, got {self.impratio!r}")

    def rows(self, jacobian, position, velocity, invweight, solref, solimp, frictional,
             timestep):
        timeconst, dampratio = solref[..., 0], solref[..., 1]
        if self.refsafe:
            timeconst = jnp.maximum(timeconst, 2 * timestep)
        dmax = jnp.clip(solimp[..., 1], MIN_IMPEDANCE, MAX_IMPEDANCE)
        direct = solref[..., 0] <= 0
        safe_tc = jnp.where(direct, 1.0, timeconst)
        safe_dr = jnp.where(direct, 1.0, dampratio)
        k = jnp.where(direct, -solref[..., 0] / dmax**2, 1 / (dmax * safe_tc * safe_dr) ** 2)
        b = jnp.where(solref[..., 1] <= 0, -solref[..., 1] / dmax, 2 / (dmax * safe_tc))
        d = impedance(solimp, position)
        invweight = jnp.where(frictional, invweight / self.impratio, invweight)
        r = jnp.maximum(invweight * (1 - d) / d, MIN_VALUE)
        pushing = position < 0
        aref = -b * velocity - k * d * jnp.where(pushing, position, 0.0)
        return jnp.where(pushing, 1 / r, 0.0), aref

    def solve(self, mass, free, jacobian, weight, reference):
        return _soft_solve(mass, free, jacobian, weight, reference, self.iterations,
                           self.tolerance)

    def converged(self, mass, free, jacobian, weight, reference):
        return jax.lax.stop_gradient(_newton(mass, free, jacobian, weight, reference,
                                             self.iterations, self.tolerance, True)[1])

    def resolved(self, solref, timestep):
        """A row's time constant is solref's timeconst (at least two steps with refsafe), or,
        for a direct (-stiffness, -damping) solref, the shorter of 1 / sqrt(stiffness) and
        2 / damping (the timeconst that MuJoCo's formulas would turn into that stiffness and
        damping); the bound is MuJoCo's refsafe: two steps."""
        direct = solref[..., 0] <= 0
        stiffness = jnp.where(direct, -solref[..., 0], 1.0)
        damping = jnp.where(solref[..., 1] < 0, -solref[..., 1], 0.0)
        scale = jnp.minimum(jnp.where(stiffness > 0, 1 / jnp.sqrt(stiffness), jnp.inf),
                            jnp.where(damping > 0, 2 / jnp.where(damping > 0, damping, 1.0),
                                      jnp.inf))
        timeconst = jnp.where(direct, scale, solref[..., 0])
        if self.refsafe:
            timeconst = jnp.where(direct, timeconst, jnp.maximum(timeconst, 2 * timestep))
        return timeconst >= 2 * timestep * (1 - 1e-9)


def _gradient(a, mass, free, jacobian, weight, reference, pushing):
    """The cost's gradient at a with the pushing rows held: M (a - a0) + J^T D (J a - aref)."""
    x = jacobian @ a - reference
    return mass @ (a - free) + jacobian.T @ (weight * pushing * x)


def _hessian(mass, jacobian, weight, pushing):
    return mass + jacobian.T @ ((weight * pushing)[:, None] * jacobian)


def _line_search(a, d, mass, free, jacobian, weight, reference):
    """The minimizer along d of the convex piecewise-quadratic cost: the root of its
    derivative, a nondecreasing piecewise-linear function of the step, by Newton's method on
    the current piece kept inside a bracket, until the derivative falls below LINE_TOLERANCE
    of its value at the start (MuJoCo's Newton line search and its `ls_tolerance`); the Newton
    iterations around it converge whatever the tolerance."""
    Md = mass @ d
    dMd, gM = d @ Md, (a - free) @ Md
    x0, jd = jacobian @ a - reference, jacobian @ d

    def slope(alpha):
        x = x0 + alpha * jd
        on = weight * (x < 0)
        return gM + alpha * dMd + jnp.sum(on * x * jd), dMd + jnp.sum(on * jd * jd)

    enough = LINE_TOLERANCE * jnp.abs(slope(0.0)[0])          # of the slope at the start

    def body(state):
        alpha, lo, hi, _, i = state
        g, h = slope(alpha)
        lo, hi = jnp.where(g < 0, alpha, lo), jnp.where(g > 0, alpha, hi)
        step = alpha - g / jnp.maximum(h, MIN_VALUE)
        inside = (step > lo) & (step < hi)
        middle = jnp.where(jnp.isfinite(hi), 0.5 * (lo + hi), 2 * jnp.maximum(alpha, 1.0))
        small = jnp.abs(g) <= enough
        new = jnp.where(small, alpha, jnp.where(inside, step, middle))
        done = small | (jnp.abs(new - alpha) <= 1e-14 * jnp.maximum(1.0, jnp.abs(alpha)))
        return new, lo, hi, done, i + 1

    state = (jnp.ones_like(dMd), jnp.zeros_like(dMd), jnp.full_like(dMd, jnp.inf),
             jnp.array(False), 0)
    alpha = jax.lax.while_loop(lambda s: ~s[3] & (s[4] < 60), body, state)[0]
    return alpha


def _cost(a, mass, free, jacobian, weight, reference):
    x = jacobian @ a - reference
    return 0.5 * (a - free) @ mass @ (a - free) + 0.5 * jnp.sum(weight * jnp.minimum(x, 0.0) ** 2)


def _newton(mass, free, jacobian, weight, reference, iterations, tolerance, report=False):
    """The minimizer, by Newton's method with exact line searches from a0; with report, also
    whether it met the tolerance within the iterations."""
    scale = jnp.maximum(free @ mass @ free, 1.0)

    def body(state):
        a, cost, _, i = state
        pushing = (jacobian @ a - reference) < 0
        g = _gradient(a, mass, free, jacobian, weight, reference, pushing)
        d = -cho_solve(cholesky(_hessian(mass, jacobian, weight, pushing)), g)
        a = a + _line_search(a, d, mass, free, jacobian, weight, reference) * d
        new = _cost(a, mass, free, jacobian, weight, reference)
        return a, new, cost - new <= tolerance * scale, i + 1

    a0 = free
    state = (a0, _cost(a0, mass, free, jacobian, weight, reference), jnp.array(False), 0)
    a, _, done, _ = jax.lax.while_loop(lambda s: ~s[2] & (s[3] < iterations), body, state)
    return (a, done) if report else a


@functools.partial(jax.custom_jvp, nondiff_argnums=(5, 6))
def _solution(mass, free, jacobian, weight, reference, iterations, tolerance):
    return _newton(mass, free, jacobian, weight, reference, iterations, tolerance)


@_solution.defjvp
def _solution_jvp(iterations, tolerance, primals, tangents):
    mass, free, jacobian, weight, reference = primals
    a = _newton(mass, free, jacobian, weight, reference, iterations, tolerance)
    pushing = (jacobian @ a - reference) < 0
    _, dg = jax.jvp(lambda *theta: _gradient(a, *theta, pushing),
                    (mass, free, jacobian, weight, reference), tuple(tangents))
    H = _hessian(mass, jacobian, weight, pushing)
    return a, -cho_solve(cholesky(H), dg)


def _soft_solve(mass, free, jacobian, weight, reference, iterations, tolerance):
    a = _solution(mass, free, jacobian, weight, reference, iterations, tolerance)
    x = jacobian @ a - reference
    return a, -weight * jnp.minimum(x, 0.0)
