"""6-D spatial algebra with vectors ordered (angular; linear), as in Jerkovsky 1978 and Anderson 1993.

A motion vector is (omega; v), a force vector (torque; force). A Plucker transform X from frame A to
frame B is stored as a 6x6 matrix; X^T maps forces back from B to A.
"""

from mbjax._src.spatial.algebra import (
    check_inertia as check_inertia,
    cross_force as cross_force,
    cross_motion as cross_motion,
    inertia_matrix as inertia_matrix,
    plucker as plucker,
    shift_force as shift_force,
    skew as skew,
)
