"""The accuracy status of time elements (issue 23): `solve_tfe(..., rtol=, atol=)` estimates
the final state's error by step doubling and the drift of the body's invariants, and flags
INACCURATE past the tolerance. Checked against the closed form of the torque-free body (Borri
1990 §8.1) and on the top whose primal element is unstable (§7)."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax import lie
from mbjax_harness.reproduce import top_long_run as tlr
from mbjax_harness.reproduce import torque_free_tfe as tft
from mbjax.scenes import torque_free_body as tfb
from mbjax.scenes import vertical_top as vt
from mbjax.tfe import Element, Mixed, PrimalUnsymmetric, initial_state, solve_tfe


@pytest.mark.slow     # 50 s; tests/integrate/test_accuracy checks the estimate
def test_the_estimate_follows_the_closed_form_error():
    body, state0 = tft.scene()
    element, spacing = Element(2), 0.015
    n = int(round(1.0 / element.length(spacing)))
    sol = solve_tfe(body, state0, dt=spacing, n_elements=n, form=Mixed(), element=element,
                    reference=tft.REFERENCE, rtol=1e-3, atol=1e-4)
    error = float(jnp.max(jax.vmap(tfb.rotation_error_matrix)(sol.R, sol.ts)))
    assert error / 10 < float(sol.error) < 10 * error, (error, float(sol.error))
    assert error > 1e-3 and sol.messages()[0].startswith("inaccurate (estimated error")
    # the drift: the energy and the angular momentum, from the solution's own records
    E, h = np.asarray(sol.energy(body)), np.asarray(sol.angular_momentum(body))
    kinetic = jax.vmap(body.kinetic_energy)(sol.R, sol.p_hat)
    expected = max(np.max(np.abs(E - E[0])) / np.max(kinetic),
                   np.max(np.abs(h - h[0])) / np.max(np.linalg.norm(h, axis=-1)))
    assert float(sol.drift) == pytest.approx(expected, rel=1e-9, abs=1e-15)
    plain = solve_tfe(body, state0, dt=spacing, n_elements=n, form=Mixed(), element=element,
                      reference=tft.REFERENCE)
    assert plain.messages() == ["success"] and np.isnan(plain.error) and np.isnan(plain.drift)


def test_the_unstable_primal_element_is_flagged_and_the_mixed_one_is_not():
    """The top at 1.01 Omega_c with 2-node elements of 0.5 s about the steady rotation, 20 s:
    the primal form's tilt grows from 1e-4 to 0.05 rad (0.37 rad by 40 s) and said success
    before; the mixed form keeps the physical tilt (below 1e-3 rad)."""
    body = vt.build()
    spin = tlr.SPIN_RATIO * vt.CRITICAL_SPIN
    state0 = initial_state(body, lie.exp(jnp.array([tlr.TILT0, 0.0, 0.0])),
                           jnp.array([0.0, 0.0, spin]))
    runs = {}
    for name, form in (("primal", PrimalUnsymmetric()), ("mixed", Mixed())):
        runs[name] = solve_tfe(body, state0, dt=tlr.DT, n_elements=40, form=form,
                               element=Element(2), reference=tlr.steady_rotation(spin),
                               **tlr.TOLERANCE)
    assert runs["primal"].messages() == ["inaccurate (estimated error 0.0258 beyond the "
                                         "tolerance; first at t = 20 s)"]
    assert float(np.max(tlr.tilt_of(runs["primal"].R))) > 0.04
    assert runs["mixed"].messages() == ["success"]
    assert float(np.max(tlr.tilt_of(runs["mixed"].R))) < 1e-3


def test_bad_tolerances_are_refused_by_name():
    body, state0 = tft.scene()
    for rtol, atol, error in ((0.0, 0.0, ValueError), (-1.0, 1e-3, ValueError),
                              ("1e-3", None, TypeError)):
        with pytest.raises(error, match="rtol"):
            solve_tfe(body, state0, dt=0.01, n_elements=2, rtol=rtol, atol=atol)
