"""The Carpal Wrist parallel robot (Canfield 1997): closed-form kinematics, forward and inverse
dynamics from an autodiff Lagrangian, an independent Newton-Euler route, and a `simulate`-ready
system."""

from mbjax.wrist.kinematics import Pose, SingularityMeasures, pose_error, rotation_angle
from mbjax.wrist.model import CarpalWrist
from mbjax.wrist.system import WristSystem
from mbjax.wrist.torques import servo

__all__ = ["CarpalWrist", "Pose", "SingularityMeasures", "WristSystem", "pose_error",
           "rotation_angle", "servo"]
