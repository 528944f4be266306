"""Rigid-body dynamics: the single rigid body, and trees by Anderson 1993's O(n) recursion, the RNEA
and Jerkovsky 1978's transformation operator (velocity and momentum forms, constraint forces)."""

from mbjax._src.rigid.aba import aba as aba
from mbjax._src.rigid.batched import (
    batch_aba as batch_aba,
    batched_forward_dynamics as batched_forward_dynamics,
)
from mbjax._src.rigid.body import RigidBody as RigidBody
from mbjax._src.rigid.dense import (
    constraint_forces as constraint_forces,
    dense_forward_dynamics as dense_forward_dynamics,
    joint_reactions as joint_reactions,
)
from mbjax._src.rigid.dynamics import (
    forward_dynamics as forward_dynamics,
    inverse_dynamics as inverse_dynamics,
    mass_matrix as mass_matrix,
)
from mbjax._src.rigid.frames import (
    frame_jacobian as frame_jacobian,
    frame_names as frame_names,
    frame_placement as frame_placement,
    frame_pose as frame_pose,
    frame_poses as frame_poses,
)
from mbjax._src.rigid.energy import (
    energy as energy,
    kinetic_energy as kinetic_energy,
    potential_energy as potential_energy,
    spatial_momentum as spatial_momentum,
)
from mbjax._src.rigid.kinematics import (
    body_kinematics as body_kinematics,
    forward_kinematics as forward_kinematics,
)
from mbjax._src.rigid.momentum import (
    constraint_forces_momentum as constraint_forces_momentum,
    momentum as momentum,
    momentum_rate as momentum_rate,
    system_momenta as system_momenta,
    velocity_from_momentum as velocity_from_momentum,
)
from mbjax._src.rigid.operator import (
    inverse_operator as inverse_operator,
    operator_terms as operator_terms,
    primitive_inverse_mass as primitive_inverse_mass,
    transformation_operator as transformation_operator,
)
from mbjax._src.rigid.rnea import joint_wrenches as joint_wrenches
from mbjax._src.rigid.system import (
    BatchTreeSystem as BatchTreeSystem,
    MomentumSystem as MomentumSystem,
    TreeSystem as TreeSystem,
)
from mbjax._src.rigid.torque_free import torque_free_motion as torque_free_motion
