"""In which order `load_urdf` visits the children of a link: the strategy it takes as
`sibling_order=`.

Bodies are numbered depth-first from the root; the order among the joints below one link decides
the numbering where a link has several children. Pinocchio (through urdfdom, which keeps joints in
a name-sorted map) visits them in order of joint name (`ByName`, the default); MuJoCo's URDF import
visits them in document order (`InDocument`).
"""

import abc

import equinox as eqx


class AbstractSiblingOrder(eqx.Module):
    """The order `load_urdf` visits the child joints of a link in (`ByName`, `InDocument`),
    passed as `sibling_order=`.

    A subclass implements `order`.
    """

    @abc.abstractmethod
    def order(self, joints: list) -> list:
        """The child joints of one link in visiting order.

        Args:
            joints: the `<joint>` elements whose parent is the link, in document order.

        Returns:
            The same elements, reordered.
        """


class ByName(AbstractSiblingOrder):
    """Children in order of joint name, as Pinocchio numbers its joints (the default)."""

    def order(self, joints: list) -> list:
        """The joints sorted by their `name` attribute.

        Args:
            joints: the `<joint>` elements whose parent is the link, in document order.

        Returns:
            The joints sorted by name.
        """
        return sorted(joints, key=lambda j: j.get("name"))


class InDocument(AbstractSiblingOrder):
    """Children in document order, as MuJoCo's URDF import numbers its bodies."""

    def order(self, joints: list) -> list:
        """The joints as they come in the document.

        Args:
            joints: the `<joint>` elements whose parent is the link, in document order.

        Returns:
            The joints, in document order.
        """
        return list(joints)


def check_sibling_order(sibling_order) -> AbstractSiblingOrder:
    """`sibling_order` itself, or a TypeError naming the argument and the strategies.

    Raises:
        TypeError: sibling_order is not a sibling-order strategy (the strings "name" and
            "document" of earlier versions included).
    """
    if not isinstance(sibling_order, AbstractSiblingOrder):
        hint = ""
        if isinstance(sibling_order, str):
            hint = (f" (the string {sibling_order!r} is no longer accepted: \"name\" is ByName(), "
                    "\"document\" is InDocument())")
        raise TypeError(f"sibling_order must be a sibling-order strategy, mbjax.model.ByName() or "
                        f"mbjax.model.InDocument(), got {type(sibling_order).__name__}{hint}")
    return sibling_order
