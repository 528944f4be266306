"""Flexible bodies (Anderson 1993): beam finite elements and Craig-Bampton modal reduction, the
modal body's coefficients and geometric stiffening (`geometric_stiffness`), flexible trees in the
O(n) recursion, a beam's deformed axis for pictures (`centreline`), and a geometrically nonlinear
ANCF beam as the independent reference (Anderson 1993's two flexible examples solved by it:
`mbjax.scenes.spin_up_beam.reference`, `mbjax.scenes.flexible_slider_crank.reference`)."""

from mbjax._src.flex.beam import Beam as Beam
from mbjax._src.flex.beam import geometric_stiffness as geometric_stiffness
from mbjax._src.flex.modal import ModalBasis as ModalBasis
from mbjax._src.flex.modal import craig_bampton as craig_bampton
from mbjax._src.flex.body import ModalBody as ModalBody
from mbjax._src.flex.builders import beam_body as beam_body
from mbjax._src.flex.model import FlexibleModel as FlexibleModel
from mbjax._src.flex.system import FlexibleSystem as FlexibleSystem
from mbjax._src.flex.dynamics import forward_dynamics as forward_dynamics
from mbjax._src.flex.ancf import AncfBeam as AncfBeam
from mbjax._src.flex.ancf import simulate_ancf as simulate_ancf
from mbjax._src.flex.points import centreline as centreline

__all__ = [
    "Beam", "geometric_stiffness", "ModalBasis", "craig_bampton", "ModalBody", "beam_body",
    "FlexibleModel", "FlexibleSystem", "forward_dynamics", "AncfBeam",
    "simulate_ancf", "centreline"
]
