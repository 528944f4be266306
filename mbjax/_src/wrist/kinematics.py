"""Closed-form kinematics of the Carpal Wrist (`docs/carpal-wrist-model.md`, Canfield 1997 §6.2).

The three knees define the midplane; the distal plate is the base plate mirrored in it. The
midplane is written in the nonsingular slope chart z = p + gx x + gy y (p: the plunge, g: the
slope, tan(beta / 2) = |g|): each knee on the plane is one linear equation

    z_i = p + rho_i c_i . g,      rho_i = rb - l cos theta_i,  z_i = l sin theta_i,

so (p, g) = K^-1 z with K's rows (1, rho_i c_i), and differentiating gives the wrist Jacobian in
the parallel-robot form d(p, g)/d theta = K^-1 D, D = diag(l (cos theta_i - k_i sin theta_i)),
k_i = c_i . g. det K = 0 is the direct (parallel) singularity, D_ii = 0 the inverse (serial) one.
(alpha, beta, p) is reported as output only: alpha is undefined at beta = 0, the home pose.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array


class Pose(eqx.Module):
    """The tool's pose in the base frame B (batched under vmap), as
    `CarpalWrist.forward_kinematics` returns it.

    Args:
        alpha: azimuth of the tool axis [rad], a scalar (0 by convention at beta = 0).
        beta: bend of the tool axis [rad], a scalar.
        plunge: distance from the base centre along e3 to the midplane [m], a scalar.
        slope: (gx, gy), the midplane's nonsingular chart (tan(beta / 2) = |slope|), shape (2,).
        normal: the midplane's unit normal N, shape (3,).
        rotation: R, B to D, shape (3, 3).
        centre: the distal-plate centre c_D [m], shape (3,).
        com: the tool's centre of mass [m], shape (3,).
    """

    alpha: Array
    beta: Array
    plunge: Array
    slope: Array
    normal: Array
    rotation: Array
    centre: Array
    com: Array


def leg_directions(wrist) -> Array:
    """c_i = (cos phi_i, sin phi_i), phi_i = phi0 + (i - 1) 120 deg; shape (3, 2)."""
    phi = wrist.phi0 + jnp.arange(3) * (2 * jnp.pi / 3)
    return jnp.stack([jnp.cos(phi), jnp.sin(phi)], axis=-1)


def knees(wrist, theta: Array) -> Array:
    """Knee centres m_i = b_i + l (-cos theta_i r_i + sin theta_i e3); shape (3, 3)."""
    c = leg_directions(wrist)
    rho = wrist.base_radius - wrist.link_length * jnp.cos(theta)
    return jnp.concatenate([rho[:, None] * c, (wrist.link_length * jnp.sin(theta))[:, None]], axis=1)


def leg_points(wrist, theta: Array) -> Array:
    """The joints of the three legs, shape (3, 3, 3): [0] the base revolutes b_i = rb r_i, [1] the
    knees m_i, [2] the distal revolutes d_i, b_i mirrored in the midplane N . x = N . m_1 (the
    mirror symmetry of `docs/carpal-wrist-model.md`); what a picture of the wrist draws."""
    c = leg_directions(wrist)
    base = jnp.concatenate([wrist.base_radius * c, jnp.zeros((3, 1), c.dtype)], axis=1)
    m = knees(wrist, theta)
    p, g = midplane(wrist, theta)
    N = normal_from_slope(g)
    distal = base - 2 * (_dot(base, N) - p * N[2])[:, None] * N
    return jnp.stack([base, m, distal])


def _knee_matrix(wrist, theta: Array) -> Array:
    """K with rows (1, rho_i c_i): the knees' plane equations in (p, gx, gy)."""
    rho = wrist.base_radius - wrist.link_length * jnp.cos(theta)
    return jnp.concatenate([jnp.ones((3, 1), theta.dtype), rho[:, None] * leg_directions(wrist)], axis=1)


def _dot(a: Array, b: Array) -> Array:
    """Contraction over the last axis, written elementwise: with 3-vectors a LAPACK/dot kernel per
    product (and per derivative of it) costs far more than the arithmetic, which XLA fuses."""
    return jnp.sum(a * b, axis=-1)


def _matmul(A: Array, B: Array) -> Array:
    """A @ B for small matrices, elementwise (see `_dot`)."""
    return jnp.sum(A[..., :, :, None] * B[..., None, :, :], axis=-2)


def _inverse3(K: Array) -> Array:
    """K^-1 of a 3x3 matrix from its rows' cross products (columns k2 x k3, k3 x k1, k1 x k2 over
    det K): elementwise arithmetic that XLA fuses, where a LAPACK call per derivative would not."""
    adj = jnp.stack([jnp.cross(K[1], K[2]), jnp.cross(K[2], K[0]), jnp.cross(K[0], K[1])], axis=1)
    return adj / _dot(K[0], adj[:, 0])


def midplane(wrist, theta: Array) -> tuple[Array, Array]:
    """(p, g): plunge and slope of the plane through the three knees, (p, g) = K^-1 z."""
    sol = _dot(_inverse3(_knee_matrix(wrist, theta)), wrist.link_length * jnp.sin(theta))
    return sol[0], sol[1:]


def _safe_norm(v: Array) -> Array:
    """|v| with gradient 0 (not NaN) at v = 0."""
    sq = jnp.sum(v * v)
    nonzero = sq > 0
    return jnp.where(nonzero, jnp.sqrt(jnp.where(nonzero, sq, 1.0)), 0.0)


def _safe_azimuth(v: Array) -> tuple[Array, Array]:
    """(cos, sin) of the azimuth of a 2-vector, (1, 0) with zero gradient at v = 0."""
    nonzero = jnp.sum(v * v) > 0
    w = jnp.where(nonzero, v, jnp.array([1.0, 0.0], v.dtype))
    w = w / jnp.sqrt(jnp.sum(w * w))
    return w[0], w[1]


def normal_from_slope(g: Array) -> Array:
    """N = (-gx, -gy, 1) / sqrt(1 + |g|^2): the midplane normal, N_z > 0."""
    return jnp.concatenate([-g, jnp.ones(1, g.dtype)]) / jnp.sqrt(1.0 + _dot(g, g))


def rotation_from_slope(g: Array, variant: str = "physical") -> Array:
    """The distal plate's rotation R (B to D).

    "physical": the mirror image of the base in the midplane, R = (I - 2 N N^T) diag(1, 1, -1)
    = Rz(alpha) Ry(beta) Rz(-alpha), smooth in g (the constant-velocity, zero-twist plate).
    "chapter": Canfield 1997's printed R = Rz(alpha) Ry(beta) (eq 6.2's omega); the same tool axis but
    twisted by alpha about it, and discontinuous at beta = 0 where alpha is undefined.
    """
    if variant == "physical":
        N = normal_from_slope(g)
        return (jnp.eye(3, dtype=g.dtype) - 2 * N[:, None] * N[None, :]) * jnp.array([1.0, 1.0, -1.0], g.dtype)
    if variant == "chapter":
        ca, sa = _safe_azimuth(-g)
        t2 = _dot(g, g)                                # tan^2(beta / 2)
        cb, sb = (1 - t2) / (1 + t2), 2 * _safe_norm(g) / (1 + t2)
        z = jnp.zeros((), g.dtype)
        return jnp.array([[ca * cb, -sa, ca * sb], [sa * cb, ca, sa * sb], [-sb, z, cb]])
    raise ValueError(f"unknown rotation variant {variant!r}: use 'physical' or 'chapter'")


def pose_from_chart(wrist, plunge: Array, g: Array) -> Pose:
    """The tool pose for midplane (p, g): c_D = 2 p N_z N = p (e3 + R e3), x_G = c_D + R G."""
    N = normal_from_slope(g)
    R = rotation_from_slope(g, wrist.rotation_model)
    ca, sa = _safe_azimuth(-g)
    centre = 2 * plunge * N[2] * N
    return Pose(alpha=jnp.arctan2(sa, ca), beta=2 * jnp.arctan(_safe_norm(g)), plunge=plunge,
                slope=g, normal=N, rotation=R, centre=centre, com=centre + _dot(R, wrist.tool_com))


def com_and_rotation(wrist, theta: Array) -> tuple[Array, Array]:
    """(x_G, R): just the tool's centre of mass and rotation, the part of the pose the dynamics
    differentiates (three times: a lean graph compiles faster)."""
    p, g = midplane(wrist, theta)
    N = normal_from_slope(g)
    R = rotation_from_slope(g, wrist.rotation_model)
    return 2 * p * N[2] * N + _dot(R, wrist.tool_com), R


def forward_kinematics(wrist, theta: Array) -> Pose:
    """The tool pose for input angles theta (closed form; `docs/carpal-wrist-model.md`)."""
    theta = jnp.asarray(theta)
    p, g = midplane(wrist, theta)
    return pose_from_chart(wrist, p, g)


def slope_from_angles(alpha: Array, beta: Array) -> Array:
    """g = -tan(beta / 2) (cos alpha, sin alpha)."""
    return -jnp.tan(beta / 2) * jnp.stack([jnp.cos(alpha), jnp.sin(alpha)])


def _ik_argument(wrist, plunge: Array, g: Array) -> tuple[Array, Array]:
    """(k_i, a_i): k_i = c_i . g, a_i = (p + rb k_i) / (l sqrt(1 + k_i^2)); reachable iff |a_i| <= 1."""
    k = _dot(leg_directions(wrist), g)
    return k, (plunge + wrist.base_radius * k) / (wrist.link_length * jnp.sqrt(1 + k * k))


def solve_inverse_kinematics(wrist, plunge: Array, g: Array) -> tuple[Array, Array]:
    """(theta, reachable) for the midplane chart (p, g), knees-out branch:
    theta_i = atan2(1, k_i) + acos(a_i). Unreachable legs get their nearest boundary angle (a_i
    clipped to +-1), so theta stays finite; `reachable` says whether every |a_i| <= 1."""
    k, a = _ik_argument(wrist, plunge, g)
    reachable = jnp.all(jnp.abs(a) <= 1.0)
    # acos has an infinite slope at +-1; keep its argument inside so gradients stay finite there
    inside = jnp.abs(a) < 1.0
    a_in = jnp.where(inside, a, 0.0)
    acos = jnp.where(inside, jnp.arccos(a_in), jnp.where(a >= 1.0, 0.0, jnp.pi))
    return jnp.arctan2(1.0, k) + acos, reachable


def in_chart(alpha: Array, beta: Array, plunge: Array) -> Array:
    """Whether (alpha, beta, p) is a tool pose the midplane chart describes: finite, with the
    bend |beta| < pi (at pi the midplane is vertical; beyond it tan(beta / 2) changes sign and
    the slope describes the pose bent by 2 pi - |beta| the other way)."""
    return (jnp.isfinite(alpha) & jnp.isfinite(beta) & jnp.isfinite(plunge)
            & (jnp.abs(beta) < jnp.pi))


def inverse_kinematics(wrist, alpha, beta, plunge) -> Array:
    """theta for tool pose (alpha, beta, p), knees-out branch; an unreachable pose, or one
    outside the chart (`in_chart`), raises (`eqx.error_if`, also under jit).
    `solve_inverse_kinematics` returns a status instead."""
    alpha, beta, plunge = (jnp.asarray(x, dtype=float) for x in (alpha, beta, plunge))
    theta, reachable = solve_inverse_kinematics(wrist, plunge, slope_from_angles(alpha, beta))
    theta = eqx.error_if(theta, ~in_chart(alpha, beta, plunge),
                         "Carpal Wrist: the pose is outside the (alpha, beta, p) chart: it needs "
                         "finite values and a bend |beta| < pi")
    return eqx.error_if(theta, ~reachable, "Carpal Wrist: pose out of reach (a knee circle misses "
                        "the midplane: |p + rb k_i| > l sqrt(1 + k_i^2) for some leg)")


def chart_jacobian(wrist, theta: Array) -> Array:
    """d(p, gx, gy)/d theta = K^-1 D in closed form."""
    p, g = midplane(wrist, theta)
    k = _dot(leg_directions(wrist), g)
    D = wrist.link_length * (jnp.cos(theta) - k * jnp.sin(theta))
    return _inverse3(_knee_matrix(wrist, theta)) * D


def _normal_plunge(wrist, theta: Array) -> Array:
    """n = (N_x, N_y, p), the chapter's intermediate coordinates (eq 6.33)."""
    p, g = midplane(wrist, theta)
    return jnp.concatenate([normal_from_slope(g)[:2], p[None]])


def jacobian(wrist, theta: Array) -> Array:
    """J of Canfield 1997 eq 6.34, (N_x, N_y, p)_dot = J theta_dot, by forward-mode autodiff."""
    return jax.jacfwd(_normal_plunge, argnums=1)(wrist, jnp.asarray(theta))


def jacobian_closed_form(wrist, theta: Array) -> Array:
    """J of eq 6.34 in closed form: dN_xy/dg (I / s - g g^T / s^3, s^2 = 1 + |g|^2, sign -)
    composed with K^-1 D; an independent check of `jacobian`."""
    _, g = midplane(wrist, theta)
    return _normal_plunge_rows(g, chart_jacobian(wrist, theta))


def _normal_plunge_rows(g: Array, chart_rows: Array) -> Array:
    """Rows d(N_x, N_y, p) from rows d(p, gx, gy) at the slope g: dN_xy/dg = -(I / s -
    g g^T / s^3), s^2 = 1 + |g|^2."""
    s = jnp.sqrt(1.0 + g @ g)
    dN_dg = -(jnp.eye(2, dtype=g.dtype) / s - jnp.outer(g, g) / s**3)
    return jnp.concatenate([dN_dg @ chart_rows[1:], chart_rows[:1]], axis=0)


class SingularityMeasures(eqx.Module):
    """Distances to the two singularity types, 1 far away and 0 on them.

    inverse: min_i sqrt(1 - a_i^2) = -D_ii / (l sqrt(1 + k_i^2)), the sine of the angle between
    leg i's knee circle and the midplane (0: the circle touches the plane, the workspace boundary;
    negative: that knee is on the knees-in branch). direct: (rho1 rho2 + rho2 rho3 + rho3 rho1) /
    max(rho1^2 + rho2^2 + rho3^2, 3 rb^2), det K (the knees' projections' triangle, 2 / sqrt(3)
    its area) over its largest for the triangle's size, or for the legs-up pose's (rho_i = rb)
    where the triangle is smaller: 0 where the knees' projections are collinear or meet in one
    point (rho_i = 0 together, at theta_i = arccos(rb / l)), the parallel singularity; 1 where all
    rho_i are equal and at least rb. condition: the smallest singular
    value of J (eq 6.34, J = dN/dg K^-1 D) over the largest of J_max = dN/dg K^-1 D_max, the
    Jacobian with every leg at its largest gain |D_ii| = l sqrt(1 + k_i^2), so in [0, 1]: 0 at
    an inverse singularity (a D_ii = 0: J loses rank), and at a direct one (det K = 0: J_max
    grows without bound), including all three legs singular at once, where J vanishes whole
    and 1 / cond(J) would be 0 / 0.
    """

    inverse: Array
    direct: Array
    condition: Array


def singularity_measures(wrist, theta: Array) -> SingularityMeasures:
    """Both singularity distances and the Jacobian's inverse condition number at theta."""
    theta = jnp.asarray(theta)
    _, g = midplane(wrist, theta)
    k = _dot(leg_directions(wrist), g)
    leg = (jnp.cos(theta) - k * jnp.sin(theta)) / jnp.sqrt(1 + k * k)
    rho = wrist.base_radius - wrist.link_length * jnp.cos(theta)
    direct = ((rho[0] * rho[1] + rho[1] * rho[2] + rho[2] * rho[0])
              / jnp.maximum(jnp.sum(rho * rho), 3 * wrist.base_radius**2))
    sv = jnp.linalg.svd(jacobian_closed_form(wrist, theta), compute_uv=False)
    K_inv = _inverse3(_knee_matrix(wrist, theta))
    J_max = _normal_plunge_rows(g, K_inv * (wrist.link_length * jnp.sqrt(1 + k * k)))
    largest = jnp.linalg.svd(J_max, compute_uv=False)[0]
    return SingularityMeasures(inverse=jnp.min(-leg), direct=direct, condition=sv[-1] / largest)


def reachable(wrist, alpha, beta, plunge) -> Array:
    """True where the pose (alpha, beta, p) is in the chart (`in_chart`) and has a knees-out
    solution (broadcasts)."""
    def one(a, b, p):
        return _ik_argument(wrist, p, slope_from_angles(a, b))[1]
    args = jnp.broadcast_arrays(*(jnp.asarray(x, dtype=float) for x in (alpha, beta, plunge)))
    a = jax.vmap(one)(*(x.ravel() for x in args))
    return (jnp.all(jnp.abs(a) <= 1.0, axis=-1).reshape(args[0].shape) & in_chart(*args))


def rotation_angle(Ra: Array, Rb: Array) -> Array:
    """The geodesic angle between two rotations, accurate near 0.

    Args:
        Ra: a rotation matrix, shape (3, 3).
        Rb: a rotation matrix, shape (3, 3).

    Returns:
        The angle of Ra^T Rb [rad], a scalar in [0, pi].
    """
    D = Ra.T @ Rb
    s = 0.5 * _safe_norm(jnp.array([D[2, 1] - D[1, 2], D[0, 2] - D[2, 0], D[1, 0] - D[0, 1]]))
    c = 0.5 * (jnp.trace(D) - 1.0)
    return jnp.arctan2(s, c)


def pose_error(wrist, a: Pose, b: Pose) -> Array:
    """One dimensionless number for 'did the tool arrive': max(rotation angle between a and b
    [rad], |centre_a - centre_b| / link_length).

    Args:
        wrist (CarpalWrist): the `CarpalWrist` (its link_length scales the distance).
        a: a tool pose.
        b: another tool pose.

    Returns:
        The error, a non-negative scalar.
    """
    return jnp.maximum(rotation_angle(a.rotation, b.rotation),
                       _safe_norm(a.centre - b.centre) / wrist.link_length)
