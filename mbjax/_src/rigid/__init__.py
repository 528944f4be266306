"""Rigid-body dynamics: the single rigid body, and trees by Anderson 1993's O(n) recursion, the RNEA
and Jerkovsky 1978's transformation operator (velocity and momentum forms, constraint forces)."""

from mbjax._src.rigid.aba import aba
from mbjax._src.rigid.batched import batch_aba, batched_forward_dynamics
from mbjax._src.rigid.body import RigidBody
from mbjax._src.rigid.dense import constraint_forces, dense_forward_dynamics, joint_reactions
from mbjax._src.rigid.dynamics import (
    forward_dynamics,
    inverse_dynamics,
    mass_matrix,
)
from mbjax._src.rigid.frames import frame_jacobian, frame_names, frame_placement, frame_pose, frame_poses
from mbjax._src.rigid.energy import energy, kinetic_energy, potential_energy, spatial_momentum
from mbjax._src.rigid.kinematics import body_kinematics, forward_kinematics
from mbjax._src.rigid.momentum import (
    constraint_forces_momentum,
    momentum,
    momentum_rate,
    system_momenta,
    velocity_from_momentum,
)
from mbjax._src.rigid.operator import (
    inverse_operator,
    operator_terms,
    primitive_inverse_mass,
    transformation_operator,
)
from mbjax._src.rigid.rnea import joint_wrenches
from mbjax._src.rigid.system import BatchTreeSystem, MomentumSystem, TreeSystem
from mbjax._src.rigid.torque_free import torque_free_motion

__all__ = [
    "BatchTreeSystem", "MomentumSystem", "RigidBody", "TreeSystem", "aba", "batch_aba",
    "batched_forward_dynamics", "body_kinematics",
    "constraint_forces", "constraint_forces_momentum", "dense_forward_dynamics",
    "energy", "forward_dynamics", "forward_kinematics", "frame_jacobian", "frame_names",
    "frame_placement", "frame_pose", "frame_poses", "inverse_dynamics", "inverse_operator",
    "joint_reactions",
    "joint_wrenches", "kinetic_energy", "mass_matrix", "momentum", "momentum_rate",
    "operator_terms", "potential_energy", "primitive_inverse_mass", "spatial_momentum", "system_momenta",
    "torque_free_motion", "transformation_operator", "velocity_from_momentum",
]
