"""How a closed system solves for its motion: the strategy `ClosedSystem` takes as `method=`.

Each method chooses the velocity state u that `simulate` integrates (the joint velocities v, the
momenta M v, or v with the constraint loads appended) and the equations that give u_dot; the
constraints themselves, the projection and the status checks are the closed system's.
"""

import abc

import equinox as eqx
from jax import Array


class AbstractLoopMethod(eqx.Module):
    """A loop-closure method (`Coupled`, `Momentum`, `Stabilized`), passed to `ClosedSystem` as
    `method=`.

    A subclass chooses the velocity state u (the defaults: u = v) and implements `acceleration`
    and `loads`; `ClosedSystem` calls these with its `Loops` (the tree and its closures).
    """

    def validate(self, tree) -> None:
        """Raise if this method cannot close loops on `tree` (nothing by default).

        Raises:
            TypeError: the method needs what the tree lacks (a symmetric mass matrix).
        """

    def velocity(self, loops, q: Array, u: Array) -> Array:
        """The joint velocities v, shape (nv,), in the state u (u itself by default)."""
        return u

    def with_velocity(self, loops, q: Array, u: Array, v: Array) -> Array:
        """u with its velocity part replaced by v, shape (nv,) (v by default)."""
        return v

    def initial_state(self, loops, q: Array, v: Array, t, consistent: bool) -> Array:
        """The state u for joint velocities v, shape (nv,) (v by default)."""
        return v

    def state_size(self, loops) -> int | None:
        """The length of u (the tree's nv by default; None where the tree does not say)."""
        return loops.tree.state_sizes()[1]

    @abc.abstractmethod
    def acceleration(self, loops, t: Array, q: Array, u: Array) -> Array:
        """u_dot, the shape of u.

        Args:
            loops: the tree and its closures.
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            u: the method's velocity state.
        """

    @abc.abstractmethod
    def loads(self, loops, t: Array, q: Array, u: Array) -> Array:
        """The constraint loads on the rows of A at (t, q, u), shape (m,) (arguments as
        `acceleration`)."""

    def multipliers(self, loops, t: Array, q: Array, u: Array) -> Array:
        """The Lagrange multipliers K_c of the rows of A at (t, q, u), shape (m,), whatever the
        method's own sign of `loads`: A^t K_c is the generalized constraint force (Jerkovsky
        1978 eq 93). `loads` by default (arguments as `acceleration`)."""
        return self.loads(loops, t, q, u)

    def solve(self, loops, t: Array, q: Array, u: Array) -> tuple[Array, Array]:
        """(`acceleration`, `multipliers`) at (t, q, u): a method that finds both in one solve
        (`Coupled`) returns them from it; the two calls by default."""
        return self.acceleration(loops, t, q, u), self.multipliers(loops, t, q, u)


def require_symmetric(method: str, tree) -> None:
    """The dense routes need M(q) v_dot + bias = 0 with a symmetric M."""
    if not tree.symmetric_dynamics:
        raise TypeError(f"{method} solves Jerkovsky 1978's multipliers with the symmetric mass matrix of "
                        f"M v_dot + bias = 0; {type(tree).__name__} has none (geometric stiffening "
                        "adds acceleration-dependent loads): close its loops with Stabilized()")
