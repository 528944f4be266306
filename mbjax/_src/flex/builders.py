"""From a beam finite-element model to a `ModalBody` (Anderson 1993 §2.2 and the Appendix).

`beam_body` chains the structural side (`mbjax._src.flex.beam`, `modal`, `points`, `stiffening`):
the reduced stiffness phi^T K phi, the mass-point cloud of the modal shapes, the 21 inertial and
the distal unit-load geometric stiffness matrices (eq 33, Table 1), and the shapes at the grid
points where other bodies or cut joints attach.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from mbjax._src.flex.beam import Beam
from mbjax._src.flex.body import ModalBody
from mbjax._src.flex.modal import ModalBasis, reduced, whole_nodes
from mbjax._src.flex.points import mass_points, node_shapes
from mbjax._src.flex.stiffening import distal_stiffening, inertial_stiffening


def beam_body(beam: Beam, basis: ModalBasis, nodes=(), *, clamped_node: int = 0,
              stiffening: bool = True, damping=None) -> ModalBody:
    """The modal body of `beam` in `basis`, ready for a `FlexibleModel`.

    Chains the structural side (Anderson 1993 §2.2 and the Appendix): the reduced stiffness
    phi^T K phi, the mass-point cloud of the modal shapes, the 21 inertial and the distal
    unit-load geometric stiffness matrices (Anderson 1993 eq 33, Table 1) and the shapes at the
    grid points where other bodies or cut joints attach.

    Args:
        beam: the beam.
        basis: its modal basis (e.g. `craig_bampton(beam, ...)`), clamped at `clamped_node`.
        nodes (Sequence[int]): beam nodes where child bodies, cut joints and markers attach: index i
            of `nodes` is attachment point i (what `FlexibleModel`'s `attach` and `markers` refer
            to).
        clamped_node: the node at the body frame's origin, the joint grid J^k.
        stiffening: include geometric stiffening; False leaves it out (the prematurely
            linearized model).
        damping (Array | None): modal damping, shape (mu, mu); None: none.

    Returns:
        The `ModalBody`.

    Raises:
        ValueError: a basis built for a beam of another number of nodes or clamped at
            another node, a node outside the beam or not a whole number, or damping not of
            shape (mu, mu).
    """
    nodes = whole_nodes("beam_body", "nodes", nodes) if len(nodes) else ()
    (clamped_node,) = whole_nodes("beam_body", "clamped_node", clamped_node)
    if basis.shapes.shape[0] != 6 * beam.n_nodes:
        raise ValueError(f"basis has shapes for {basis.shapes.shape[0] // 6} nodes (6 dofs each) "
                         f"but beam has {beam.n_nodes}: build the basis from this beam "
                         "(craig_bampton(beam, ...))")
    outside = [h for h in (*nodes, clamped_node) if not 0 <= h < beam.n_nodes]
    if outside:
        raise ValueError(f"nodes and clamped_node must be nodes of the beam (0 ... "
                         f"{beam.n_nodes - 1}), got {outside}")
    held = basis.shapes[6 * clamped_node:6 * clamped_node + 6]
    if not isinstance(held, jax.core.Tracer) and bool(jnp.any(held != 0)):   # concrete only
        raise ValueError(f"basis moves clamped_node {clamped_node} (the body frame's joint "
                         "grid): build it with craig_bampton(beam, clamped_node="
                         f"{clamped_node}, ...)")
    return _beam_body(beam, basis, nodes, clamped_node, stiffening, damping)


@eqx.filter_jit
def _beam_body(beam: Beam, basis: ModalBasis, nodes: tuple, clamped_node: int,
               stiffening: bool, damping) -> ModalBody:
    """`beam_body` once its arguments are checked."""
    _, K_r = reduced(beam, basis)
    index = np.asarray(nodes, dtype=int)
    node_position = jnp.zeros((len(nodes), 3)).at[:, 0].set(beam.node_x()[index])
    shapes = [node_shapes(basis, h) for h in nodes]
    node_psi = jnp.stack([psi for psi, _ in shapes]) if nodes else jnp.zeros((0, 3, basis.mu))
    node_phi = jnp.stack([phi for _, phi in shapes]) if nodes else jnp.zeros((0, 3, basis.mu))
    return ModalBody.from_points(
        mass_points(beam, basis), K_r, damping=damping,
        inertial_stiffening=inertial_stiffening(beam, basis, clamped_node) if stiffening else None,
        nodes=(node_position, node_phi, node_psi),
        distal_stiffening=(distal_stiffening(beam, basis, nodes, clamped_node)
                           if stiffening and nodes else None))
