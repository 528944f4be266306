"""The Carpal Wrist at and beyond its singularities (issue 23): measures right at both kinds,
including all three legs singular at once, a SINGULAR status from `WristSystem`, and inverse
kinematics that refuses a pose outside its chart instead of answering another pose."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax import simulate
from mbjax.integrate import RK4
from mbjax._src.integrate import Status
from mbjax.scenes import carpal_wrist as cw
from mbjax._src.wrist import kinematics as kin
from mbjax._src.wrist.system import WristSystem

WRIST = cw.wrist()
LEGS_UP = jnp.full(3, jnp.pi / 2)     # every knee at the top of its circle: all three tangent


def test_measures_at_all_three_inverse_singularities_at_once():
    m = WRIST.singularity_measures(LEGS_UP)
    assert abs(float(m.inverse)) < 1e-12 and float(m.direct) == pytest.approx(1.0)
    # J = dN/dg K^-1 D vanishes whole here; the condition measure still reads 0
    assert np.allclose(kin.jacobian_closed_form(WRIST, LEGS_UP), 0.0, atol=1e-15)
    assert float(m.condition) < 1e-12
    home = WRIST.singularity_measures(cw.home(WRIST))
    assert 0.01 < float(home.condition) <= 1.0 and float(home.inverse) > 0.5


def test_the_condition_measure_vanishes_on_approach_to_either_kind():
    """Along a path into each singularity the measure falls to 0 with the distance."""
    rb, length = float(WRIST.base_radius), float(WRIST.link_length)
    rho = 0.5 * rb * np.array([1.0, 1.0, -0.5])          # rho1 rho2 + rho2 rho3 + rho3 rho1 = 0
    direct = np.arccos((rb - rho) / length)
    home = np.asarray(cw.home(WRIST))
    for target in (direct, np.asarray(LEGS_UP)):
        values = [float(WRIST.singularity_measures(jnp.asarray(target + s * (home - target)))
                        .condition) for s in (1e-1, 1e-2, 1e-3)]
        assert values[0] > values[1] > values[2] and values[2] < 1e-2 * values[0], values


def test_the_measures_agree_at_the_symmetric_poses():
    """theta = (t, t, t): where the knees' projections meet in one point (rho_i = rb - l cos t = 0
    together, t = arccos(rb / l)) K is singular, and the direct measure reads 0 there (it read 1,
    all rho_i being equal, while the condition read 5e-18); legs up (t = pi / 2) is the inverse
    singularity. Everywhere the condition vanishes exactly where one of the two measures does,
    and K's smallest singular value (numpy's, from the knees' positions) with the direct one."""
    rb, length = float(WRIST.base_radius), float(WRIST.link_length)
    meet = np.arccos(rb / length)
    grid = np.concatenate([np.linspace(0.05, 3.0, 60), [meet, np.pi / 2]])
    m = jax.vmap(lambda t: WRIST.singularity_measures(jnp.full(3, t)))(jnp.asarray(grid))
    direct, inverse, condition = (np.asarray(x) for x in (m.direct, m.inverse, m.condition))
    knees = np.asarray(jax.vmap(lambda t: kin.knees(WRIST, jnp.full(3, t)))(jnp.asarray(grid)))
    K = np.concatenate([np.ones((len(grid), 3, 1)), knees[:, :, :2]], axis=2)
    smallest = np.linalg.svd(K, compute_uv=False)[:, -1]
    assert direct[-2] < 1e-12 and condition[-2] < 1e-12 and smallest[-2] < 1e-12
    assert abs(inverse[-1]) < 1e-12 and condition[-1] < 1e-12
    nearest = np.minimum(np.abs(inverse), np.abs(direct))
    assert np.all((condition < 1e-9) == (nearest < 1e-9)), (grid, condition, nearest)
    assert np.all((direct < 1e-9) == (smallest < 1e-9))
    away = nearest > 0.05
    assert np.all(condition[away] > 1e-4), condition[away].min()
    system = WristSystem(WRIST)
    assert int(system.check(0.0, jnp.full(3, meet), jnp.zeros(3))) & Status.SINGULAR


def test_simulate_reports_singular_and_not_far_away():
    system = WristSystem(WRIST)
    at = simulate(system, RK4(), LEGS_UP, jnp.zeros(3), dt=1e-3, t1=0.01)
    assert int(at.status) & Status.SINGULAR and not bool(at.ok)
    away = simulate(system, RK4(), cw.home(WRIST), jnp.zeros(3), dt=1e-3, t1=0.01)
    assert away.messages() == ["success"]


@pytest.mark.parametrize("beta", [np.pi, 3.5, -4.0, 2 * np.pi - 0.1, np.nan])
def test_inverse_kinematics_outside_the_chart(beta):
    """|beta| >= pi (or NaN) is not a pose of the chart: refused, and not 'reachable'; at
    2 pi - 0.1 the slope is that of the pose bent by 0.1 the other way, which is reachable."""
    assert not bool(kin.reachable(WRIST, 0.3, beta, 0.075))
    with pytest.raises(eqx.EquinoxRuntimeError, match="outside the .* chart"):
        jax.block_until_ready(WRIST.inverse_kinematics(0.3, beta, 0.075))
    assert bool(kin.reachable(WRIST, 0.3 + np.pi, 0.1, 0.075))


@pytest.mark.parametrize(("change", "message"), [
    (dict(base_radius=-0.06), "base_radius must be positive"),
    (dict(link_length=np.nan), "link_length must be positive and finite"),
    (dict(tool_mass=0.0), "tool_mass must be positive"),
    (dict(tool_inertia=np.eye(3) * np.nan), "tool_inertia must be finite"),
    (dict(tool_com=(np.nan, 0.0, 0.0)), "tool_com must be finite"),
    (dict(gravity=np.inf), "gravity must be finite"),
])
def test_wrist_parameters_are_validated(change, message):
    from mbjax.wrist import CarpalWrist

    args = {**dict(base_radius=0.06, link_length=0.1, tool_mass=1.0,
                   tool_inertia=np.eye(3) * 1e-3), **change}
    with pytest.raises(ValueError, match=message):
        CarpalWrist(args.pop("base_radius"), args.pop("link_length"), **args)


_CHART = jax.jit(lambda a, b, p: (kin.in_chart(a, b, p),
                                  *kin.solve_inverse_kinematics(WRIST, p,
                                                                kin.slope_from_angles(a, b))))
_MIDPLANE = jax.jit(lambda theta: kin.midplane(WRIST, theta))


def _wide_floats(low, high):
    from hypothesis import strategies as st

    return st.one_of(st.floats(low, high), st.sampled_from([np.nan, np.inf, -np.inf, high * 3]))


def test_inverse_kinematics_never_answers_another_pose():
    """Hypothesis over chart coordinates, in, at the edge of and far outside the chart and the
    workspace (NaN and infinities included): inverse kinematics either raises or returns joint
    angles whose forward kinematics is the pose asked for; never a silent other pose."""
    from hypothesis import HealthCheck, given, settings

    @settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(_wide_floats(-4.0, 4.0), _wide_floats(-4.0, 4.0), _wide_floats(-0.3, 0.3))
    def check(alpha, beta, plunge):
        inside, theta, reachable = _CHART(alpha, beta, plunge)
        if bool(inside) and bool(reachable):
            p, g = _MIDPLANE(theta)
            assert abs(float(p) - plunge) < 1e-9
            np.testing.assert_allclose(g, kin.slope_from_angles(alpha, beta), atol=1e-9)
            np.testing.assert_allclose(WRIST.inverse_kinematics(alpha, beta, plunge), theta,
                                       rtol=0, atol=1e-12)
        else:
            with pytest.raises(eqx.EquinoxRuntimeError, match="outside the .* chart|out of reach"):
                jax.block_until_ready(WRIST.inverse_kinematics(alpha, beta, plunge))

    check()
