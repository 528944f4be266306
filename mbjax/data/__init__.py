"""Model files shipped with mbjax, for the examples and the tests.

`ARM7`: a 7-dof arm (the Franka Emika Panda's joint layout and limits, uniform-cylinder link
inertias; a fixed flange link on the last joint), `mbjax.load_urdf(mbjax.data.ARM7)`.

`ANT`, `HALF_CHEETAH`: gymnasium's MuJoCo Ant and HalfCheetah (gymnasium 1.4.0, MIT License,
unchanged), for the contact examples: `mbjax.load_mjcf(mbjax.data.ANT)` (MuJoCo reads them).
"""

from pathlib import Path

ARM7 = Path(__file__).parent / "arm7.urdf"
ANT = Path(__file__).parent / "ant.xml"
HALF_CHEETAH = Path(__file__).parent / "half_cheetah.xml"

__all__ = ["ANT", "ARM7", "HALF_CHEETAH"]
