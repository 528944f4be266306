"""Time finite elements for rigid-body dynamics (Borri 1990): the body, elements and their
quadrature (`ExactQuadrature`, `ReducedQuadrature`), references as strategies
(`ConstantReference`, `ConstantVelocityReference`, a prescribed `Reference`),
the weak forms of Hamilton's law as strategies, time marching with `solve_tfe`, and linearized
stability by transition matrices (`mbjax.tfe.stability`)."""

from mbjax._src.tfe import stability as stability
from mbjax._src.tfe.body import Body as Body
from mbjax._src.tfe.elements import Element as Element
from mbjax._src.tfe.elements import AbstractQuadrature as AbstractQuadrature
from mbjax._src.tfe.elements import ExactQuadrature as ExactQuadrature
from mbjax._src.tfe.elements import ReducedQuadrature as ReducedQuadrature
from mbjax._src.tfe.reference import AbstractReference as AbstractReference
from mbjax._src.tfe.reference import ConstantReference as ConstantReference
from mbjax._src.tfe.reference import ConstantVelocityReference as ConstantVelocityReference
from mbjax._src.tfe.reference import Reference as Reference
from mbjax._src.tfe.form import AbstractForm as AbstractForm
from mbjax._src.tfe.primal import PrimalUnsymmetric as PrimalUnsymmetric
from mbjax._src.tfe.primal import PrimalSymmetric as PrimalSymmetric
from mbjax._src.tfe.mixed import Mixed as Mixed
from mbjax._src.tfe.mixed import MixedUnsymmetric as MixedUnsymmetric
from mbjax._src.tfe.three_field import ThreeField as ThreeField
from mbjax._src.tfe.solve import solve_tfe as solve_tfe
from mbjax._src.tfe.solve import initial_state as initial_state

__all__ = [
    "Body", "Element", "AbstractQuadrature", "ExactQuadrature", "ReducedQuadrature",
    "AbstractReference", "ConstantReference", "ConstantVelocityReference", "Reference",
    "AbstractForm", "PrimalUnsymmetric", "PrimalSymmetric", "Mixed",
    "MixedUnsymmetric", "ThreeField", "solve_tfe", "initial_state", "stability"
]
