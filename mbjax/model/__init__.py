"""Models of rigid-body trees: `Model`, joint types, builders, the URDF and MJCF loaders, the
plausibility checks (`ModelWarning`), joint limits and the peers' state layouts."""

from mbjax.model import checks, limits, states
from mbjax.model.builders import chain, random_tree
from mbjax.model.checks import ModelWarning
from mbjax.model.joints import JOINT_TYPES
from mbjax.model.mjcf import from_mujoco, load_mjcf
from mbjax.model.model import Model
from mbjax.model.urdf import load_urdf, to_urdf

__all__ = ["JOINT_TYPES", "Model", "ModelWarning", "chain", "checks", "from_mujoco", "limits",
           "load_mjcf", "load_urdf", "random_tree", "states", "to_urdf"]
