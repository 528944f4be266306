"""The Carpal Wrist parallel robot (Canfield 1997): closed-form kinematics, forward and inverse
dynamics from an autodiff Lagrangian, an independent Newton-Euler route, and a `simulate`-ready
system."""

from mbjax._src.wrist.kinematics import (
    Pose as Pose,
    SingularityMeasures as SingularityMeasures,
    pose_error as pose_error,
    rotation_angle as rotation_angle,
)
from mbjax._src.wrist.model import CarpalWrist as CarpalWrist
from mbjax._src.wrist.system import WristSystem as WristSystem
from mbjax._src.wrist.torques import servo as servo
