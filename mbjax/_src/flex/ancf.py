"""Planar absolute-nodal-coordinate (ANCF) beam: an independent, geometrically exact reference for
the modal flexible bodies of Anderson 1993 (§3.1 slider-crank, §3.2 spin-up beam, geometric stiffening
eqs 32-33).

The element is the planar gradient-deficient beam of Berzeri & Shabana (J. Sound Vib. 235, 2000)
with the "elastic line" strain measures of Gerstmayr & Irschik (J. Sound Vib. 318, 2008):

- node coordinates (x, y, dx/ds, dy/ds); element coordinates e_k = (r_A, r_A', r_B, r_B') of its
  two nodes, global index 4 * node + i, so element k owns the contiguous slice 4k ... 4k + 7;
- cubic Hermite interpolation r(s) = S(xi) e_k, xi = s_local / l, S = [h1 I, h2 I, h3 I, h4 I];
- constant consistent mass matrix M = int rhoA S^T S ds (exact with the Gauss rule below);
- U(e) = 1/2 int (EA eps^2 + EI kappa^2) ds with the engineering axial strain eps = |r'| - 1 and
  the curvature kappa = (r' x r'')_z / |r'|^3. Linearised about the straight state, eps -> u' and
  kappa -> v'', so small-strain frequencies are Euler-Bernoulli's; the axial law is linear in
  the stretch (Green strain would add an artificial hardening at large stretch). |r'| - 1 couples
  transverse slopes into the axial strain (eps ~ u' + v'^2 / 2), which is the geometric
  stiffening that Anderson 1993 adds to modal models by eqs 32-33.
- Gauss-Legendre quadrature with `n_gauss` points per element (default 5: exact for the mass
  matrix (degree 6), and for eps and kappa, which are not polynomials, converged: the stiffness
  at the straight state is a degree-4 polynomial, exact from 3 points on).

Dynamics with prescribed coordinates (`simulate`): coordinates split into free f and prescribed p
(static index sets), e_p(t) a user function of time whose velocities and accelerations come from
`jax.jvp`; M_ff e_f'' = -dU/de_f - M_fp e_p''(t) + Q_f (gravity, applied generalized forces).
`simulate_embedded` generalises this to e = embed(t, q) affine in q (e.g. a clamp that prescribes
the slope's direction but not its length). No damping. Time stepping is classical RK4 in one
jitted `lax.scan`, the step set by the highest frequency of the linearised system (`stable_step`,
the axial modes: omega_max ~ 49 n sqrt(EA / rhoA) / L). The cost grows as n^2 (steps ~ n, work per
step ~ n); run times of the spin-up reference are in benchmarks/README.md.
"""

from collections.abc import Callable

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.system.status import Flags, flags, Status, WithStatus, raise_on_failure


def _hermite(xi, l):  # noqa: E741 (the element length, as in the ANCF papers)
    """Cubic Hermite shape functions h(xi) and their s-derivatives, xi in [0, 1], element length l.
    Returns (h, h_s, h_ss), each (..., 4) in the order (r_A, r_A', r_B, r_B')."""
    h = jnp.stack([1 - 3 * xi**2 + 2 * xi**3, l * (xi - 2 * xi**2 + xi**3), 3 * xi**2 - 2 * xi**3,
                   l * (xi**3 - xi**2)], -1)
    h_s = jnp.stack([-6 * xi + 6 * xi**2, l * (1 - 4 * xi + 3 * xi**2), 6 * xi - 6 * xi**2,
                     l * (3 * xi**2 - 2 * xi)], -1) / l
    h_ss = jnp.stack([-6 + 12 * xi, l * (-4 + 6 * xi), 6 - 12 * xi, l * (6 * xi - 2)], -1) / l**2
    return h, h_s, h_ss


class AncfBeam(eqx.Module):
    """Uniform planar ANCF beam of `n_elements` equal elements (Berzeri & Shabana 2000; Gerstmayr
    & Irschik 2008): an independent, geometrically exact reference for the modal flexible
    bodies of Anderson 1993 (§3.1 slider-crank, §3.2 spin-up beam, geometric stiffening
    eqs 32-33).

    Coordinates e: shape (4 * (n_elements + 1),), node n at e[4n : 4n + 4] =
    (x, y, dx/ds, dy/ds). Material parameters are array leaves (differentiable).

    Args:
        length (float): length [m].
        EA (float): axial stiffness [N].
        EI (float): bending stiffness [N m^2].
        rhoA (float): mass per length [kg/m].
        n_elements (int): number of equal elements, >= 1; static.
        n_gauss (int): Gauss points per element, >= 3; static.

    Raises:
        ValueError: n_elements < 1 or n_gauss < 3.

    More on the element: the documentation site's Details page (docs/details.md).
    """

    length: Array
    EA: Array
    EI: Array
    rhoA: Array
    n_elements: int = eqx.field(static=True)
    n_gauss: int = eqx.field(static=True, default=5)

    def __init__(self, length, EA, EI, rhoA, n_elements, n_gauss=5):
        if n_elements < 1 or n_gauss < 3:
            raise ValueError("AncfBeam needs n_elements >= 1 and n_gauss >= 3")
        self.length, self.EA, self.EI, self.rhoA = (jnp.asarray(v, float) for v in (length, EA, EI, rhoA))
        self.n_elements, self.n_gauss = int(n_elements), int(n_gauss)

    @property
    def n_coordinates(self) -> int:
        """Number of coordinates, 4 per node."""
        return 4 * (self.n_elements + 1)

    @property
    def element_length(self) -> Array:
        """Element length [m]."""
        return self.length / self.n_elements

    @property
    def element_dofs(self) -> np.ndarray:
        """(n_elements, 8) global indices of each element's coordinates."""
        return 4 * np.arange(self.n_elements)[:, None] + np.arange(8)

    def _gauss(self):
        xi, w = np.polynomial.legendre.leggauss(self.n_gauss)
        return jnp.asarray((xi + 1) / 2), jnp.asarray(w / 2)

    @eqx.filter_jit
    def initial_coordinates(self, origin=(0.0, 0.0), angle=0.0) -> Array:
        """Coordinates of the straight, unstrained beam.

        Args:
            origin: position of node 0 [m], shape (2,).
            angle: direction of the beam from the x axis [rad].

        Returns:
            e, shape (n_coordinates,).
        """
        t = jnp.stack([jnp.cos(angle), jnp.sin(angle)])
        s = jnp.linspace(0.0, 1.0, self.n_elements + 1)[:, None] * self.length
        r = jnp.asarray(origin, float) + s * t
        return jnp.concatenate([r, jnp.broadcast_to(t, r.shape)], 1).ravel()

    def _interp(self, e, s):
        k = jnp.clip(jnp.floor(s / self.element_length), 0, self.n_elements - 1).astype(int)
        ek = jax.lax.dynamic_slice(e, (4 * k,), (8,)).reshape(4, 2)
        return _hermite(s / self.element_length - k, self.element_length), ek

    def position(self, e, s) -> Array:
        """r(s) = S(s) e: the position [m], shape (2,), of the point at arc length s in
        [0, length] of the reference configuration, for coordinates e (n_coordinates,)."""
        (h, _, _), ek = self._interp(e, s)
        return h @ ek

    def slope(self, e, s) -> Array:
        """r'(s) = dr/ds at arc length s, shape (2,), for coordinates e (n_coordinates,)."""
        (_, h_s, _), ek = self._interp(e, s)
        return h_s @ ek

    @eqx.filter_jit
    def mass_matrix(self) -> Array:
        """Consistent mass M = sum_k int rhoA S^T S ds, scatter-added over elements (constant),
        shape (n_coordinates, n_coordinates)."""
        xi, w = self._gauss()
        h, _, _ = _hermite(xi, self.element_length)
        Me = self.rhoA * self.element_length * jnp.kron(jnp.einsum("g,gi,gj->ij", w, h, h), jnp.eye(2))
        dofs = self.element_dofs
        Me = jnp.broadcast_to(Me, (self.n_elements, 8, 8))
        return jnp.zeros((self.n_coordinates,) * 2).at[dofs[:, :, None], dofs[:, None, :]].add(Me)

    def strains(self, e) -> tuple[Array, Array]:
        """(eps, kappa) at the Gauss points, each (n_elements, n_gauss)."""
        xi, _ = self._gauss()
        _, h_s, h_ss = _hermite(xi, self.element_length)
        E = e[self.element_dofs].reshape(self.n_elements, 4, 2)
        rp, rpp = jnp.einsum("gi,kij->kgj", h_s, E), jnp.einsum("gi,kij->kgj", h_ss, E)
        n = jnp.linalg.norm(rp, axis=-1)
        return n - 1, (rp[..., 0] * rpp[..., 1] - rp[..., 1] * rpp[..., 0]) / n**3

    def elastic_energy(self, e) -> Array:
        """U(e) = 1/2 int (EA eps^2 + EI kappa^2) ds by Gauss quadrature (Gerstmayr & Irschik),
        a scalar [J], for coordinates e (n_coordinates,)."""
        _, w = self._gauss()
        eps, kappa = self.strains(e)
        return 0.5 * self.element_length * jnp.sum(w * (self.EA * eps**2 + self.EI * kappa**2))

    def elastic_force(self, e) -> Array:
        """Q_e = -dU/de, shape (n_coordinates,)."""
        return -jax.grad(self.elastic_energy)(e)

    def kinetic_energy(self, e_dot) -> Array:
        """T = e_dot^T M e_dot / 2 [J], a scalar."""
        return 0.5 * e_dot @ self.mass_matrix() @ e_dot

    def gravity_force(self, g) -> Array:
        """Q_g = int rhoA S^T g ds = M e_g with e_g the coordinates of the uniform field r(s) = g
        (positions g, slopes 0), which the Hermite interpolation reproduces exactly.

        Args:
            g: gravitational acceleration [m/s^2], shape (2,).

        Returns:
            Q_g, shape (n_coordinates,).
        """
        eg = jnp.tile(jnp.concatenate([jnp.asarray(g, float), jnp.zeros(2)]), self.n_elements + 1)
        return self.mass_matrix() @ eg


class AncfSolution(WithStatus):
    """The beam's coordinates e and rates e_dot at the save times ts; `status` NONFINITE where
    the run blew up (a step past RK4's stability, `stable_step`)."""

    ts: Array       # (n_saves,)
    e: Array        # (n_saves, n_coordinates)
    e_dot: Array    # (n_saves, n_coordinates)
    status: Flags = eqx.field(converter=flags)
    dt: float = eqx.field(static=True)      # the largest RK4 step used


def _split(n, prescribed):
    p = np.asarray(sorted(prescribed), int)
    if len(set(p.tolist())) != len(p) or (len(p) and (p[0] < 0 or p[-1] >= n)):
        raise ValueError("prescribed indices must be distinct coordinates of the beam")
    return np.setdiff1d(np.arange(n), p), p


def _kinematics(embed, t, q, q_dot):
    """(e, e_dot, G = de/dq, c) for e = embed(t, q) affine in q, so that e_ddot = G q_ddot + c
    with c = d^2/dtau^2 embed(t + tau, q + tau q_dot) at tau = 0 (nested jax.jvp)."""
    def path(tau):
        return embed(t + tau, q + tau * q_dot)
    one = jnp.ones_like(t)
    (e, e_dot), (_, c) = jax.jvp(lambda tau: jax.jvp(path, (tau,), (one,)), (0.0 * t,), (one,))
    return e, e_dot, jax.jacfwd(embed, argnums=1)(t, q), c


def stable_step(beam: AncfBeam, e, prescribed=(), safety=0.5, G=None) -> float:
    """RK4 step safety * 2.83 / omega_max, omega_max the highest frequency of the linearised
    system at e: K_q x = omega^2 M_q x with K_q = G^T K G, M_q = G^T M G, K the hessian of U and G
    the free columns (or a given de/dq). RK4's stability interval on the imaginary axis is
    |omega dt| < 2 sqrt 2."""
    G = np.eye(beam.n_coordinates)[:, _split(beam.n_coordinates, prescribed)[0]] if G is None else G
    omega_max = float(_highest_frequency(beam, jnp.asarray(e), jnp.asarray(G)))
    return safety * 2.0 * np.sqrt(2.0) / omega_max


@jax.jit
def _highest_frequency(beam: AncfBeam, e, G) -> Array:
    """omega_max of `stable_step`, one compiled program."""
    K = G.T @ jax.hessian(beam.elastic_energy)(e) @ G
    Lc = jnp.linalg.cholesky(G.T @ beam.mass_matrix() @ G)
    A = jax.scipy.linalg.solve_triangular(Lc, jax.scipy.linalg.solve_triangular(Lc, K, lower=True).T,
                                          lower=True)
    return jnp.sqrt(jnp.max(jnp.linalg.eigvalsh((A + A.T) / 2)))


def simulate_embedded(beam: AncfBeam, embed: Callable, q0, q_dot0, ts, *, dt: float | None = None,
                      safety: float = 0.5, gravity=None, force: Callable | None = None,
                      constant_mass: bool = False, throw: bool = False) -> AncfSolution:
    """Beam coordinates given by generalized coordinates q through e = embed(t, q), affine in q
    (prescribed coordinates, a prescribed slope direction with free magnitude, ...). Lagrange's
    equations: (G^T M G) q_ddot = G^T (Q - M c), G = de/dq, c as in `_kinematics`, Q = -dU/de +
    M e_g (`gravity` g) + `force(t, e, e_dot)`. Classical RK4 in one jitted lax.scan; each interval
    of the concrete, increasing save times ts is split into the same number of equal steps <= dt,
    dt defaulting to `stable_step` at t = ts[0]. `constant_mass`: G does not depend on t, so
    G^T M G is factored once. The status says NONFINITE where the run blew up; throw=True
    raises instead (as `mbjax.simulate`)."""
    ts = np.asarray(ts, float)
    q0, q_dot0 = jnp.asarray(q0, float), jnp.asarray(q_dot0, float)
    M = beam.mass_matrix()

    @jax.jit
    def start(t, q):              # e, G = de/dq and the Cholesky factor of G^T M G at ts[0]
        e, G = embed(t, q), jax.jacfwd(embed, argnums=1)(t, q)
        return e, G, jnp.linalg.cholesky(G.T @ M @ G)

    e0, G0, L0 = start(jnp.asarray(ts[0]), q0)
    dt = stable_step(beam, e0, safety=safety, G=G0) if dt is None else float(dt)
    m = max(1, int(np.ceil(np.max(np.diff(ts), initial=0.0) / dt)))
    Qg = jnp.zeros(beam.n_coordinates) if gravity is None else beam.gravity_force(gravity)

    def rhs(t, y):
        q, q_dot = y
        e, e_dot, G, c = _kinematics(embed, t, q, q_dot)
        Q = beam.elastic_force(e) + Qg + (0.0 if force is None else force(t, e, e_dot))
        Lq = L0 if constant_mass else jnp.linalg.cholesky(G.T @ M @ G)
        return q_dot, jax.scipy.linalg.cho_solve((Lq, True), G.T @ (Q - M @ c))

    def rk4(carry, _):
        (t, y), h = carry
        k1 = rhs(t, y)
        k2 = rhs(t + h / 2, jax.tree.map(lambda a, b: a + h / 2 * b, y, k1))
        k3 = rhs(t + h / 2, jax.tree.map(lambda a, b: a + h / 2 * b, y, k2))
        k4 = rhs(t + h, jax.tree.map(lambda a, b: a + h * b, y, k3))
        y = jax.tree.map(lambda a, b1, b2, b3, b4: a + h / 6 * (b1 + 2 * b2 + 2 * b3 + b4), y, k1, k2, k3, k4)
        return ((t + h, y), h), None

    def save(t, y):
        e, e_dot, _, _ = _kinematics(embed, t, *y)
        return e, e_dot

    def interval(y, t01):
        ((_, y), _), _ = jax.lax.scan(rk4, ((t01[0], y), (t01[1] - t01[0]) / m), None, length=m)
        return y, save(t01[1], y)

    @jax.jit
    def run(y0):
        _, (es, eds) = jax.lax.scan(interval, y0, jnp.stack([ts[:-1], ts[1:]], 1))
        e_0, ed_0 = save(jnp.asarray(ts[0]), y0)
        return jnp.concatenate([e_0[None], es]), jnp.concatenate([ed_0[None], eds])

    es, eds = run((q0, q_dot0))
    finite = jnp.all(jnp.isfinite(es)) & jnp.all(jnp.isfinite(eds))
    status = jnp.where(finite, 0, int(Status.NONFINITE)).astype(jnp.int32)
    return raise_on_failure(AncfSolution(ts=jnp.asarray(ts), e=es, e_dot=eds, status=status,
                                         dt=float(dt)), throw, "mbjax.flex.simulate_ancf")


def simulate_ancf(beam: AncfBeam, e0, e_dot0, ts, *, prescribed=(), e_p: Callable | None = None,
             **kwargs) -> AncfSolution:
    """Simulate an ANCF beam with some coordinates prescribed: M_ff e_f'' = -dU/de_f -
    M_fp e_p''(t) + Q_f from (e0, e_dot0) at ts[0].

    Classical RK4 in one jitted `lax.scan` (time stepping below); each interval of ts is split
    into equal steps no longer than dt.

    Args:
        beam: the beam.
        e0 (Array): initial coordinates, shape (n_coordinates,) (prescribed entries ignored).
        e_dot0 (Array): initial rates, shape (n_coordinates,) (prescribed entries ignored).
        ts (Array): save times [s], concrete and increasing, shape (n_saves,); the run starts at
            ts[0].
        prescribed (Sequence[int]): static global indices of the prescribed coordinates.
        e_p: a differentiable callable t -> the prescribed coordinates' values, shape
            (len(prescribed),) (positions only; velocities and accelerations by jax.jvp);
            required when `prescribed` is not empty.
        **kwargs: dt (the largest step [s], default `stable_step` at ts[0]), safety (the
            factor on RK4's stability limit, 0.5), gravity (shape (2,) [m/s^2]), force (a
            callable (t, e, e_dot) -> generalized forces, shape (n_coordinates,)) and throw, as
            in `simulate_embedded`.

    Returns:
        An `AncfSolution`: ts, e and e_dot at the save times (shape (n_saves, n_coordinates)),
            `status` (NONFINITE where the run blew up) and the step dt used.

    Raises:
        ValueError: prescribed indices repeated or outside the beam, or prescribed coordinates
            without e_p; with throw=True, a failed run.

    Time stepping:
        The coordinates split into free f and prescribed p (static index sets), e_p(t) a user
        function of time whose velocities and accelerations come from `jax.jvp`;
        M_ff e_f'' = -dU/de_f - M_fp e_p''(t) + Q_f (gravity, applied generalized forces). No
        damping. Time stepping is classical RK4 in one jitted `lax.scan`, the step set by the
        highest frequency of the linearised system (`stable_step`, the axial modes:
        omega_max ~ 49 n sqrt(EA / rhoA) / L). The cost grows as n^2 (steps ~ n, work per step
        ~ n); run times of the spin-up reference are in benchmarks/README.md.
    """
    f, p = _split(beam.n_coordinates, prescribed)
    if len(p) and e_p is None:
        raise ValueError("prescribed coordinates need e_p(t)")
    def embed(t, q):
        return jnp.zeros(beam.n_coordinates, q.dtype).at[f].set(q).at[p].set(
            e_p(t) if len(p) else jnp.zeros(0))
    return simulate_embedded(beam, embed, jnp.asarray(e0, float)[f], jnp.asarray(e_dot0, float)[f], ts,
                             constant_mass=True, **kwargs)
