"""Paper reproductions: `mbjax reproduce NAME` writes NAME.json and NAME.png.

Each entry is reproduce(out: Path, quick: bool) -> dict (the JSON written).
"""

from mbjax_harness.reproduce import (andrews_squeezer, carpal_wrist, closed_chain, flexible_slider_crank, gradient_matrix,
                             integrators, model_corpus, spin_up_beam, top_long_run, torque_free_tfe, trajopt,
                             tree_scaling, vertical_top)

REPRODUCTIONS = {
    integrators.NAME: integrators.reproduce,
    tree_scaling.NAME: tree_scaling.reproduce,
    vertical_top.NAME: vertical_top.reproduce,
    torque_free_tfe.NAME: torque_free_tfe.reproduce,
    top_long_run.NAME: top_long_run.reproduce,
    closed_chain.NAME: closed_chain.reproduce,
    andrews_squeezer.NAME: andrews_squeezer.reproduce,
    spin_up_beam.NAME: spin_up_beam.reproduce,
    flexible_slider_crank.NAME: flexible_slider_crank.reproduce,
    carpal_wrist.NAME: carpal_wrist.reproduce,
    gradient_matrix.NAME: gradient_matrix.reproduce,
    model_corpus.NAME: model_corpus.reproduce,
    trajopt.NAME: trajopt.reproduce,
}

__all__ = ["REPRODUCTIONS"]
