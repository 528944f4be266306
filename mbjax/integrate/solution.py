"""The result of a simulation and its status."""

import enum

import equinox as eqx
import numpy as np
from jax import Array


class Status(enum.IntFlag):
    """Flags OR-ed into `Solution.status`; 0 means success."""

    SUCCESS = 0
    NONFINITE = 1          # a state became inf or NaN (the step is beyond the method's stability)
    NOT_CONVERGED = 2      # an implicit step's Newton iteration missed its tolerance
    SOLVER_FAILED = 4      # the adaptive reference solver stopped (step-size underflow, max_steps)


class WithStatus(eqx.Module):
    """A result carrying an integer `status` array of `Status` flags (one per run; batched under
    vmap)."""

    @property
    def ok(self) -> Array:
        """True where the run succeeded."""
        return self.status == 0

    def messages(self) -> list[str]:
        """Human-readable status for each (possibly batched) run; needs concrete values."""
        out = []
        for code in np.atleast_1d(np.asarray(self.status)).ravel():
            flags = [f.name.lower().replace("_", " ") for f in Status if f and Status(int(code)) & f]
            out.append(", ".join(flags) if flags else "success")
        return out


class Solution(WithStatus):
    """States saved at times `ts`: `qs[i]`, `us[i]` are q(ts[i]), u(ts[i]).

    `status` is an integer array of `Status` flags (one per solution; batched under vmap).
    """

    ts: Array
    qs: Array
    us: Array
    status: Array
