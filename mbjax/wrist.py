"""The Carpal Wrist parallel robot (Canfield 1997): closed-form kinematics, forward and inverse
dynamics from an autodiff Lagrangian, a `simulate`-ready system, and its trajectory synthesis
(§6): the minimum-jerk baseline, gradient synthesis of torque splines, a neural controller (its
gradient taken by `ForwardMode()` or `ReverseMode()`), and batches of wrists for
`mbjax.trajopt.sweep`."""

from mbjax._src.wrist.model import CarpalWrist as CarpalWrist
from mbjax._src.wrist.system import WristSystem as WristSystem
from mbjax._src.wrist.kinematics import Pose as Pose
from mbjax._src.wrist.kinematics import pose_error as pose_error
from mbjax._src.wrist.kinematics import rotation_angle as rotation_angle
from mbjax._src.wrist.torques import servo as servo
from mbjax._src.synthesis.baseline import ToolPath as ToolPath
from mbjax._src.synthesis.baseline import feedforward_torques as feedforward_torques
from mbjax._src.synthesis.synthesis import synthesize as synthesize
from mbjax._src.synthesis.controller import NeuralController as NeuralController
from mbjax._src.synthesis.controller import train_controller as train_controller
from mbjax._src.synthesis.controller import make_episodes as make_episodes
from mbjax._src.synthesis.controller import evaluate_controller as evaluate_controller
from mbjax._src.synthesis.descent import AbstractGradient as AbstractGradient
from mbjax._src.synthesis.descent import ForwardMode as ForwardMode
from mbjax._src.synthesis.descent import ReverseMode as ReverseMode
from mbjax._src.synthesis.sweeps import grid as grid
from mbjax._src.synthesis.sweeps import peak_torque as peak_torque

__all__ = [
    "CarpalWrist", "WristSystem", "Pose", "pose_error", "rotation_angle",
    "servo", "ToolPath", "feedforward_torques", "synthesize", "NeuralController", "train_controller", "make_episodes", "evaluate_controller", "grid",
    "peak_torque", "AbstractGradient", "ForwardMode", "ReverseMode"
]
