"""Models of rigid-body trees: `Model`, joint types, builders, the URDF and MJCF loaders, the
plausibility checks (`ModelWarning`), joint limits and the peers' state layouts."""

from mbjax._src.model import checks as checks, limits as limits, states as states
from mbjax._src.model.builders import chain as chain, random_tree as random_tree
from mbjax._src.model.checks import ModelWarning as ModelWarning
from mbjax._src.model.joints import JOINT_TYPES as JOINT_TYPES
from mbjax._src.model.mjcf import from_mujoco as from_mujoco, load_mjcf as load_mjcf
from mbjax._src.model.model import Model as Model
from mbjax._src.model.urdf import load_urdf as load_urdf, to_urdf as to_urdf
