"""The result of a simulation."""

from jax import Array

from mbjax._src.system.status import WithStatus


class Solution(WithStatus):
    """The result of a simulation: states saved at times `ts`, qs[i] = q(ts[i]), us[i] = u(ts[i]).

    Returned by `simulate` and `solve_reference`; under `jax.vmap` every field gains a leading
    batch axis. `ok` and `messages()` read the status.

    Args:
        ts: save times [s], shape (T,).
        qs: configurations, shape (T, nq).
        us: velocity coordinates, shape (T, nv).
        status: an integer array of `Status` flags (one per solution; batched under vmap).
        error: the estimated global error of the final state (largest component, in the
            state's units) where the run was asked for a tolerance (`simulate(..., rtol=,
            atol=)`), else NaN.
        drift: with a tolerance, the largest relative drift of the system's invariants (its
            energy, its momenta: `mbjax._src.system.invariants`) over the saved states; NaN
            where it has none or no tolerance was asked.
    """

    ts: Array
    qs: Array
    us: Array
    status: Array
    error: Array = float("nan")
    drift: Array = float("nan")
