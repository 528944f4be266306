"""Rigid-body dynamics: the single rigid body, and trees by Anderson 1993's O(n) recursion, the
RNEA and Jerkovsky 1978's transformation operator (velocity and momentum forms, constraint
forces), as functions of a `Model` and as systems for `simulate`."""

from mbjax._src.rigid.body import RigidBody as RigidBody
from mbjax._src.rigid.system import TreeSystem as TreeSystem
from mbjax._src.rigid.system import MomentumSystem as MomentumSystem
from mbjax._src.rigid.system import BatchTreeSystem as BatchTreeSystem
from mbjax._src.rigid.dynamics import forward_dynamics as forward_dynamics
from mbjax._src.rigid.dynamics import inverse_dynamics as inverse_dynamics
from mbjax._src.rigid.dynamics import mass_matrix as mass_matrix
from mbjax._src.rigid.batched import batched_forward_dynamics as batched_forward_dynamics
from mbjax._src.rigid.kinematics import forward_kinematics as forward_kinematics
from mbjax._src.rigid.frames import frame_pose as frame_pose
from mbjax._src.rigid.frames import frame_poses as frame_poses
from mbjax._src.rigid.frames import frame_jacobian as frame_jacobian
from mbjax._src.rigid.centre import center_of_mass as center_of_mass
from mbjax._src.rigid.energy import kinetic_energy as kinetic_energy
from mbjax._src.rigid.energy import potential_energy as potential_energy
from mbjax._src.rigid.operator import transformation_operator as transformation_operator
from mbjax._src.rigid.dense import constraint_forces as constraint_forces
from mbjax._src.rigid.torque_free import torque_free_motion as torque_free_motion

__all__ = [
    "RigidBody", "TreeSystem", "MomentumSystem", "BatchTreeSystem", "forward_dynamics",
    "inverse_dynamics", "mass_matrix", "batched_forward_dynamics", "forward_kinematics",
    "frame_pose", "frame_poses", "frame_jacobian", "center_of_mass", "kinetic_energy",
    "potential_energy", "transformation_operator", "constraint_forces", "torque_free_motion"
]
