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

from mbjax._src.control.base import (
    AbstractControl as AbstractControl,
    Constant as Constant,
    Function as Function,
    Saturated as Saturated,
    Sum as Sum,
    as_control as as_control,
    saturate as saturate,
)
from mbjax._src.control.feedback import PD as PD, MLPPolicy as MLPPolicy
from mbjax._src.control.hold import SampleAndHold as SampleAndHold, ZeroOrderHold as ZeroOrderHold
from mbjax._src.control.spline import CubicSpline as CubicSpline, bspline_basis as bspline_basis
