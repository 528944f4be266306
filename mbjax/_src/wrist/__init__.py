"""The Carpal Wrist parallel robot (Canfield 1997): closed-form kinematics, forward and inverse
dynamics from an autodiff Lagrangian, an independent Newton-Euler route, and a `simulate`-ready
system."""

from mbjax._src.wrist.kinematics import Pose, SingularityMeasures, pose_error, rotation_angle
from mbjax._src.wrist.model import CarpalWrist
from mbjax._src.wrist.system import WristSystem
from mbjax._src.wrist.torques import servo

__all__ = ["CarpalWrist", "Pose", "SingularityMeasures", "WristSystem", "pose_error",
           "rotation_angle", "servo"]
