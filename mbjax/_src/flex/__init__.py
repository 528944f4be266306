"""Flexible bodies (Anderson 1993): beam finite elements and Craig-Bampton modal reduction, the modal
body's time-invariant coefficients and geometric stiffening, flexible bodies in the O(n)
recursion, and a geometrically nonlinear ANCF beam as the independent reference."""

from mbjax._src.flex.aba import (
    flexible_aba as flexible_aba,
    flexible_aba_responses as flexible_aba_responses,
)
from mbjax._src.flex.ancf import (
    AncfBeam as AncfBeam,
    AncfSolution as AncfSolution,
    simulate_ancf as simulate_ancf,
    simulate_embedded as simulate_embedded,
    stable_step as stable_step,
)
from mbjax._src.flex.beam import (
    Beam as Beam,
    eigenmodes as eigenmodes,
    free_dofs as free_dofs,
    geometric_stiffness as geometric_stiffness,
)
from mbjax._src.flex.body import ModalBody as ModalBody
from mbjax._src.flex.builders import beam_body as beam_body
from mbjax._src.flex.kinematics import (
    flex_kinematics as flex_kinematics,
    body_and_marker_poses as body_and_marker_poses,
)
from mbjax._src.flex.lagrange import (
    lagrangian_forward_dynamics as lagrangian_forward_dynamics,
    energy as energy,
)
from mbjax._src.flex.modal import (
    ModalBasis as ModalBasis,
    craig_bampton as craig_bampton,
    reduced as reduced,
)
from mbjax._src.flex.model import FlexibleModel as FlexibleModel
from mbjax._src.flex.points import (
    MassPoints as MassPoints,
    centreline as centreline,
    mass_points as mass_points,
    node_shapes as node_shapes,
    shape_at as shape_at,
)
from mbjax._src.flex.references import (
    slider_crank_reference as slider_crank_reference,
    spin_up_beam_reference as spin_up_beam_reference,
    spin_up_theta as spin_up_theta,
)
from mbjax._src.flex.stiffening import (
    distal_stiffening as distal_stiffening,
    inertial_stiffening as inertial_stiffening,
)
from mbjax._src.flex.system import FlexibleSystem as FlexibleSystem
