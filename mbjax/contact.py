"""Contacts with the ground (legged robots): a frame held on the ground is a closure with the
ground (Jerkovsky 1978 §VI), so a contact phase is a `mbjax.loops.ClosedSystem`:

    phase = stance(TreeSystem(model), q, [PointContact("LF_FOOT"), ...])

`contact_wrenches` gives the ground's reactions, `impulse` the velocity jump at touchdown,
`simulate_schedule` runs a robot through a sequence of phases (with `mu`, a foot that pulls or
slips fails the run: `Status.PULLING`, `Status.SLIPPING`).

Contacts that find themselves: `ContactSystem(TreeSystem(model))` detects contacts between the
model's geoms (`mbjax.model.Geoms`, kept by `load_mjcf`; `mbjax.model.ground_plane` adds a floor) each
step and holds its limited joints in their ranges, by MuJoCo's soft constraints
(`SoftConstraints`):

    system = ContactSystem(TreeSystem(mbjax.load_mjcf("ant.xml")), timestep=0.01)
"""

from mbjax._src.contact.contact import AbstractContact as AbstractContact
from mbjax._src.contact.contact import PointContact as PointContact
from mbjax._src.contact.contact import SurfaceContact as SurfaceContact
from mbjax._src.contact.impulse import impulse as impulse
from mbjax._src.contact.stance import contact_wrenches as contact_wrenches
from mbjax._src.contact.stance import stance as stance
from mbjax._src.contact.stance import stance_contacts as stance_contacts
from mbjax._src.contact.schedule import ContactSolution as ContactSolution
from mbjax._src.contact.schedule import simulate_schedule as simulate_schedule
from mbjax._src.contact.system import ContactSystem as ContactSystem
from mbjax._src.contact.soft import AbstractContactModel as AbstractContactModel
from mbjax._src.contact.soft import SoftConstraints as SoftConstraints

__all__ = [
    "AbstractContact", "PointContact", "SurfaceContact", "stance", "stance_contacts", "contact_wrenches", "impulse",
    "simulate_schedule", "ContactSolution", "ContactSystem",
    "AbstractContactModel", "SoftConstraints",
]
