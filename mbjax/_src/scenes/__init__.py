"""Ready-made scenes used by the tests, the benchmarks, the notebooks and the `mbjax` CLI.

Each scene module has `build(...)` returning (system, q0, v0) and the scene's constants.
"""

from mbjax._src.scenes import heavy_top as heavy_top, torque_free_body as torque_free_body

TOLERANCE = {"rtol": 1e-3, "atol": 1e-4}
"""What the tour and the reproductions ask of a run unless a scene says otherwise, as
`simulate(..., **TOLERANCE)`: its final state to 1e-3 (relative) or 1e-4 (absolute) and its
invariants to 1e-3 (`simulate`'s rtol and atol); a run past it is reported INACCURATE, whatever
else it shows."""
