"""Flexible bodies: beam finite elements, modal reduction, geometric stiffening (seed 002)."""

from mbjax.flex.ancf import AncfBeam, AncfSolution, simulate as simulate_ancf, stable_step
from mbjax.flex.references import slider_crank_reference, spin_up_beam_reference, spin_up_theta
from mbjax.flex.ancf import simulate_embedded
