"""Controls: callables (t, q, v) -> generalized forces that drive every system.

Every system (`RigidBody`, `TreeSystem`, `FlexibleSystem`, `ClosedSystem`, `WristSystem`) takes
`control=` one of these (or any callable, or a constant array) on its actuated velocity
coordinates, and `external=` a callable returning world-frame wrenches on its bodies. Controls are
equinox modules: their gains, knots and weights are differentiable and vmappable leaves, so
`jax.grad` of a rollout with respect to them is what trajectory optimisation and policy training
need.

- `Constant`, `Sum` (also `a + b`), `Saturated`, `Function` (any callable): `base`
- `ZeroOrderHold` (a history on the step grid), `SampleAndHold` (any law sampled per step): `hold`
- `CubicSpline` (optionally saturated): `spline`
- `PD` (gains, targets, feed-forward), `MLPPolicy`: `feedback`
"""

from mbjax._src.control.base import AbstractControl, Constant, Function, Saturated, Sum, as_control, saturate
from mbjax._src.control.feedback import PD, MLPPolicy
from mbjax._src.control.hold import SampleAndHold, ZeroOrderHold
from mbjax._src.control.spline import CubicSpline, bspline_basis

__all__ = ["PD", "AbstractControl", "Constant", "CubicSpline", "Function", "MLPPolicy",
           "SampleAndHold", "Saturated", "Sum", "ZeroOrderHold", "as_control", "bspline_basis",
           "saturate"]
