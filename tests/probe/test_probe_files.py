"""Probes of the model files (`mbjax.load_urdf`, `mbjax.load_mjcf`) (issue 43, item 5): malformed
and edge-case XML drawn by hypothesis, as strings and as files, each answered by a clear error
naming what is wrong, a warning and a status, or the right answer against an independent
reference (a pendulum's closed-form angular acceleration); never a silent NaN.

Every drawn model is the same one-joint pendulum, so its dynamics compile once per format."""

import atexit
import os
import shutil
import tempfile
import warnings
from functools import partial
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from hypothesis import Phase, given, settings
from hypothesis import strategies as st

import mbjax
from mbjax import Status
from mbjax.integrate import RK4
from mbjax.model import ModelWarning
from mbjax.rigid import TreeSystem

# XLA flushes subnormal numbers to zero on the CPU: draws keep clear of them
floats = partial(st.floats, allow_subnormal=False)
FEW = settings(max_examples=15, deadline=None)
DEFECT = settings(max_examples=10, deadline=None, phases=[Phase.explicit, Phase.generate])
G = 9.81
FOLDER = Path(tempfile.mkdtemp(prefix="mbjax-probe-files-"))
atexit.register(shutil.rmtree, FOLDER, ignore_errors=True)


def urdf(joint="continuous", axis="0 1 0", mass="1.5", com="0.5 0 0", inertia=None,
         origin="0 0 0", limit="", dynamics="", root="robot", inertial=True):
    inertia = inertia or 'ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"'
    body = (f'<inertial><origin xyz="{com}"/><mass value="{mass}"/><inertia {inertia}/></inertial>'
            if inertial else "")
    return (f'<{root} name="probe"><link name="base"/><link name="arm">{body}</link>'
            f'<joint name="hinge" type="{joint}"><origin xyz="{origin}"/><parent link="base"/>'
            f'<child link="arm"/><axis xyz="{axis}"/>{limit}{dynamics}</joint></{root}>')


def mjcf(joint='type="hinge" axis="0 1 0"', inertial='pos="0.5 0 0" mass="1.5" diaginertia="0.1 0.1 0.1"'):
    return (f'<mujoco><option gravity="0 0 {-G}"/><worldbody><body name="arm">'
            f'<joint name="hinge" {joint}/><inertial {inertial}/></body></worldbody></mujoco>')


def _source(text: str, as_file: bool, suffix: str):
    if not as_file:
        return text
    handle, name = tempfile.mkstemp(suffix=suffix, dir=FOLDER)
    with os.fdopen(handle, "w") as file:
        file.write(text)
    return Path(name)


@jax.jit
def _acceleration(model, q, v):
    return mbjax.forward_dynamics(model, q, v, jnp.zeros_like(v))


def _pendulum(m, arm, inertia, sign, damping, armature, q, v):
    """A mass m at distance `arm` along the x axis of a link turning about sign * y, gravity -z:
    q_ddot = (sign m g arm cos q - d v) / (I_yy + m arm^2 + armature)."""
    return (sign * m * G * arm * np.cos(q) - damping * v) / (inertia + m * arm**2 + armature)


pendulums = dict(m=floats(0.1, 10), arm=floats(0.05, 2), inertia=floats(1e-3, 1),
                 scale=floats(1e-2, 1e2), sign=st.sampled_from([1.0, -1.0]),
                 damping=floats(0, 2), armature=floats(0, 0.5), q=floats(-np.pi, np.pi),
                 v=floats(-5, 5), as_file=st.booleans())


# -- the right answer --------------------------------------------------------------------------------

@FEW
@given(**pendulums)
def test_a_urdf_pendulum_accelerates_as_the_closed_form(m, arm, inertia, scale, sign, damping,
                                                        armature, q, v, as_file):
    """Also: the axis is normalized (any positive length), a file reads as its string."""
    text = urdf(axis=f"0 {sign * scale!r} 0", mass=repr(m), com=f"{arm!r} 0 0",
                inertia=f'ixx="{inertia!r}" iyy="{inertia!r}" izz="{inertia!r}"',
                dynamics=f'<dynamics damping="{damping!r}"/>')
    model = mbjax.load_urdf(_source(text, as_file, ".urdf"), armature=armature)
    a = _acceleration(model, jnp.array([q]), jnp.array([v]))
    np.testing.assert_allclose(a, [_pendulum(m, arm, inertia, sign, damping, armature, q, v)],
                               rtol=1e-12, atol=1e-12)


@FEW
@given(**pendulums)
def test_an_mjcf_pendulum_accelerates_as_the_closed_form(m, arm, inertia, scale, sign, damping,
                                                         armature, q, v, as_file):
    text = mjcf(joint=f'type="hinge" axis="0 {sign * scale!r} 0" damping="{damping!r}" '
                      f'armature="{armature!r}"',
                inertial=f'pos="{arm!r} 0 0" mass="{m!r}" diaginertia="{inertia!r} {inertia!r} {inertia!r}"')
    model = mbjax.load_mjcf(_source(text, as_file, ".xml"))
    a = _acceleration(model, jnp.array([q]), jnp.array([v]))
    # MuJoCo stores its numbers in float64 from the text: the same closed form
    np.testing.assert_allclose(a, [_pendulum(m, arm, inertia, sign, damping, armature, q, v)],
                               rtol=1e-10, atol=1e-10)


@FEW
@given(lower=floats(-3, 0), width=floats(0, 3), effort=floats(0.1, 100),
       velocity=floats(0.1, 100))
def test_urdf_limits_are_read_and_missing_ones_are_warned_about(lower, width, effort, velocity):
    upper = lower + width
    limit = (f'<limit lower="{lower!r}" upper="{upper!r}" effort="{effort!r}" '
             f'velocity="{velocity!r}"/>')
    model = mbjax.load_urdf(urdf(joint="revolute", limit=limit))
    np.testing.assert_array_equal([model.lower[0], model.upper[0], model.effort_limit[0],
                                   model.velocity_limit[0]], [lower, upper, effort, velocity])
    with pytest.warns(ModelWarning, match="'hinge' \\(revolute\\) has no <limit>"):
        model = mbjax.load_urdf(urdf(joint="revolute"))
    assert model.lower[0] == -np.inf and model.upper[0] == np.inf
    with pytest.raises(ValueError, match="has no <limit>"):
        mbjax.load_urdf(urdf(joint="revolute"), strict=True)


# -- malformed URDF ----------------------------------------------------------------------------------

KINDS = ("revolute", "continuous", "prismatic", "floating", "fixed")


def _malformed_urdf(defect, value):
    """(text, the expected error) for each kind of defect, `value` a drawn detail."""
    if defect == "joint type":
        return urdf(joint=value), rf"joint 'hinge' has unknown or unsupported type '{value}'"
    if defect == "zero axis":
        return urdf(axis="0 0 0"), "joint 'hinge' has a zero axis"
    if defect == "short axis":
        return urdf(axis=value), "joint 'hinge' axis must be 3 numbers"
    if defect == "nonfinite axis":
        return urdf(axis=f"0 {value} 0"), "joint 'hinge' axis must be finite"
    if defect == "nonfinite origin":
        return urdf(origin=f"{value} 0 0"), "joint 'hinge' origin xyz must be finite"
    if defect == "nonfinite mass":
        return urdf(mass=value), "link 'arm' mass must be finite"
    if defect == "negative mass":
        return urdf(mass=f"-{value}"), "body 'arm': mass must be positive"
    if defect == "crossed limits":
        return (urdf(joint="revolute", limit=f'<limit lower="1" upper="{value}" effort="1" '
                                               'velocity="1"/>'),
                "lower must not exceed upper; joint 'hinge'")
    if defect == "nan limit":
        return (urdf(joint="prismatic", limit='<limit lower="nan" upper="1" effort="1" velocity="1"/>'),
                "joint 'hinge' lower is NaN")
    if defect == "text damping":
        return urdf(dynamics=f'<dynamics damping="{value}"/>'), "joint 'hinge' damping must be a number"
    if defect == "negative damping":
        return urdf(dynamics=f'<dynamics damping="-{value}"/>'), \
            "damping must be non-negative and finite; joint 'hinge'"
    if defect == "no mass":
        return urdf().replace('<mass value="1.5"/>', ""), "link 'arm' has <inertial> without <mass"
    if defect == "root":
        return urdf(root=value), f"the root element must be <robot>, got <{value}>"
    text = urdf()
    return text[:value], "URDF: malformed XML"                         # truncated


defects = st.one_of(
    st.tuples(st.just("joint type"), st.text("abcdefghijklmnopqrstuvwxyz_", min_size=1, max_size=10)
              .filter(lambda k: k not in KINDS)),
    st.tuples(st.sampled_from(["zero axis", "no mass"]), st.none()),
    st.tuples(st.just("short axis"), st.sampled_from(["0 1", "1", "", "0 1 0 0", "a b c", "0,1,0"])),
    st.tuples(st.sampled_from(["nonfinite axis", "nonfinite origin", "nonfinite mass"]),
              st.sampled_from(["nan", "inf", "-inf", "NaN", "1e999"])),
    st.tuples(st.sampled_from(["negative mass", "negative damping"]),
              floats(1e-6, 1e6).map(repr)),
    st.tuples(st.just("crossed limits"), floats(-10, 0.999).map(repr)),
    st.tuples(st.sampled_from(["nan limit"]), st.none()),
    st.tuples(st.just("text damping"), st.sampled_from(["abc", "1,5", "0x", "one"])),
    st.tuples(st.just("root"), st.sampled_from(["mujoco", "robots", "sdf"])),
    st.tuples(st.just("truncated"), st.integers(1, len(urdf()) - 2)),
)

# one xdist worker runs the module, so its programs compile once (the group tests/conftest.py
# adds comes after xdist has read the groups)
pytestmark = pytest.mark.xdist_group("tests/probe/test_probe_files.py")


@settings(max_examples=40, deadline=None)
@given(defects, st.booleans())
def test_malformed_urdf_is_named(defect, as_file):
    text, message = _malformed_urdf(*defect)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)
        with pytest.raises(ValueError, match=message):
            mbjax.load_urdf(_source(text, as_file, ".urdf"))


@FEW
@given(st.text("abcdefghijklmnopqrstuvwxyz0123456789_-", min_size=1, max_size=20),
       st.sampled_from([".urdf", ".xml", ""]))
def test_missing_files_are_named(name, suffix):
    path = FOLDER / "missing" / f"{name}{suffix}"
    with pytest.raises(FileNotFoundError, match=f"URDF file not found: {path}"):
        mbjax.load_urdf(path)
    with pytest.raises((FileNotFoundError, ValueError), match=str(path)):
        mbjax.load_mjcf(str(path))


@FEW
@given(mass=st.sampled_from(["0", "0.0", "1e-200", "1e-100", "1e-6"]), strict=st.booleans(),
       q=floats(-np.pi, np.pi))
def test_a_massless_moving_leaf_is_warned_about_and_flagged_and_a_point_mass_is_right(mass, strict, q):
    """A link with no mass and no inertia on a moving joint: a warning naming it (an error with
    strict=True) and, simulated anyway, a non-finite status. A tiny point mass instead (no
    inertia about its centre) is a pendulum of any mass: q_ddot = g cos(q) / 0.5 (the arm).
    (Not below about 1e-280 kg: XLA flushes subnormal products such as m z^2 to zero.)"""
    text = urdf(mass=mass, inertia='ixx="0" iyy="0" izz="0"')
    if float(mass) > 0:
        model = mbjax.load_urdf(text, strict=strict)
        a = _acceleration(model, jnp.array([q]), jnp.zeros(1))
        np.testing.assert_allclose(a, [G * np.cos(q) / 0.5], rtol=1e-12, atol=1e-12)
        return
    if strict:
        with pytest.raises(ValueError, match="body 'arm' is massless"):
            mbjax.load_urdf(text, strict=True)
        return
    with pytest.warns(ModelWarning, match="body 'arm' is massless"):
        model = mbjax.load_urdf(text)
    sol = mbjax.simulate(TreeSystem(model), RK4(), jnp.array([q]), jnp.zeros(1), dt=0.01, t1=0.03)
    finite = bool(np.isfinite(sol.qs).all() and np.isfinite(sol.vs).all())
    assert not finite and int(sol.status) & Status.NONFINITE


@FEW
@given(floats(0.1, 10).map(repr), st.booleans())
def test_rotational_inertia_without_mass_is_warned_about(inertia, strict):
    text = urdf(mass="0", inertia=f'ixx="{inertia}" iyy="{inertia}" izz="{inertia}"')
    if strict:
        with pytest.raises(ValueError, match="body 'arm' has rotational inertia but no mass"):
            mbjax.load_urdf(text, strict=True)
    else:
        with pytest.warns(ModelWarning, match="body 'arm' has rotational inertia but no mass"):
            mbjax.load_urdf(text)


@FEW
@given(st.sampled_from([mbjax.model.ByName(), mbjax.model.InDocument()]), st.text(max_size=8))
def test_sibling_orders_are_checked(good, bad):
    assert mbjax.load_urdf(urdf(), sibling_order=good).nq == 1
    with pytest.raises(TypeError, match=r"sibling_order must be .*ByName\(\) or .*InDocument\(\)"):
        mbjax.load_urdf(urdf(), sibling_order=bad)


@DEFECT
@given(st.integers(2, 5))
def test_armature_of_the_wrong_length_is_named(n):
    with pytest.raises(ValueError, match="armature"):
        mbjax.load_urdf(urdf(), armature=np.ones(n))


@DEFECT
@given(st.just(urdf().encode()))
def test_a_source_in_bytes_is_read_or_named(source):
    try:
        model = mbjax.load_urdf(source)
    except (TypeError, ValueError) as error:
        assert "source" in str(error)
        return
    assert model.nq == 1


# -- malformed MJCF ----------------------------------------------------------------------------------

mjcf_defects = st.sampled_from([
    (mjcf(joint='type="planar"'), "invalid keyword: 'planar'"),
    (mjcf(joint='type="hinge" axis="0 0 0"'), "axis too small"),
    (mjcf(joint='type="hinge" axis="0 1 0" limited="true" range="1 -1"'),
     r"range\[0\] should be smaller than range\[1\]"),
    (mjcf(inertial='pos="0.5 0 0" mass="0" diaginertia="0.1 0.1 0.1"'),
     "mass and inertia of moving bodies must be larger"),
    (mjcf(inertial='pos="0.5 0 0" mass="-1" diaginertia="0.1 0.1 0.1"'),
     "mass and inertia of moving bodies must be larger"),
    (mjcf(joint='type="hinge" axis="0 1 0" damping="-1"'),
     "damping must be non-negative and finite; joint 'hinge'"),
    (mjcf().replace('<joint name="hinge" type="hinge" axis="0 1 0"/>', ""),
     "the MuJoCo model has no joints"),
    (mjcf()[:40], "XML parse error"),
    ("<robot name='r'><link name='a'/></robot>", "the MuJoCo model has no joints"),
])


@FEW
@given(mjcf_defects, st.booleans())
def test_malformed_mjcf_is_named(defect, as_file):
    text, message = defect
    with pytest.raises(ValueError, match=message):
        mbjax.load_mjcf(_source(text, as_file, ".xml"))
