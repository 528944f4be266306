"""Ready-made scenes used by the tests, the benchmarks, the notebooks and the `mbjax` CLI.

Each scene module has `build(...)` returning (system, q0, u0) and the scene's constants.
"""

from mbjax.scenes import heavy_top, torque_free_body

__all__ = ["heavy_top", "torque_free_body"]
