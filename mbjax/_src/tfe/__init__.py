"""Time finite elements for rigid-body dynamics (Borri 1990).

Elements and their quadrature (`Element`; `ExactQuadrature`, `ReducedQuadrature`), the body and
its reference motion (`Body`; `ConstantReference`, `ConstantVelocityReference`, `Reference`),
the weak forms as residuals (`PrimalUnsymmetric`, `PrimalSymmetric`, `Mixed`, `MixedUnsymmetric`, `ThreeField`),
Newton per element with implicit-function-theorem gradients (`newton`), time marching
(`solve_tfe`, about references rebuilt per element or one prescribed `Reference`), linearized
stability by transition matrices (`mbjax._src.tfe.stability`) and the hand tangents of the paper
(`mbjax._src.tfe.tangents`) against which the autodiff ones are checked.
"""

from mbjax._src.tfe.body import Body as Body
from mbjax._src.tfe.elements import (
    AbstractQuadrature as AbstractQuadrature,
    Element as Element,
    ExactQuadrature as ExactQuadrature,
    ReducedQuadrature as ReducedQuadrature,
    gauss_legendre as gauss_legendre,
    lagrange as lagrange,
)
from mbjax._src.tfe.form import AbstractForm as AbstractForm
from mbjax._src.tfe.mixed import Mixed as Mixed, MixedUnsymmetric as MixedUnsymmetric
from mbjax._src.tfe.newton import NewtonInfo as NewtonInfo, newton as newton
from mbjax._src.tfe.primal import (
    PrimalSymmetric as PrimalSymmetric,
    PrimalUnsymmetric as PrimalUnsymmetric,
)
from mbjax._src.tfe.reference import (
    AbstractReference as AbstractReference,
    ConstantReference as ConstantReference,
    ConstantVelocityReference as ConstantVelocityReference,
    Reference as Reference,
)
from mbjax._src.tfe.solve import (
    State as State,
    TFESolution as TFESolution,
    element_map as element_map,
    initial_state as initial_state,
    solve_tfe as solve_tfe,
)
from mbjax._src.tfe.three_field import ThreeField as ThreeField
from mbjax._src.tfe import stability as stability, tangents as tangents

FORMS = {cls.name: cls for cls in (PrimalUnsymmetric, PrimalSymmetric, Mixed, MixedUnsymmetric, ThreeField)}
