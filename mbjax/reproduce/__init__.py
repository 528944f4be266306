"""Paper reproductions: `mbjax reproduce NAME` writes NAME.json and NAME.png.

Each entry is reproduce(out: Path, quick: bool) -> dict (the JSON written).
"""

from mbjax.reproduce import integrators

REPRODUCTIONS = {
    integrators.NAME: integrators.reproduce,
}

__all__ = ["REPRODUCTIONS"]
