"""How a tree's forward dynamics are computed: a strategy passed to `forward_dynamics`,
`TreeSystem` and `FlexibleSystem` (as integrators are passed to `simulate`).

`Recursive()` runs Anderson 1993's O(n) recursion (§2.3, eqs 51-86), `Dense()` forms the mass
matrix (Jerkovsky 1978 eq 74 for rigid trees, the Lagrangian for flexible ones) and solves it by
Cholesky, O(n^3); `Auto()` picks one of them from the number of velocity coordinates, once, when
the program is built.
"""

import abc

import equinox as eqx

from mbjax._src import runtime


class AbstractForwardDynamics(eqx.Module):
    """A route to the accelerations of a tree; `resolve(nv)` names the concrete one.

    Pass an instance (`Recursive()`, `Dense()`, `Auto()`) as `method=` to
    `mbjax.forward_dynamics`, `mbjax.rigid.TreeSystem` or `mbjax.flex.FlexibleSystem`; strings
    and classes are refused with a TypeError.
    """

    @abc.abstractmethod
    def resolve(self, nv: int) -> "Recursive | Dense":
        """The concrete route for a tree of `nv` velocity coordinates.

        Args:
            nv: the tree's number of velocity coordinates.

        Returns:
            `Recursive()` or `Dense()`.
        """


class Recursive(AbstractForwardDynamics):
    """Anderson 1993's O(n) recursion: one inward pass that triangularizes the mass matrix body
    by body and one outward pass for the accelerations (§2.3, eqs 51-86).

    Takes no arguments: `method=Recursive()`.
    """

    def resolve(self, nv: int) -> "Recursive":
        return self


class Dense(AbstractForwardDynamics):
    """The generalized mass matrix formed and factored by Cholesky (Jerkovsky 1978 eq 74 for rigid
    trees; the Lagrangian route of Anderson 1993 §2.2 for flexible ones), O(n^3).

    Takes no arguments: `method=Dense()`.
    """

    def resolve(self, nv: int) -> "Dense":
        return self


# Below this many velocity coordinates the dense form's few array operations beat the
# recursion's n sequential steps when XLA runs a loop kernel by kernel; where it compiles each
# loop as one kernel (the setting `import mbjax` makes, `mbjax._src.runtime`) the recursion wins
# at every size. The crossover is measured by `mbjax bench rigid` (benchmarks/README.md).
CROSSOVER_NV = 5


def _default_crossover() -> int:
    return 0 if runtime.HOISTING else CROSSOVER_NV


class Auto(AbstractForwardDynamics):
    """`Dense()` below `crossover_nv` velocity coordinates, `Recursive()` from there on.

    The choice is made once, when the program is traced, from the model's static size.

    Args:
        crossover_nv (int | None): the smallest tree, in velocity coordinates, run by the recursion.
            By default 0 where XLA compiles loops as one kernel (what `import mbjax` sets up), else
            5 (`CROSSOVER_NV`, the crossover found by `mbjax bench rigid`).
    """

    crossover_nv: int = eqx.field(static=True, default_factory=_default_crossover)

    def resolve(self, nv: int) -> "Recursive | Dense":
        return Dense() if nv < self.crossover_nv else Recursive()


def as_dynamics(method) -> AbstractForwardDynamics:
    """`method` checked to be a strategy instance, with an error that says what to pass."""
    if isinstance(method, AbstractForwardDynamics):
        return method
    hint = (f"; pass an instance, {method.__name__}()" if isinstance(method, type) else
            "; strings are gone: pass Recursive(), Dense() or Auto()" if isinstance(method, str)
            else "")
    raise TypeError(f"method must be mbjax.Recursive(), mbjax.Dense() or mbjax.Auto(), got "
                    f"{method!r}{hint}")
