"""Models of rigid-body trees: `Model`, joint types, builders, the URDF and MJCF loaders, the
plausibility checks (`ModelWarning`), joint limits and the peers' state layouts."""

from mbjax._src.model import checks, limits, states
from mbjax._src.model.builders import chain, random_tree
from mbjax._src.model.checks import ModelWarning
from mbjax._src.model.joints import JOINT_TYPES
from mbjax._src.model.mjcf import from_mujoco, load_mjcf
from mbjax._src.model.model import Model
from mbjax._src.model.urdf import load_urdf, to_urdf

__all__ = ["JOINT_TYPES", "Model", "ModelWarning", "chain", "checks", "from_mujoco", "limits",
           "load_mjcf", "load_urdf", "random_tree", "states", "to_urdf"]
