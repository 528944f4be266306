"""Models of rigid-body trees: `Model`, joint types, builders, the URDF and MJCF loaders, the
plausibility checks (`ModelWarning`), joint limits and the peers' state layouts."""

from mbjax.model import checks, limits, states
from mbjax.model.builders import chain, random_tree
from mbjax.model.checks import ModelWarning
from mbjax.model.joints import JOINT_TYPES
from mbjax.model.model import Model

__all__ = ["JOINT_TYPES", "Model", "ModelWarning", "chain", "checks", "limits", "random_tree",
           "states"]
