"""Time finite elements for rigid-body dynamics (Borri 1990).

Elements and quadrature (`Element`), the body and its reference motion (`Body`, `Reference`),
the weak forms as residuals (`PrimalUnsymmetric`, `PrimalSymmetric`, `Mixed`, `MixedUnsymmetric`, `ThreeField`),
Newton per element with implicit-function-theorem gradients (`newton`), time marching
(`solve_tfe`, about references rebuilt per element or one prescribed `Reference`), linearized
stability by transition matrices (`mbjax._src.tfe.stability`) and the hand tangents of the paper
(`mbjax._src.tfe.tangents`) against which the autodiff ones are checked.
"""

from mbjax._src.tfe.body import Body
from mbjax._src.tfe.elements import QUADRATURES, Element, gauss_legendre, lagrange
from mbjax._src.tfe.form import AbstractForm
from mbjax._src.tfe.mixed import Mixed, MixedUnsymmetric
from mbjax._src.tfe.newton import NewtonInfo, newton
from mbjax._src.tfe.primal import PrimalSymmetric, PrimalUnsymmetric
from mbjax._src.tfe.reference import REFERENCES, Reference, make_reference
from mbjax._src.tfe.solve import State, TFESolution, element_map, initial_state, solve_tfe
from mbjax._src.tfe.three_field import ThreeField
from mbjax._src.tfe import stability, tangents

FORMS = {cls.name: cls for cls in (PrimalUnsymmetric, PrimalSymmetric, Mixed, MixedUnsymmetric, ThreeField)}

__all__ = [
    "AbstractForm", "Body", "Element", "FORMS", "Mixed", "MixedUnsymmetric", "NewtonInfo", "PrimalSymmetric",
    "PrimalUnsymmetric", "QUADRATURES", "REFERENCES", "Reference", "State", "TFESolution",
    "ThreeField", "element_map", "gauss_legendre", "initial_state", "lagrange",
    "make_reference", "newton", "solve_tfe", "stability", "tangents",
]
