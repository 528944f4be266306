"""Time finite elements for rigid-body dynamics (Borri 1990).

Elements and quadrature (`Element`), the body and its reference motion (`Body`, `Reference`),
the weak forms as residuals (`PrimalUnsymmetric`, `PrimalSymmetric`, `Mixed`, `MixedUnsymmetric`, `ThreeField`),
Newton per element with implicit-function-theorem gradients (`newton`), time marching
(`solve_tfe`, about references rebuilt per element or one prescribed `Reference`), linearized
stability by transition matrices (`mbjax._src.tfe.stability`) and the hand tangents of the paper
(`mbjax._src.tfe.tangents`) against which the autodiff ones are checked.
"""

from mbjax._src.tfe.body import Body as Body
from mbjax._src.tfe.elements import (
    QUADRATURES as QUADRATURES,
    Element as Element,
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
    REFERENCES as REFERENCES,
    Reference as Reference,
    make_reference as make_reference,
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
