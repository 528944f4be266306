"""Flexible bodies (Anderson 1993): beam finite elements and Craig-Bampton modal reduction, the modal
body's time-invariant coefficients and geometric stiffening, flexible bodies in the O(n)
recursion, and a geometrically nonlinear ANCF beam as the independent reference."""

from mbjax._src.flex.aba import flexible_aba, flexible_aba_responses
from mbjax._src.flex.ancf import AncfBeam, AncfSolution, simulate_ancf, simulate_embedded, stable_step
from mbjax._src.flex.beam import Beam, eigenmodes, free_dofs, geometric_stiffness
from mbjax._src.flex.body import ModalBody
from mbjax._src.flex.builders import beam_body
from mbjax._src.flex.kinematics import flex_kinematics, body_and_marker_poses
from mbjax._src.flex.lagrange import lagrangian_forward_dynamics, energy
from mbjax._src.flex.modal import ModalBasis, craig_bampton, reduced
from mbjax._src.flex.model import FlexibleModel
from mbjax._src.flex.points import MassPoints, centreline, mass_points, node_shapes, shape_at
from mbjax._src.flex.references import slider_crank_reference, spin_up_beam_reference, spin_up_theta
from mbjax._src.flex.stiffening import distal_stiffening, inertial_stiffening
from mbjax._src.flex.system import FlexibleSystem

__all__ = ["AncfBeam", "AncfSolution", "Beam", "FlexibleModel", "FlexibleSystem", "MassPoints",
           "ModalBasis", "ModalBody", "beam_body", "centreline", "craig_bampton", "lagrangian_forward_dynamics",
           "distal_stiffening", "eigenmodes", "energy", "flex_kinematics", "flexible_aba",
           "flexible_aba_responses", "body_and_marker_poses", "free_dofs", "geometric_stiffness",
           "inertial_stiffening", "mass_points", "node_shapes", "reduced", "shape_at",
           "simulate_ancf", "simulate_embedded", "slider_crank_reference", "spin_up_beam_reference", "spin_up_theta",
           "stable_step"]
