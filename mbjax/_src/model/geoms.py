"""Collision geometry as data: the geoms of a model, their contact parameters, and the pairs
that may touch (MuJoCo's geoms, `contype`/`conaffinity` and `filterparent` rules)."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

# the primitives detected (`mbjax._src.contact.collision`), in MuJoCo's order: a pair is
# ordered so that its first geom's kind comes first here
KINDS = ("plane", "sphere", "capsule", "ellipsoid", "cylinder", "box")
# the pairs of kinds whose contacts `mbjax.contact.ContactSystem` detects (its collision
# functions, `mbjax._src.contact.collision.PAIRS`)
DETECTED = frozenset({("plane", "sphere"), ("plane", "capsule"), ("plane", "ellipsoid"),
                      ("plane", "cylinder"), ("plane", "box"), ("sphere", "sphere"),
                      ("sphere", "capsule"), ("sphere", "box"), ("capsule", "capsule"),
                      ("capsule", "box"), ("box", "box")})
GROUND = -1
# MuJoCo's defaults
FRICTION = (1.0, 0.005, 0.0001)
SOLREF = (0.02, 1.0)
SOLIMP = (0.9, 0.95, 0.001, 0.5, 2.0)


def _rows(value, default, n: int, width: int | None, name: str):
    """value (or default) broadcast to (n,) or (n, width), float; a ValueError naming it."""
    value = default if value is None else value
    shape = (n,) if width is None else (n, width)
    xp = jnp if isinstance(value, jax.core.Tracer) else np      # shaped in NumPy, as Model's
    try:
        return jnp.asarray(xp.broadcast_to(xp.asarray(value, dtype=float), shape))
    except ValueError as error:
        raise ValueError(f"{name} must broadcast to shape {shape}, got shape "
                         f"{np.shape(value)}") from error


def _concrete(x) -> bool:
    return not isinstance(x, jax.core.Tracer)


class Geoms(eqx.Module):
    """A model's collision geometry: each geom's kind, body, size, pose on its body and contact
    parameters, as arrays (so `eqx.tree_at` changes them and `jax.vmap` sweeps them), and the
    pairs of geoms that may touch.

    Sizes follow MJCF: a plane (its half extents; an infinite plane for zeros, its normal the
    geom's z axis), a sphere (radius), a capsule (radius, half length of its segment along z),
    an ellipsoid (semi-axes), a cylinder (radius, half length along z), a box (half extents).
    Contact parameters are MuJoCo's (`friction` sliding, torsional, rolling; `solref`
    (timeconst, dampratio) or (-stiffness, -damping); `solimp` (dmin, dmax, width, mid, power);
    `margin` and `gap`; `solmix` the weight of a geom's solref and solimp in a pair); two geoms'
    parameters combine as MuJoCo combines them (`pair_parameters`). Contacts are detected
    between a plane and every other kind, and between spheres, capsules and boxes (cylinders
    and ellipsoids on planes only).

    Args:
        kinds: each geom's kind, one of "plane", "sphere", "capsule", "ellipsoid", "cylinder",
            "box".
        bodies: each geom's body (-1 for the ground).
        size: (n, 3) sizes (unused entries ignored).
        position: (n, 3) each geom's origin in its body's frame; zeros by default.
        rotation: (n, 3, 3) each geom's axes in its body's frame; identity by default.
        friction, solref, solimp, solmix, margin, gap: contact parameters, (n, 3), (n, 2),
            (n, 5), (n,), (n,), (n,); MuJoCo's defaults.
        condim: each geom's contact dimension, 1 (frictionless), 3 (sliding friction), 4 (and
            torsional friction) or 6 (and rolling friction); a pair takes the larger; 3 by
            default.
        names: each geom's name; "geomK" by default.
        pairs: the pairs of geom indices that may touch, or None for every pair whose
            `contype` and `conaffinity` match, on different bodies not both the ground and not
            parent and child (MuJoCo's rules; `from_mujoco` passes MuJoCo's own list).
        contype, conaffinity: each geom's collision bits (1 by default), used where `pairs` is
            None.
        parents: the model's body parents (`model.topology.parents`), used where `pairs` is
            None to leave out parent and child.

    Raises:
        ValueError: naming the field: an unknown kind, a negative size, a sphere, capsule or
            cylinder of zero radius, an ellipsoid with a zero semi-axis, negative friction,
            margin or solmix, a solref mixing signs, a solimp outside MuJoCo's range, a condim
            other than 1, 3, 4 or 6, a pair out of range.
    """

    kinds: tuple = eqx.field(static=True)
    bodies: tuple = eqx.field(static=True)
    names: tuple = eqx.field(static=True)
    condim: tuple = eqx.field(static=True)
    pairs: tuple = eqx.field(static=True)
    size: Array
    position: Array
    rotation: Array
    friction: Array
    solref: Array
    solimp: Array
    solmix: Array
    margin: Array
    gap: Array

    def __init__(self, kinds, bodies, size, *, position=None, rotation=None, friction=None,
                 solref=None, solimp=None, solmix=None, margin=None, gap=None, condim=None,
                 names=None, pairs=None, contype=None, conaffinity=None, parents=None):
        self.kinds, self.bodies = tuple(kinds), tuple(int(b) for b in bodies)
        n = len(self.kinds)
        if len(self.bodies) != n:
            raise ValueError(f"bodies must give one body per geom ({n}), got {len(self.bodies)}")
        for k in self.kinds:
            if k not in KINDS:
                raise ValueError(f"kinds: unknown geom kind {k!r}; choose from {KINDS}")
        self.names = tuple(names) if names is not None else tuple(f"geom{k}" for k in range(n))
        self.condim = (3,) * n if condim is None else tuple(int(c) for c in condim)
        if any(c not in (1, 3, 4, 6) for c in self.condim):
            raise ValueError(f"condim must be 1 (frictionless), 3 (sliding friction), 4 (and "
                             f"torsional) or 6 (and rolling), got {self.condim}")
        self.size = _rows(size, None, n, 3, "size")
        self.position = _rows(position, 0.0, n, 3, "position")
        if rotation is None:
            self.rotation = jnp.asarray(np.broadcast_to(np.eye(3), (n, 3, 3)))
        else:
            xp = np if _concrete(rotation) else jnp
            self.rotation = jnp.asarray(xp.asarray(rotation, dtype=float).reshape(n, 3, 3))
        self.friction = _rows(friction, FRICTION, n, 3, "friction")
        self.solref = _rows(solref, SOLREF, n, 2, "solref")
        self.solimp = _rows(solimp, SOLIMP, n, 5, "solimp")
        self.solmix = _rows(solmix, 1.0, n, None, "solmix")
        self.margin = _rows(margin, 0.0, n, None, "margin")
        self.gap = _rows(gap, 0.0, n, None, "gap")
        if pairs is None:
            pairs = default_pairs(self.bodies, contype, conaffinity, parents)
        self.pairs = tuple(_ordered(self.kinds, i, j) for i, j in pairs)
        if any(not (0 <= i < n and 0 <= j < n) for i, j in self.pairs):
            raise ValueError(f"pairs must index the {n} geoms, got {self.pairs}")

    def __check_init__(self):
        checks = (
            ("size", self.size, lambda x: np.all(x >= 0), "must not be negative"),
            ("friction", self.friction, lambda x: np.all(x >= 0), "must not be negative"),
            ("margin", self.margin, lambda x: np.all(x >= 0), "must not be negative"),
            ("solmix", self.solmix, lambda x: np.all(x >= 0), "must not be negative"),
            ("solref", self.solref, _solref_ok,
             "must be (timeconst > 0, dampratio > 0) or (-stiffness, -damping), both <= 0"),
            ("solimp", self.solimp, _solimp_ok,
             "must have dmin, dmax and mid in [0, 1] and width >= 0 (MuJoCo clamps them "
             "into its own range)"),
        )
        for name, value, ok, what in checks:
            if _concrete(value) and not ok(np.asarray(value)):
                raise ValueError(f"{name} {what}, got {np.asarray(value).tolist()}")
        if _concrete(self.size):
            size = np.asarray(self.size)
            for k, kind in enumerate(self.kinds):     # a radius (a segment, a box may be flat)
                if kind in ("sphere", "capsule", "cylinder") and not size[k, 0] > 0:
                    raise ValueError(f"size of {kind} geom {self.names[k]!r}: its radius must be "
                                     f"positive, got {size[k, 0]}")
                if kind == "ellipsoid" and not np.all(size[k] > 0):
                    raise ValueError(f"size of ellipsoid geom {self.names[k]!r}: its semi-axes "
                                     f"must be positive, got {size[k].tolist()}")

    @property
    def n(self) -> int:
        """The number of geoms."""
        return len(self.kinds)

    def join(self, other: "Geoms", pairs=None) -> "Geoms":
        """These geoms and `other`'s (a floor: `model.geoms.join(ground_plane())`).

        Args:
            other: the geoms to add, after these.
            pairs: the pairs that may touch, indices into the joined list; None for each
                one's pairs and every pair of one geom of each on different bodies, not both
                the ground.

        Returns:
            The joined `Geoms`.
        """
        n = self.n
        if pairs is None:
            across = [(i, n + j) for i in range(n) for j in range(other.n)
                      if self.bodies[i] != other.bodies[j]
                      and not (self.bodies[i] == GROUND and other.bodies[j] == GROUND)]
            pairs = [*self.pairs, *((n + i, n + j) for i, j in other.pairs), *across]
        return Geoms(self.kinds + other.kinds, self.bodies + other.bodies,
                     _cat(self.size, other.size),
                     position=_cat(self.position, other.position),
                     rotation=_cat(self.rotation, other.rotation),
                     friction=_cat(self.friction, other.friction),
                     solref=_cat(self.solref, other.solref), solimp=_cat(self.solimp, other.solimp),
                     solmix=_cat(self.solmix, other.solmix), margin=_cat(self.margin, other.margin),
                     gap=_cat(self.gap, other.gap),
                     condim=self.condim + other.condim, names=self.names + other.names,
                     pairs=pairs)


def _cat(a, b):
    xp = np if _concrete(a) and _concrete(b) else jnp
    return xp.concatenate([a, b])


def _solref_ok(x) -> bool:
    positive = (x[:, 0] > 0) & (x[:, 1] > 0)
    direct = (x[:, 0] <= 0) & (x[:, 1] <= 0)
    return bool(np.all(positive | direct))


def _solimp_ok(x) -> bool:
    dmin, dmax, width, mid, power = x.T
    unit = [(y >= 0) & (y <= 1) for y in (dmin, dmax, mid)]
    return bool(np.all(unit[0] & unit[1] & unit[2] & (width >= 0) & np.isfinite(power)))


def _ordered(kinds, i: int, j: int) -> tuple[int, int]:
    """(i, j) ordered so that the first geom's kind comes first in `KINDS`."""
    return (i, j) if KINDS.index(kinds[i]) <= KINDS.index(kinds[j]) else (j, i)


def default_pairs(bodies, contype=None, conaffinity=None, parents=None) -> list:
    """MuJoCo's rule for the pairs that may touch: `contype` of one and `conaffinity` of the
    other share a bit, the bodies differ and are not both the ground, and neither body is the
    other's parent (the ground excepted, as MuJoCo's `filterparent`)."""
    n = len(bodies)
    contype = np.ones(n, int) if contype is None else np.asarray(contype, int)
    conaffinity = np.ones(n, int) if conaffinity is None else np.asarray(conaffinity, int)
    parents = () if parents is None else tuple(parents)

    def related(a, b):
        return (a >= 0 and b >= 0 and (a < len(parents) and parents[a] == b
                                       or b < len(parents) and parents[b] == a))

    return [(i, j) for i in range(n) for j in range(i + 1, n)
            if (contype[i] & conaffinity[j]) | (contype[j] & conaffinity[i])
            and bodies[i] != bodies[j] and not related(bodies[i], bodies[j])]


def ground_plane(normal=(0.0, 0.0, 1.0), height: float = 0.0, **parameters) -> Geoms:
    """An infinite plane fixed to the ground, through the point height * normal, facing
    `normal` (MJCF's `<geom type="plane">` on the world body).

    Args:
        normal: the plane's normal, world components (z by default).
        height: the plane's offset along its normal [m].
        **parameters: contact parameters, as `Geoms` takes them (friction, solref, ...), each
            for this one geom.

    Returns:
        `Geoms` of one plane.
    """
    n = np.asarray(normal, dtype=float)
    if n.shape != (3,) or not np.linalg.norm(n) > 0:
        raise ValueError(f"normal must be a nonzero 3-vector, got {np.asarray(normal).tolist()}")
    z = n / np.linalg.norm(n)
    x = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = x - z * (x @ z)
    x /= np.linalg.norm(x)
    rotation = np.stack([x, np.cross(z, x), z], axis=1)
    values = {k: np.asarray(v, dtype=float)[None] for k, v in parameters.items()}
    return Geoms(("plane",), (GROUND,), np.zeros((1, 3)), position=(height * z)[None],
                 rotation=rotation[None], names=("ground",), pairs=(), **values)


def pair_parameters(geoms: Geoms, i: np.ndarray, j: np.ndarray):
    """Pairs' contact parameters from their two geoms', as MuJoCo 4 combines them: the larger
    friction (each component), the sum of the margins (MuJoCo 4 leaves the gaps out of the
    margin a contact pushes within), and solref and solimp averaged with weights solmix (the
    smaller components where the solrefs are direct, negative values).

    Args:
        geoms: the geometry.
        i, j: the pairs' first and second geoms, NumPy int arrays (P,).

    Returns:
        (friction (P, 3), solref (P, 2), solimp (P, 5), margin (P,)).
    """
    s1, s2 = geoms.solmix[i], geoms.solmix[j]
    total = s1 + s2
    mix = jnp.where(total > 0, s1 / jnp.where(total > 0, total, 1.0), 0.5)[:, None]
    r1, r2 = geoms.solref[i], geoms.solref[j]
    solref = jnp.where((r1[:, :1] > 0) & (r2[:, :1] > 0), mix * r1 + (1 - mix) * r2,
                       jnp.minimum(r1, r2))
    solimp = mix * geoms.solimp[i] + (1 - mix) * geoms.solimp[j]
    friction = jnp.maximum(geoms.friction[i], geoms.friction[j])
    return friction, solref, solimp, geoms.margin[i] + geoms.margin[j]
