"""Rigid-body dynamics: the single rigid body and its closed-form references."""

from mbjax.rigid.body import RigidBody
from mbjax.rigid.torque_free import torque_free_motion

__all__ = ["RigidBody", "torque_free_motion"]
