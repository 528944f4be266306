"""Ready-made scenes: the papers' mechanisms and the examples the tests, benchmarks, notebooks and
the `mbjax` command share. Each is a module with `build(...)` returning (system, q0, v0) and the
scene's constants; the two built for trajectory optimisation only, `acrobot` and `slewing_beam`,
have `model()` and a `Problem` builder instead. `TOLERANCE` is the accuracy the tour and the
reproductions ask of a run (`simulate(..., **TOLERANCE)`)."""

from mbjax._src.scenes import TOLERANCE as TOLERANCE
from mbjax._src.scenes import acrobot as acrobot
from mbjax._src.scenes import andrews_squeezer as andrews_squeezer
from mbjax._src.scenes import arm as arm
from mbjax._src.scenes import bricard as bricard
from mbjax._src.scenes import carpal_wrist as carpal_wrist
from mbjax._src.scenes import closed_chain as closed_chain
from mbjax._src.scenes import flexible_slider_crank as flexible_slider_crank
from mbjax._src.scenes import four_bar as four_bar
from mbjax._src.scenes import heavy_top as heavy_top
from mbjax._src.scenes import rigid_chain as rigid_chain
from mbjax._src.scenes import slewing_beam as slewing_beam
from mbjax._src.scenes import slider_crank as slider_crank
from mbjax._src.scenes import spin_up_beam as spin_up_beam
from mbjax._src.scenes import torque_free_body as torque_free_body
from mbjax._src.scenes import vertical_top as vertical_top

__all__ = [
    "TOLERANCE", "acrobot", "andrews_squeezer", "arm", "bricard", "carpal_wrist", "closed_chain",
    "flexible_slider_crank", "four_bar", "heavy_top", "rigid_chain", "slewing_beam", "slider_crank",
    "spin_up_beam", "torque_free_body", "vertical_top",
]
