"""Straight 3-D beam finite elements: the structural model M x_dd + K x = 0 of Anderson 1993 eq (9).

Conventions (used by `modal`, `points` and `stiffening` too):

- The beam runs from node 0 at the body-frame origin along the body x axis; the element frame is
  the body frame, so no rotation between local and body components is needed.
- Node dofs are ordered (ux, uy, uz, rx, ry, rz): displacements, then small rotations, so global dof
  6 i + d belongs to node i. For Euler-Bernoulli bending rz = duy/dx and ry = -duz/dx.
- Bending in the xy plane (uy, rz) uses Iz; bending in the xz plane (uz, ry) uses Iy; torsion (rx)
  uses G J for stiffness and the polar moment Iy + Iz for inertia.
- Timoshenko elements use the interdependent interpolation (Przemieniecki's stiffness; the shape
  functions of Friedman and Kosmatka) with Phi = 12 E I / (kappa G A Le^2); Phi = 0 is Euler-Bernoulli.

The decoupled dof groups of a straight beam (axial ux; torsion rx; xy bending uy, rz; xz bending
uz, ry) are solved as separate eigenproblems (`dof_groups`), so that the equal frequencies of the
two bending planes of a symmetric section do not make eigenvector gradients singular.
"""

from __future__ import annotations

import functools
import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

__all__ = [
    "Beam",
    "axial_forces",
    "dof_groups",
    "eigenmodes",
    "element_mass",
    "element_stiffness",
    "free_dofs",
    "geometric_stiffness",
    "interpolation",
]

# dof -> decoupled group of a straight beam: 0 axial, 1 torsion, 2 xy bending, 3 xz bending
_GROUP = np.array([0, 2, 3, 1, 3, 2])
_PLANAR = {None: (0, 1, 2, 3, 4, 5), "xy": (0, 1, 5), "xz": (0, 2, 4)}


def _check_positive(name, value):
    if isinstance(value, jax.core.Tracer):
        return
    v = np.asarray(value)
    if not np.all(np.isfinite(v)) or np.any(v <= 0):
        raise ValueError(f"Beam: {name} must be positive and finite, got {value!r}")


def _whole(x) -> bool:
    """Whether x is a whole number (an int, or a float with no fraction), not a bool."""
    return (isinstance(x, int | float | np.integer | np.floating) and not isinstance(x, bool)
            and math.isfinite(x) and x == int(x))


class Beam(eqx.Module):
    """Uniform straight beam along the body x axis, n_elements equal 2-node, 12-dof elements.

    The structural model M x_dd + K x = 0 of Anderson 1993 eq (9) (`matrices`), with the dof
    conventions in docs/details.md. Array fields are differentiable leaves (float64);
    `n_elements` and `timoshenko` are static. `Beam.round` and `Beam.rectangle` build solid
    sections.

    Args:
        L (float): length [m].
        E (float): Young's modulus [Pa].
        G (float): shear modulus [Pa].
        rho (float): density [kg/m^3].
        A (float): cross-section area [m^2].
        Iy (float): second moment of area about the section's y axis [m^4] (bending in the xz
            plane).
        Iz (float): second moment of area about the section's z axis [m^4] (bending in the xy
            plane).
        J (float): torsion constant [m^4].
        n_elements (int): number of equal elements, an integer >= 1; static.
        timoshenko (bool): shear-deformable (Timoshenko) elements instead of Euler-Bernoulli;
            static.
        kappa (float): shear correction factor (used with `timoshenko`).

    Raises:
        ValueError: a parameter that is not positive and finite, or a bad n_elements.

    More on conventions: the documentation site's Details page (docs/details.md).
    """

    L: jax.Array
    E: jax.Array
    G: jax.Array
    rho: jax.Array
    A: jax.Array
    Iy: jax.Array
    Iz: jax.Array
    J: jax.Array
    kappa: jax.Array
    n_elements: int = eqx.field(static=True)
    timoshenko: bool = eqx.field(static=True)

    def __init__(self, L, E, G, rho, A, Iy, Iz, J, n_elements=10, *, timoshenko=False, kappa=5.0 / 6.0):
        if not _whole(n_elements) or n_elements < 1:
            raise ValueError(f"Beam: n_elements must be an integer >= 1, got {n_elements!r}")
        for name, v in dict(L=L, E=E, G=G, rho=rho, A=A, Iy=Iy, Iz=Iz, J=J, kappa=kappa).items():
            _check_positive(name, v)
            setattr(self, name, jnp.asarray(v, dtype=jnp.float64))
        self.n_elements = int(n_elements)
        self.timoshenko = bool(timoshenko)

    @classmethod
    def round(cls, L, diameter, E, rho, nu=None, G=None, n_elements=10, *, timoshenko=False, kappa=5.0 / 6.0):
        """A beam of solid circular section: A = pi d^2/4, Iy = Iz = pi d^4/64, J = pi d^4/32.

        Args:
            L: length [m].
            diameter: section diameter d [m].
            E: Young's modulus [Pa].
            rho: density [kg/m^3].
            nu: Poisson's ratio, giving G = E / (2 (1 + nu)); give exactly one of nu and G.
            G: shear modulus [Pa].
            n_elements: number of equal elements.
            timoshenko: shear-deformable elements.
            kappa: shear correction factor, 5/6 by default (Cowper's 6 (1 + nu) / (7 + 6 nu) =
                0.886 at nu = 0.3 may be passed instead).

        Returns:
            The `Beam`.

        Raises:
            ValueError: both or neither of nu and G, or a parameter that is not positive.
        """
        if (nu is None) == (G is None):
            raise ValueError("Beam.round: give exactly one of nu or G")
        _check_positive("diameter", diameter)
        d = jnp.asarray(diameter, dtype=jnp.float64)
        G = jnp.asarray(E, dtype=jnp.float64) / (2.0 * (1.0 + nu)) if G is None else G
        I = math.pi * d**4 / 64.0  # noqa: E741 (the second moment of area)
        return cls(L, E, G, rho, math.pi * d**2 / 4.0, I, I, 2.0 * I, n_elements,
                   timoshenko=timoshenko, kappa=kappa)

    @classmethod
    def rectangle(cls, L, width, height, E, rho, nu=None, G=None, n_elements=10, *, timoshenko=False,
                  kappa=5.0 / 6.0):
        """A beam of solid rectangular section: Iy = w h^3/12, Iz = h w^3/12, and Saint-Venant's
        J ~ a b^3 (1/3 - 0.21 (b/a) (1 - b^4 / (12 a^4))) with a >= b the sides.

        Args:
            L: length [m].
            width: section width w along y [m].
            height: section height h along z [m].
            E: Young's modulus [Pa].
            rho: density [kg/m^3].
            nu: Poisson's ratio, giving G = E / (2 (1 + nu)); give exactly one of nu and G.
            G: shear modulus [Pa].
            n_elements: number of equal elements.
            timoshenko: shear-deformable elements.
            kappa: shear correction factor, 5/6 by default.

        Returns:
            The `Beam`.

        Raises:
            ValueError: both or neither of nu and G, or a parameter that is not positive.
        """
        if (nu is None) == (G is None):
            raise ValueError("Beam.rectangle: give exactly one of nu or G")
        _check_positive("width", width)
        _check_positive("height", height)
        w, h = jnp.asarray(width, dtype=jnp.float64), jnp.asarray(height, dtype=jnp.float64)
        a, b = jnp.maximum(w, h), jnp.minimum(w, h)
        J = a * b**3 * (1.0 / 3.0 - 0.21 * b / a * (1.0 - b**4 / (12.0 * a**4)))
        G = jnp.asarray(E, dtype=jnp.float64) / (2.0 * (1.0 + nu)) if G is None else G
        return cls(L, E, G, rho, w * h, w * h**3 / 12.0, h * w**3 / 12.0, J, n_elements,
                   timoshenko=timoshenko, kappa=kappa)

    @property
    def n_nodes(self) -> int:
        """Number of nodes, n_elements + 1 (node 0 at the body-frame origin)."""
        return self.n_elements + 1

    @property
    def n_dofs(self) -> int:
        """Number of dofs, 6 per node."""
        return 6 * self.n_nodes

    @property
    def Le(self):
        """Element length [m]."""
        return self.L / self.n_elements

    @property
    def shear_factors(self):
        """(Phi_xy, Phi_xz) = 12 E (Iz, Iy) / (kappa G A Le^2); zeros for Euler-Bernoulli."""
        if not self.timoshenko:
            return jnp.zeros(()), jnp.zeros(())
        c = 12.0 * self.E / (self.kappa * self.G * self.A * self.Le**2)
        return c * self.Iz, c * self.Iy

    def node_x(self):
        """Undeformed node positions along the body x axis, (N,)."""
        return jnp.arange(self.n_nodes) * self.Le

    def element_dofs(self) -> np.ndarray:
        """Global dof indices of each element, (n_elements, 12) (static)."""
        return 6 * np.arange(self.n_elements)[:, None] + np.arange(12)[None, :]

    def matrices(self):
        """Assembled consistent mass and stiffness of the free beam, Anderson 1993 eq (9).

        Returns:
            (M, K), each shape (6N, 6N) for N = n_nodes, dofs ordered node by node as
            (ux, uy, uz, rx, ry, rz): global dof 6 i + d belongs to node i (the class's
            conventions).
        """
        return _matrices(self)


@eqx.filter_jit
def _matrices(beam: Beam):
    n = beam.n_elements
    Me = jnp.broadcast_to(element_mass(beam), (n, 12, 12))
    Ke = jnp.broadcast_to(element_stiffness(beam), (n, 12, 12))
    return _assemble(beam, Me), _assemble(beam, Ke)


def _assemble(beam: Beam, ke):
    """Scatter-add element matrices (n_elements, 12, 12) into the global (6N, 6N) matrix."""
    idx = beam.element_dofs()
    return jnp.zeros((beam.n_dofs, beam.n_dofs), ke.dtype).at[idx[:, :, None], idx[:, None, :]].add(ke)


def _hermite(xi, Phi, Le):
    """Interdependent (Timoshenko) interpolation of one bending plane at xi = x / Le in [0, 1]:
    deflection w and section rotation theta against (w1, theta1, w2, theta2); Phi = 0 gives the
    Hermite cubics with theta = dw/dx."""
    c = 1.0 / (1.0 + Phi)
    w = c * jnp.stack([2 * xi**3 - 3 * xi**2 - Phi * xi + 1 + Phi,
                       Le * (xi**3 - (2 + Phi / 2) * xi**2 + (1 + Phi / 2) * xi),
                       -2 * xi**3 + 3 * xi**2 + Phi * xi,
                       Le * (xi**3 - (1 - Phi / 2) * xi**2 - Phi / 2 * xi)])
    t = c * jnp.stack([6.0 / Le * (xi**2 - xi),
                       3 * xi**2 - (4 + Phi) * xi + 1 + Phi,
                       -6.0 / Le * (xi**2 - xi),
                       3 * xi**2 - (2 - Phi) * xi])
    return w, t


def interpolation(beam: Beam, xi):
    """Element interpolation at xi = x / Le: (Nt, Nr), each (3, 12), mapping the element's 12 dofs to
    the centroid's displacement (ux, uy, uz) and the section's small rotation (rx, ry, rz).

    Axial and torsion linear; bending by `_hermite` (rz = duy/dx, ry = -duz/dx for Euler-Bernoulli)."""
    Le = beam.Le
    Pxy, Pxz = beam.shear_factors
    wy, ty = _hermite(xi, Pxy, Le)
    wz, tz = _hermite(xi, Pxz, Le)
    zero = jnp.zeros(())
    lin = jnp.stack([1.0 - xi, xi])

    def row(pairs):
        r = [zero] * 12
        for i, v in pairs:
            r[i] = v
        return jnp.stack(r)

    Nt = jnp.stack([row([(0, lin[0]), (6, lin[1])]),
                    row([(1, wy[0]), (5, wy[1]), (7, wy[2]), (11, wy[3])]),
                    row([(2, wz[0]), (4, -wz[1]), (8, wz[2]), (10, -wz[3])])])
    Nr = jnp.stack([row([(3, lin[0]), (9, lin[1])]),
                    row([(2, -tz[0]), (4, tz[1]), (8, -tz[2]), (10, tz[3])]),
                    row([(1, ty[0]), (5, ty[1]), (7, ty[2]), (11, ty[3])])])
    return Nt, Nr


def _gauss(n):
    x, w = np.polynomial.legendre.leggauss(n)
    return jnp.asarray((x + 1.0) / 2.0), jnp.asarray(w / 2.0)


def element_mass(beam: Beam):
    """Consistent 12x12 element mass, integral over the element of
    rho A Nt^T Nt + Nr^T diag(rho (Iy + Iz), rho Iy, rho Iz) Nr dx (translation, rotary inertia of
    the section, torsion), by 4-point Gauss quadrature, exact for the cubic interpolation."""
    xi, w = _gauss(4)
    Nt, Nr = jax.vmap(lambda x: interpolation(beam, x))(xi)
    Ir = beam.rho * jnp.stack([beam.Iy + beam.Iz, beam.Iy, beam.Iz])
    Mt = beam.rho * beam.A * jnp.einsum("g,gik,gil->kl", w, Nt, Nt)
    Mr = jnp.einsum("g,i,gik,gil->kl", w, Ir, Nr, Nr)
    return beam.Le * (Mt + Mr)


def element_stiffness(beam: Beam):
    """12x12 element stiffness of Przemieniecki (Theory of Matrix Structural Analysis, 1968, sec. 5.6),
    with shear deformation through Phi (Timoshenko) or Phi = 0 (Euler-Bernoulli)."""
    Le, E = beam.Le, beam.E
    Pxy, Pxz = beam.shear_factors

    def bend(EI, Phi, s):
        # (w1, theta1, w2, theta2); s = -1 flips theta for the xz plane (ry = -duz/dx)
        c = EI / ((1.0 + Phi) * Le**3)
        return c * jnp.array([[12.0, s * 6 * Le, -12.0, s * 6 * Le],
                              [s * 6 * Le, (4 + Phi) * Le**2, -s * 6 * Le, (2 - Phi) * Le**2],
                              [-12.0, -s * 6 * Le, 12.0, -s * 6 * Le],
                              [s * 6 * Le, (2 - Phi) * Le**2, -s * 6 * Le, (4 + Phi) * Le**2]])

    bar = jnp.array([[1.0, -1.0], [-1.0, 1.0]]) / Le
    K = jnp.zeros((12, 12))
    K = K.at[np.ix_([0, 6], [0, 6])].set(E * beam.A * bar)
    K = K.at[np.ix_([3, 9], [3, 9])].set(beam.G * beam.J * bar)
    K = K.at[np.ix_([1, 5, 7, 11], [1, 5, 7, 11])].set(bend(E * beam.Iz, Pxy, 1.0))
    return K.at[np.ix_([2, 4, 8, 10], [2, 4, 8, 10])].set(bend(E * beam.Iy, Pxz, -1.0))


def geometric_stiffness(beam: Beam, axial_force, torsion=True):
    """Assembled geometric stiffness (6N, 6N) for per-element axial forces N_e (tension positive).

    Anderson 1993 eq (32) (Banerjee and Dickens) with only the axial prestress sigma_xx0 = N_e / A: the
    bending and shear stresses of eq (32) are dropped, the usual beam approximation, so transverse
    loads and moments do not stiffen a straight beam. Integrated over the section (centroidal axes),
    eq (32) gives N_e times the integral of uy'^2 + uz'^2 (+ (Iy + Iz)/A rx'^2 with `torsion`) over
    the element, with the element's own interpolation; the small axial (ux'^2) and section-rotation
    (Iz/A rz'^2, Iy/A ry'^2) terms are dropped as well. For Euler-Bernoulli the bending part is
    N/(30 Le) [36, 3Le, -36, 3Le; ...], the standard consistent form.

    Args:
        beam: the beam.
        axial_force: each element's axial force N_e [N], tension positive, shape (n_elements,).
        torsion (bool): include the torsional term (Iy + Iz)/A rx'^2.

    Returns:
        K_G, shape (n_dofs, n_dofs), in the beam's dof order (6 per node; see `Beam`) and linear
            in the axial forces: with unit forces and torsion=False, q^T K_G q / 2 is the axial
            shortening (1/2) int (uy'^2 + uz'^2) dx of a deflection q.
    """
    kg = _unit_geometric_stiffness(beam, torsion)
    return _assemble(beam, jnp.asarray(axial_force)[:, None, None] * kg)


def _unit_geometric_stiffness(beam: Beam, torsion=True):
    """Element geometric stiffness (12, 12) per unit axial force, Anderson 1993 eq (32) (see above)."""
    xi, w = _gauss(4)
    dNt = jax.vmap(jax.jacfwd(lambda x: interpolation(beam, x)[0]))(xi) / beam.Le
    dNr = jax.vmap(jax.jacfwd(lambda x: interpolation(beam, x)[1]))(xi) / beam.Le
    kg = jnp.einsum("g,gik,gil->kl", w, dNt[:, 1:], dNt[:, 1:])
    if torsion:
        kg = kg + (beam.Iy + beam.Iz) / beam.A * jnp.einsum("g,gk,gl->kl", w, dNr[:, 0], dNr[:, 0])
    return beam.Le * kg


def axial_forces(beam: Beam, u):
    """Element axial forces EA (ux2 - ux1) / Le (tension positive) from nodal displacements u (6N,)
    or (6N, k) (one column per load case): (n_elements,) or (n_elements, k)."""
    ux = u[0::6]
    return beam.E * beam.A * (ux[1:] - ux[:-1]) / beam.Le


def free_dofs(beam: Beam, clamped_nodes=(0,), planar=None) -> np.ndarray:
    """Sorted global indices of the unconstrained dofs (static numpy).

    Args:
        beam: the beam.
        clamped_nodes: nodes whose six dofs are all held.
        planar: "xy" keeps only ux, uy, rz (axial + in-plane bending), "xz" keeps ux, uz, ry,
            None keeps all six per node.

    Returns:
        The free dof indices, a NumPy int array.

    Raises:
        ValueError: an unknown `planar` or a clamped node outside the beam.
    """
    if planar not in _PLANAR:
        raise ValueError(f"free_dofs: planar must be None, 'xy' or 'xz', got {planar!r}")
    clamped = np.atleast_1d(np.asarray(clamped_nodes, dtype=int))
    if np.any((clamped < 0) | (clamped >= beam.n_nodes)):
        raise ValueError(f"free_dofs: clamped nodes {tuple(clamped)} outside 0..{beam.n_nodes - 1}")
    mask = np.zeros((beam.n_nodes, 6), bool)
    mask[:, list(_PLANAR[planar])] = True
    mask[clamped] = False
    return np.flatnonzero(mask.ravel())


def dof_groups(free) -> tuple[np.ndarray, ...]:
    """Split free dof indices into the decoupled groups of a straight beam (axial, torsion, xy
    bending, xz bending), dropping empty ones (static)."""
    free = np.asarray(free)
    g = _GROUP[free % 6]
    return tuple(free[g == k] for k in range(4) if np.any(g == k))


@jax.custom_jvp
def _eigh(A):
    """`jnp.linalg.eigh` whose eigenvector tangent drops the 1/(lam_j - lam_i) terms of (numerically)
    equal eigenvalues. A symmetric perturbation of a symmetric structure (both bending planes of a
    round section) does not couple such a pair, so the dropped term is 0 * inf, not information."""
    lam, V = jnp.linalg.eigh(A)
    return lam, V


@_eigh.defjvp
def _eigh_jvp(primals, tangents):
    (A,), (dA,) = primals, tangents
    lam, V = _eigh(A)
    B = V.T @ (0.5 * (dA + dA.T)) @ V
    gap = lam[None, :] - lam[:, None]
    tol = 1e-9 * jnp.max(jnp.abs(lam))
    F = jnp.where(jnp.abs(gap) > tol, 1.0 / jnp.where(jnp.abs(gap) > tol, gap, 1.0), 0.0)
    return (lam, V), (jnp.diagonal(B), V @ (F * B))


def _eigh_generalized(M, K):
    """K x = lam M x with M = L L^T: eigh of L^-1 K L^-T; returns lam and M-orthonormal x."""
    Lc = jnp.linalg.cholesky(M)
    solve = jax.scipy.linalg.solve_triangular
    A = solve(Lc, solve(Lc, K, lower=True).T, lower=True)
    lam, Y = _eigh(0.5 * (A + A.T))
    return lam, solve(Lc.T, Y, lower=False)


def eigenmodes(M, K, free, groups=None):
    """Generalized symmetric eigenproblem of Anderson 1993 eq (9) on the free dofs.

    Cholesky M_ff = L L^T, then `jnp.linalg.eigh` of L^-1 K_ff L^-T. `groups` (static index arrays
    partitioning `free`, e.g. `dof_groups(free)`) splits uncoupled blocks into separate eigenproblems
    (same result; finite gradients when two blocks share a frequency). Returns angular frequencies
    (n_free,) in rad/s ascending and mass-normalised shapes (6N, n_free), zero on constrained dofs."""
    free = np.asarray(free)
    groups = (free,) if groups is None else tuple(np.asarray(g) for g in groups)
    if sorted(np.concatenate(groups).tolist()) != sorted(free.tolist()):
        raise ValueError("eigenmodes: groups must partition the free dofs")
    return _eigenmodes(M, K, tuple(tuple(int(d) for d in g) for g in groups))


@functools.partial(jax.jit, static_argnames="groups")
def _eigenmodes(M, K, groups):
    lams, cols = [], []
    for g in map(np.array, groups):  # a handful of static blocks, not elements
        lam, X = _eigh_generalized(M[np.ix_(g, g)], K[np.ix_(g, g)])
        lams.append(lam)
        cols.append(jnp.zeros((M.shape[0], len(g)), X.dtype).at[g].set(X))
    lam, X = jnp.concatenate(lams), jnp.concatenate(cols, axis=1)
    order = jnp.argsort(lam)
    return jnp.sqrt(lam[order]), X[:, order]
