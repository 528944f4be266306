"""The result of a simulation."""

import warnings

import equinox as eqx
from jax import Array

from mbjax._src.system.status import Flags, flags, WithStatus, accuracy_notes


class Solution(WithStatus):
    """The result of a simulation: states saved at times `ts`, qs[i] = q(ts[i]), vs[i] = v(ts[i]).

    Returned by `simulate` and `solve_reference`; under `jax.vmap` every field gains a leading
    batch axis. `ok` and `messages()` read the status.

    Args:
        ts: save times [s], shape (T,).
        qs: configurations, shape (T, nq).
        vs: velocity coordinates, shape (T, nv).
        status: the `Status` flags, one per solution (batched under vmap), as `Flags`: an
            integer array that prints in words.
        error: the estimated global error of the final state (largest component, in the
            state's units) where the run was asked for a tolerance (`simulate(..., rtol=,
            atol=)`), else NaN.
        drift: the largest relative drift of the system's invariants (its energy, its
            momenta: `mbjax/_src/system/invariants.py`) over the start and the states the rollout
            checks; NaN where it has none.
        resolution: the step times the motion's fastest rate, held over `SUSTAINED` steps,
            at its largest along the run (`step_ratio` in `mbjax/_src/system/accuracy.py`); above
            `RESOLUTION_LIMIT` (1) the steps do not resolve the motion.
        drifting: the index of the invariant that drifted most (-1 where none).
        flagged_at: the time [s] each `Status` flag (1, 2, 4, ... in order) was first raised,
            NaN where never, shape (8,).
        inaccurate_by: why the run is INACCURATE, a mask: 1 the resolution, 2 the drift, 4
            the error estimate.
        invariant_names: the names of the system's invariants (static).
        culprit: what first made the system's check flag a state (an index into
            culprit_names: a joint's limit, a singularity), -1 for none.
        culprit_names: the names culprit indexes (static; `AbstractSystem.culprit_names`).
    """

    ts: Array
    qs: Array
    vs: Array
    status: Flags = eqx.field(converter=flags)
    error: Array = float("nan")
    drift: Array = float("nan")
    resolution: Array = float("nan")
    drifting: Array = -1
    flagged_at: Array | None = None
    inaccurate_by: Array = 0
    invariant_names: tuple[str, ...] = eqx.field(static=True, default=())
    culprit: Array = -1
    culprit_names: tuple[str, ...] = eqx.field(static=True, default=())

    @property
    def us(self) -> Array:
        """Deprecated: the velocities are `vs` (`us` names controls, as in `mbjax.trajopt`)."""
        warnings.warn("Solution.us is renamed Solution.vs (the velocities; us names controls, as "
                      "in mbjax.trajopt)", DeprecationWarning, stacklevel=2)
        return self.vs

    def notes(self, i: int) -> dict:
        """What tripped each flag of the i-th run (`WithStatus.messages`)."""
        return accuracy_notes(self, i, self.flagged_at)
