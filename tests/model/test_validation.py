"""Bad model data at build time (issue 23): each refused with a message that names the body,
joint or field, and what was given; rotations that are rotations to round-off accepted."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mbjax import lie
from mbjax.model import Model
from mbjax._src.tree import Topology

INERTIA = np.tile(np.eye(3) * 0.1, (2, 1, 1))


def _model(parents=(-1, 0), joint_types="revolute", **kw):
    return Model(list(parents), joint_types, **{"mass": [1.0, 1.0], "inertia": INERTIA, **kw})


@pytest.mark.parametrize(("kwargs", "message"), [
    (dict(com=[[np.nan, 0, 0], [0, 0, 0]]), "com of 'body0' must be finite"),
    (dict(placement_translation=[[0, 0, 0], [np.inf, 0, 0]]),
     "placement_translation of 'body1' must be finite"),
    (dict(gravity=[0, 0, np.nan]), "gravity must be finite"),
    (dict(placement_rotation=np.stack([np.eye(3), 2 * np.eye(3)])),
     "placement_rotation of 'body1' is not orthonormal"),
    (dict(placement_rotation=np.stack([np.diag([1.0, 1, -1]), np.eye(3)])),
     r"placement_rotation of 'body0' is a reflection \(det -1\)"),
    (dict(joint_types="universal", axis=[[0, 0, 1.0]] * 2, axis2=[[0, 0, -3.0]] * 2),
     "body 'body0': the universal joint's axis .* are parallel"),
    (dict(axis=[[0, 0, 0.0], [0, 0, 1]]), "body 'body0': the revolute joint's axis is zero"),
    (dict(parents=(-1, 0.7)), "parents must be body indices"),
    (dict(mass=[1 + 1j, 1.0]), r"mass must be real numbers of shape \(2,\)"),
    (dict(mass="heavy"), "mass must be real numbers"),
    (dict(mass=[np.nan, 1.0]), "body 'body0': mass and inertia must be finite"),
    (dict(frame_names=("tool",), frame_parents=(1,), frame_translation=[[np.nan, 0, 0]]),
     "frame_translation of 'tool' must be finite"),
    (dict(frame_names=("tool",), frame_parents=(1,), frame_rotation=[3 * np.eye(3)]),
     "frame_rotation of 'tool' is not orthonormal"),
    (dict(damping=[0.0, np.inf]), r"damping must be non-negative and finite; joint 'joint1'"),
    (dict(friction=[-1.0, 0.0]), r"friction must be non-negative and finite; joint 'joint0'"),
    (dict(effort_limit=[1.0, np.nan]), r"effort_limit must be non-negative; joint 'joint1'"),
    (dict(lower=[0.0, 1.0], upper=[1.0, 0.5]), r"lower must not exceed upper; joint 'joint1'"),
])
def test_bad_model_data_is_refused_by_name(kwargs, message):
    with pytest.raises((ValueError, TypeError), match=message):
        _model(**kwargs)


def _rotation(q):
    q = np.asarray(q, float)
    return np.asarray(lie.quat_to_matrix(q / np.linalg.norm(q)))


quaternions = st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(
    lambda q: np.linalg.norm(q) > 0.1)


@settings(max_examples=40, deadline=None)
@given(quaternions, st.floats(1e-4, 1.0), st.integers(0, 8))
def test_perturbed_rotations_are_refused_and_rotations_accepted(q, size, entry):
    R = _rotation(q)
    _model(placement_rotation=np.stack([R, R.T]))            # a rotation to round-off: builds
    bad = R.copy()
    bad.flat[entry] += size
    with pytest.raises(ValueError, match="placement_rotation of 'body1' is not orthonormal"):
        _model(placement_rotation=np.stack([R, bad]))


def test_integer_valued_float_parents_are_indices():
    assert Topology(np.array([-1.0, 0.0, 1.0])).parents == (-1, 0, 1)
