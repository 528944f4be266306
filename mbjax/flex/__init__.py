"""Flexible bodies (Anderson 1993): beam finite elements and Craig-Bampton modal reduction, the modal
body's time-invariant coefficients and geometric stiffening, flexible bodies in the O(n)
recursion, and a geometrically nonlinear ANCF beam as the independent reference."""

from mbjax.flex.aba import flexible_aba, flexible_aba_responses
from mbjax.flex.ancf import AncfBeam, AncfSolution, simulate as simulate_ancf, simulate_embedded, stable_step
from mbjax.flex.beam import Beam, eigenmodes, free_dofs, geometric_stiffness
from mbjax.flex.body import ModalBody
from mbjax.flex.builders import beam_body
from mbjax.flex.kinematics import flex_kinematics, frame_poses
from mbjax.flex.lagrange import dense_forward_dynamics, energy
from mbjax.flex.modal import ModalBasis, craig_bampton, reduced
from mbjax.flex.model import FlexibleModel
from mbjax.flex.points import MassPoints, centreline, mass_points, node_shapes, shape_at
from mbjax.flex.references import slider_crank_reference, spin_up_beam_reference, spin_up_theta
from mbjax.flex.stiffening import distal_stiffening, inertial_stiffening
from mbjax.flex.system import FlexibleSystem

__all__ = ["AncfBeam", "AncfSolution", "Beam", "FlexibleModel", "FlexibleSystem", "MassPoints",
           "ModalBasis", "ModalBody", "beam_body", "centreline", "craig_bampton", "dense_forward_dynamics",
           "distal_stiffening", "eigenmodes", "energy", "flex_kinematics", "flexible_aba",
           "flexible_aba_responses", "frame_poses", "free_dofs", "geometric_stiffness",
           "inertial_stiffening", "mass_points", "node_shapes", "reduced", "shape_at",
           "simulate_ancf", "simulate_embedded", "slider_crank_reference", "spin_up_beam_reference", "spin_up_theta",
           "stable_step"]
