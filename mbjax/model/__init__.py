"""Models of rigid-body trees: `Model`, joint types, builders and the URDF loader."""

from mbjax.model.builders import chain, random_tree
from mbjax.model.joints import JOINT_TYPES
from mbjax.model.model import Model, check_inertia

__all__ = ["JOINT_TYPES", "Model", "chain", "check_inertia", "random_tree"]
