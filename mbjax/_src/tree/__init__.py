"""Tree topology (Jerkovsky 1978 §II, Anderson 1993 §2.1) and the tree passes every algorithm runs on."""

from mbjax._src.tree.passes import (
    backward_pass as backward_pass,
    forward_pass as forward_pass,
    outward_sum as outward_sum,
    path_sum as path_sum,
)
from mbjax._src.tree.topology import Topology as Topology
