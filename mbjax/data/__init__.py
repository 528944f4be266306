"""Model files shipped with mbjax, for the examples and the tests.

`ARM7`: a 7-dof arm (the Franka Emika Panda's joint layout and limits, uniform-cylinder link
inertias; a fixed flange link on the last joint), `mbjax.load_urdf(mbjax.data.ARM7)`.
"""

from pathlib import Path

ARM7 = Path(__file__).parent / "arm7.urdf"

__all__ = ["ARM7"]
