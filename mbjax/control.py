"""Controls: callables (t, q, v) -> generalized forces that drive every system (`control=`), and
external loads (`external=`). They are equinox modules, so their gains, knots and weights are
differentiable and vmappable leaves."""

from mbjax._src.control.base import AbstractControl as AbstractControl
from mbjax._src.control.base import Constant as Constant
from mbjax._src.control.base import Saturated as Saturated
from mbjax._src.control.base import Sum as Sum
from mbjax._src.control.hold import SampleAndHold as SampleAndHold
from mbjax._src.control.hold import ZeroOrderHold as ZeroOrderHold
from mbjax._src.control.spline import CubicSpline as CubicSpline
from mbjax._src.control.feedback import PD as PD
from mbjax._src.control.feedback import MLPPolicy as MLPPolicy

__all__ = [
    "AbstractControl", "Constant", "Saturated", "Sum", "SampleAndHold", "ZeroOrderHold",
    "CubicSpline", "PD", "MLPPolicy"
]
