"""Paper reproductions: `mbjax reproduce NAME` writes NAME.json and NAME.png.

Each entry is reproduce(out: Path, quick: bool) -> dict (the JSON written).
"""

from mbjax.reproduce import integrators, tree_scaling

REPRODUCTIONS = {
    integrators.NAME: integrators.reproduce,
    tree_scaling.NAME: tree_scaling.reproduce,
}

__all__ = ["REPRODUCTIONS"]
