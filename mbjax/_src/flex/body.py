"""A modal flexible body: the time-invariant coefficients of Anderson 1993's Appendix, and the body's
equations of motion in its own frame.

Anderson 1993 lumps the body's mass and rotary inertia at points P (eqs 36-42): a point at undeformed
position rho_p (from the joint grid J, the body frame's origin) moves to
xi_p = rho_p + phi_p q (eq 5) and turns by psi_p q (eq 8), q the modal coordinates. With
A_p = [rho_p, phi_p] (3 x (1 + mu)) and q_bar = (1, q), every mass integral the equations need is
a contraction of four time-invariant coefficients, computed once (the Appendix, eqs A1-A39, in
tensor form):

    mass          m      = sum_p m_p
    first         S      = sum_p m_p A_p                        (3, 1 + mu)
    second        P      = sum_p m_p A_p (x) A_p                (3, 1 + mu, 3, 1 + mu)
    rotary        I_0    = sum_p I_p,   I_psi = sum_p I_p psi_p
    modal mass    M_ff   = sum_p m_p phi_p^T phi_p + psi_p^T I_p psi_p

so that sum_p m_p xi_p = S q_bar and sum_p m_p xi_p xi_p^T = P : (q_bar, q_bar). The body's
generalized mass in (omega, v, u) (body-frame angular velocity and velocity of the origin,
modal rates; eqs 41-42, 51-53) is then

    [[J(q),       xi~(q),  C(q)],          J = tr(Q) 1 - Q + I_0,  Q = P : (q_bar, q_bar)
     [xi~(q)^T,   m 1,     S_1 ],          xi~ = skew(S q_bar),    S_1 = S[:, 1:]
     [C(q)^T,     S_1^T,   M_ff]]          C = sum_p m_p xi_p~ phi_p + I_psi

with no sum over the points at run time. The velocity terms are not expanded by hand (the
Appendix's long list of remainder terms): the kinetic energy T = w^T M(q) w / 2 gives them by
autodiff through the Boltzmann-Hamel equations of the floating frame,

    d/dt dT/dV + V x* dT/dV = f,        d/dt dT/du - dT/dq = Q,

i.e. M(q) w_dot + M_dot w + (V x* h; -dT/dq) with h = M w, M_dot = dM/dq . u.

Geometric stiffening (eqs 32-33, 46, Table 1) enters the modal equation as K_G q with
K_G = sum_q s_q K_q (21 inertial unit loads, `mbjax._src.flex.stiffening`) plus the distal bodies'
loads; the temporal scalars s are linear in the body's acceleration, so K_G q = G_s A + g_s.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.flex.stiffening import inertial_scalars
from mbjax._src.spatial import cross_force, skew

# d s / d A for the 21 temporal scalars of Table 1 (`mbjax._src.flex.stiffening` order): s[0:3] = a
# (the joint grid's classical acceleration), s[3:6] = s[12:15] = alpha, the rest omega products;
# A = (alpha; a_spatial) is the body frame's spatial acceleration, a = a_spatial + omega x v.
_DS_DA = np.zeros((21, 6))
_DS_DA[0:3, 3:6] = _DS_DA[3:6, 0:3] = _DS_DA[12:15, 0:3] = np.eye(3)


_EPS = np.zeros((3, 3, 3))                                   # the Levi-Civita symbol
for i, j, k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
    _EPS[i, j, k], _EPS[i, k, j] = 1.0, -1.0


class ModalBody(eqx.Module):
    """The time-invariant coefficients of a flexible body with mu modal coordinates (Anderson
    1993's Appendix; the coefficients in docs/details.md), its modal stiffness and damping, the
    geometric-stiffening matrices, and the modal shapes at the grid points where other bodies or
    cut joints attach.

    Build it with `mbjax.flex.beam_body` (from a beam and its modal basis),
    `ModalBody.from_points` (a `MassPoints` cloud, `mbjax/_src/flex/points.py`, and the reduced
    stiffness) or `ModalBody.rigid` (a rigid body in the same form); the constructor takes the
    fields below directly. Body-frame components throughout, the frame at the joint grid J^k.

    Args:
        mass: total mass m [kg], a scalar.
        first: first mass moments S = sum_p m_p A_p, shape (3, 1 + mu).
        second: second mass moments P = sum_p m_p A_p (x) A_p, shape (3, 1 + mu, 3, 1 + mu).
        rotary: the points' summed rotary inertia I_0 [kg m^2], shape (3, 3).
        rotary_psi: I_psi = sum_p I_p psi_p, shape (3, mu).
        modal_mass: M_ff, shape (mu, mu).
        stiffness: reduced modal stiffness K, shape (mu, mu).
        damping: modal damping D, shape (mu, mu).
        inertial_stiffening: eq 33's K_hat_Gq, one per temporal scalar of Table 1, shape
            (21, mu, mu) (zero: stiffening off).
        node_position: undeformed positions of the H attachment grid points [m], shape (H, 3).
        node_phi: their translational shapes, shape (H, 3, mu).
        node_psi: their rotational shapes, shape (H, 3, mu).
        distal_stiffening: eq 33's K_check_Gh for loads at each attachment point, shape
            (H, 6, mu, mu).

    More on the coefficients, geometric stiffening: the documentation site's Details page
    (docs/details.md).
    """

    mass: Array
    first: Array
    second: Array
    rotary: Array
    rotary_psi: Array
    modal_mass: Array
    stiffness: Array
    damping: Array
    inertial_stiffening: Array
    node_position: Array
    node_phi: Array
    node_psi: Array
    distal_stiffening: Array

    @property
    def mu(self) -> int:
        """Number of modal coordinates."""
        return self.modal_mass.shape[-1]

    @staticmethod
    def from_points(points, stiffness, *, damping=None, inertial_stiffening=None, nodes=None,
                    distal_stiffening=None) -> "ModalBody":
        """The body's coefficients from a mass-point cloud (the sums over the points P given
        under "The coefficients" in `ModalBody`).

        Args:
            points: the cloud, with `mass` (P,), `position` (P, 3), `phi`, `psi` (P, 3, mu)
                and `inertia` (P, 3, 3) (a `MassPoints`).
            stiffness: reduced modal stiffness, shape (mu, mu).
            damping: modal damping, shape (mu, mu); None: zero.
            inertial_stiffening: shape (21, mu, mu); None: zero (no stiffening).
            nodes: attachment grid points (position (H, 3), phi (H, 3, mu), psi (H, 3, mu));
                None: none.
            distal_stiffening: shape (H, 6, mu, mu); None: zero.

        Returns:
            The `ModalBody`.

        Raises:
            ValueError: stiffness or damping not of shape (mu, mu).
        """
        m, rho, phi, psi, inertia = (jnp.asarray(points.mass, float), points.position,
                                     points.phi, points.psi, points.inertia)
        mu = phi.shape[-1]
        A = jnp.concatenate([rho[..., None], phi], -1)                     # (P, 3, 1 + mu)
        stiffness = jnp.asarray(stiffness, float)
        if stiffness.shape != (mu, mu):
            raise ValueError(f"stiffness must be ({mu}, {mu}) for {mu} modes, got {stiffness.shape}")
        damping = jnp.zeros((mu, mu)) if damping is None else jnp.asarray(damping, float)
        if damping.shape != (mu, mu):
            raise ValueError(f"damping must be the modal damping matrix of shape ({mu}, {mu}) for "
                             f"{mu} modes, got shape {damping.shape} (per-mode coefficients c: "
                             "jnp.diag(c))")
        if nodes is None:
            nodes = (jnp.zeros((0, 3)), jnp.zeros((0, 3, mu)), jnp.zeros((0, 3, mu)))
        node_position, node_phi, node_psi = (jnp.asarray(x, float) for x in nodes)
        return ModalBody(
            mass=jnp.sum(m),
            first=jnp.einsum("p,pia->ia", m, A),
            second=jnp.einsum("p,pia,pjb->iajb", m, A, A),
            rotary=jnp.sum(inertia, 0),
            rotary_psi=jnp.einsum("pij,pjs->is", inertia, psi),
            modal_mass=(jnp.einsum("p,pis,pit->st", m, phi, phi)
                        + jnp.einsum("pis,pij,pjt->st", psi, inertia, psi)),
            stiffness=stiffness,
            damping=damping,
            inertial_stiffening=(jnp.zeros((21, mu, mu)) if inertial_stiffening is None
                                 else jnp.asarray(inertial_stiffening, float)),
            node_position=node_position, node_phi=node_phi, node_psi=node_psi,
            distal_stiffening=(jnp.zeros((node_position.shape[0], 6, mu, mu))
                               if distal_stiffening is None
                               else jnp.asarray(distal_stiffening, float)))

    @staticmethod
    def rigid(mass, com, inertia, mu: int) -> "ModalBody":
        """A rigid body in the same form, padded to mu modal columns that stay decoupled and at
        rest (unit modal mass, no shapes, no stiffness).

        Args:
            mass: mass [kg].
            com: centre of mass in the body frame [m], shape (3,).
            inertia: inertia about the centre of mass [kg m^2], shape (3, 3).
            mu: number of (idle) modal columns.

        Returns:
            The `ModalBody`, with no attachment points.
        """
        mass, com = jnp.asarray(mass, float), jnp.asarray(com, float)
        first = jnp.zeros((3, 1 + mu)).at[:, 0].set(mass * com)
        second = jnp.zeros((3, 1 + mu, 3, 1 + mu)).at[:, 0, :, 0].set(mass * jnp.outer(com, com))
        zeros = jnp.zeros((mu, mu))
        return ModalBody(mass=mass, first=first, second=second, rotary=jnp.asarray(inertia, float),
                         rotary_psi=jnp.zeros((3, mu)), modal_mass=jnp.eye(mu), stiffness=zeros,
                         damping=zeros, inertial_stiffening=jnp.zeros((21, mu, mu)),
                         node_position=jnp.zeros((0, 3)), node_phi=jnp.zeros((0, 3, mu)),
                         node_psi=jnp.zeros((0, 3, mu)), distal_stiffening=jnp.zeros((0, 6, mu, mu)))

    @eqx.filter_jit
    def padded(self, mu: int, nodes: int) -> "ModalBody":
        """The same body with mu >= self.mu modal columns (the extra ones decoupled and at rest)
        and `nodes` attachment points (the extra ones without shapes), so bodies stack."""
        k, h = mu - self.mu, nodes - self.node_position.shape[0]
        if k < 0 or h < 0:
            raise ValueError(f"cannot pad a body with {self.mu} modes and "
                             f"{self.node_position.shape[0]} nodes to {mu} and {nodes}")
        z = lambda a, widths: jnp.pad(a, widths)                              # noqa: E731
        return ModalBody(
            mass=self.mass, first=z(self.first, ((0, 0), (0, k))),
            second=z(self.second, ((0, 0), (0, k), (0, 0), (0, k))), rotary=self.rotary,
            rotary_psi=z(self.rotary_psi, ((0, 0), (0, k))),
            modal_mass=z(self.modal_mass, ((0, k), (0, k))).at[self.mu:, self.mu:].set(jnp.eye(k)),
            stiffness=z(self.stiffness, ((0, k), (0, k))), damping=z(self.damping, ((0, k), (0, k))),
            inertial_stiffening=z(self.inertial_stiffening, ((0, 0), (0, k), (0, k))),
            node_position=z(self.node_position, ((0, h), (0, 0))),
            node_phi=z(self.node_phi, ((0, h), (0, 0), (0, k))),
            node_psi=z(self.node_psi, ((0, h), (0, 0), (0, k))),
            distal_stiffening=z(self.distal_stiffening, ((0, h), (0, 0), (0, k), (0, k))))

    def without_stiffening(self) -> "ModalBody":
        """The same body with geometric stiffening switched off (the prematurely linearized model
        that Anderson 1993's introduction warns about)."""
        return eqx.tree_at(lambda b: (b.inertial_stiffening, b.distal_stiffening), self,
                           (jnp.zeros_like(self.inertial_stiffening),
                            jnp.zeros_like(self.distal_stiffening)))


# -- the body's equations in its own frame ------------------------------------------------------


def mass_matrix(body: ModalBody, q: Array) -> Array:
    """(6 + mu) x (6 + mu) generalized mass in (omega, v, u), body frame at the joint grid (eqs
    41-42, 51-53 with the Appendix's coefficients)."""
    q_bar = jnp.concatenate([jnp.ones(1, q.dtype), q])
    s = body.first @ q_bar                                          # sum m xi
    Q = jnp.einsum("iajb,a,b->ij", body.second, q_bar, q_bar)      # sum m xi xi^T
    J = jnp.trace(Q) * jnp.eye(3, dtype=q.dtype) - Q + body.rotary
    xi_phi = jnp.einsum("iakb,a->ikb", body.second[:, :, :, 1:], q_bar)   # sum m xi_i phi_kb
    C = jnp.einsum("jik,ikb->jb", _EPS, xi_phi) + body.rotary_psi
    S1 = body.first[:, 1:]
    m = body.mass * jnp.eye(3, dtype=q.dtype)
    return jnp.block([[J, skew(s), C], [skew(s).T, m, S1], [C.T, S1.T, body.modal_mass]])


def kinetic_energy(body: ModalBody, q: Array, w: Array) -> Array:
    """T = w^T M(q) w / 2 for w = (omega, v, u)."""
    return 0.5 * w @ mass_matrix(body, q) @ w


def velocity_terms(body: ModalBody, q: Array, w: Array) -> Array:
    """The remainder of the body's equations at zero acceleration (eqs 43, 47-53 in Hamel form):
    M_dot w + (V x* h; -dT/dq), h = M(q) w, M_dot = dM/dq . u; autodiff, no hand expansion."""
    M, M_dot = jax.jvp(lambda q_: mass_matrix(body, q_), (q,), (w[6:],))
    h = M @ w
    dT_dq = jax.grad(kinetic_energy, argnums=1)(body, q, w)
    return M_dot @ w + jnp.concatenate([cross_force(w[:6], h[:6]), -dT_dq])


def inertial_stiffening(body: ModalBody, q: Array, V: Array) -> tuple[Array, Array]:
    """(G_s (mu, 6), g_s (mu,)) with K_G q = G_s A + g_s for the body frame's spatial
    acceleration A and velocity V = (omega; v), body coordinates: eq 33's 21 temporal scalars of
    Table 1, linear in A."""
    Kq = jnp.einsum("qst,t->sq", body.inertial_stiffening, q)           # (mu, 21)
    w, v = V[:3], V[3:]
    s0 = inertial_scalars(jnp.cross(w, v), jnp.zeros(3, q.dtype), w)     # A = 0
    return Kq @ jnp.asarray(_DS_DA, q.dtype), Kq @ s0
