"""Models of rigid-body trees: `Model`, joint types, builders and the URDF loader."""

from mbjax.model.builders import chain, random_tree
from mbjax.model.joints import JOINT_TYPES
from mbjax.model.model import Model

__all__ = ["JOINT_TYPES", "Model", "chain", "random_tree"]
