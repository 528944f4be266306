"""Models of rigid-body trees: `Model` (its `Topology`: Jerkovsky 1978's path and reference
matrices), its collision geometry (`Geoms`), builders, the URDF and MJCF loaders, the plausibility warning and the peers' state
layouts."""

from mbjax._src.model.model import Model as Model
from mbjax._src.model.geoms import Geoms as Geoms
from mbjax._src.model.geoms import ground_plane as ground_plane
from mbjax._src.tree.topology import Topology as Topology
from mbjax._src.model.checks import ModelWarning as ModelWarning
from mbjax._src.model.builders import chain as chain
from mbjax._src.model.builders import random_tree as random_tree
from mbjax._src.model.urdf import load_urdf as load_urdf
from mbjax._src.model.urdf import to_urdf as to_urdf
from mbjax._src.model.siblings import AbstractSiblingOrder as AbstractSiblingOrder
from mbjax._src.model.siblings import ByName as ByName
from mbjax._src.model.siblings import InDocument as InDocument
from mbjax._src.model.mjcf import load_mjcf as load_mjcf
from mbjax._src.model.mjcf import from_mujoco as from_mujoco
from mbjax._src.model.states import state_from_mujoco as state_from_mujoco
from mbjax._src.model.states import state_from_pinocchio as state_from_pinocchio
from mbjax._src.model.states import state_to_mujoco as state_to_mujoco
from mbjax._src.model.states import state_to_pinocchio as state_to_pinocchio

__all__ = [
    "Model", "Geoms", "ground_plane", "Topology", "ModelWarning", "chain", "random_tree", "load_urdf", "to_urdf",
    "AbstractSiblingOrder", "ByName", "InDocument",
    "load_mjcf", "from_mujoco", "state_from_mujoco", "state_from_pinocchio", "state_to_mujoco",
    "state_to_pinocchio"
]
