"""`Model` validation, the URDF loader (against Pinocchio and MuJoCo) and the URDF writer."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import mbjax
from mbjax import Recursive, Dense
from mbjax import rigid
from mbjax.model import Model, chain, random_tree
from mbjax._src.model.checks import ModelWarning
from mbjax._src.model.urdf import to_urdf
from mbjax_harness.peers import pinocchio_maps, random_state

I3 = 0.01 * np.eye(3)


def _model(**overrides):
    args = {"parents": [-1, 0], "joint_types": "revolute", "mass": [1.0, 2.0], "inertia": I3}
    args.update(overrides)
    return Model(args.pop("parents"), args.pop("joint_types"), **args)


def _with_body1_inertia(J):
    return np.stack([I3, np.asarray(J, dtype=float)])


# --------------------------------------------------------------------------------------------
# Model validation
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("overrides, match", [
    ({"joint_types": ("revolute", "planar")}, r"body 1: unknown joint type 'planar'; choose from"),
    ({"joint_types": ("revolute",)}, "1 joint types for 2 bodies"),
    ({"parents": [-1, 1]}, "cannot be its own parent"),
    ({"mass": [1.0, -2.0]}, r"body 'body1': mass must be positive, got -2.0"),
    ({"mass": [1.0, np.inf]}, r"body 'body1': mass and inertia must be finite, got mass inf"),
    ({"inertia": _with_body1_inertia([[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])},
     "must be symmetric"),
    ({"inertia": _with_body1_inertia(np.diag([1.0, np.nan, 1.0]))}, "must be finite"),
    ({"mass": [1.0, 2.0, 3.0]}, r"mass must have shape \(2,\), got \(3,\)"),
    ({"inertia": np.ones((2, 3, 4))}, r"inertia must have shape \(2, 3, 3\)"),
    ({"com": np.zeros((2, 2))}, r"com must have shape \(2, 3\)"),
    ({"axis": np.ones((3, 3))}, r"axis must have shape \(2, 3\)"),
    ({"placement_rotation": np.ones((2, 2, 2))}, r"placement_rotation must have shape \(2, 3, 3\)"),
    ({"gravity": [0.0, -9.81]}, r"gravity must have shape \(3,\)"),
    ({"names": ["only_one"]}, "1 names and 2 joint names for 2 bodies"),
])
def test_model_rejects_bad_input(overrides, match):
    with pytest.raises(ValueError, match=match):
        _model(**overrides)


@pytest.mark.parametrize("overrides, match", [
    ({"mass": [1.0, 0.0]}, "has rotational inertia but no mass"),
    ({"mass": [1.0, 0.0], "inertia": _with_body1_inertia(np.zeros((3, 3)))},
     "massless and carries no other body.*armature"),
    ({"inertia": _with_body1_inertia(np.diag([1.0, -1.0, 1.0]))}, "not positive semi-definite"),
    ({"inertia": _with_body1_inertia(np.diag([1.0, 1.0, -1e-9]))}, "negative by round-off"),
    ({"inertia": _with_body1_inertia(np.diag([1.0, 1.0, 2.5]))},
     r"violate the triangle inequality J1 \+ J2 >= J3"),
], ids=["rotor_without_mass", "massless_leaf", "indefinite", "round_off", "triangle"])
def test_model_warns_on_implausible_but_computable_data(overrides, match):
    """Implausible data loads with a ModelWarning naming the body (Pinocchio computes with it);
    strict=True makes it an error."""
    with pytest.warns(ModelWarning, match="body 'body1'.*" + match):
        _model(**overrides)
    with pytest.raises(ValueError, match=match + ".*strict=True"):
        _model(strict=True, **overrides)


def test_model_rejects_zero_axis():
    with pytest.raises(ValueError, match="axis"):
        _model(axis=[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])


def test_model_accepts_massless_link_carrying_bodies_and_broadcasts_fields():
    """A massless intermediate link is allowed (it carries body 2); one 3x3 inertia and one axis
    are broadcast to every body; axes are normalized."""
    model = Model([-1, 0, 0], "revolute", mass=[0.0, 1.0, 1.0],
                  inertia=np.stack([np.zeros((3, 3)), I3, I3]), axis=[0.0, 0.0, 2.0])
    np.testing.assert_allclose(model.axis, np.tile([0.0, 0.0, 1.0], (3, 1)))
    assert model.inertia.shape == (3, 3, 3)
    one = _model()
    np.testing.assert_allclose(one.inertia, np.stack([I3, I3]))


def test_model_sizes_and_layout():
    model = Model([-1, 0, 1, 2, 1], ("free", "revolute", "universal", "spherical", "prismatic"),
                  mass=np.ones(5), inertia=I3)
    assert (model.n, model.nq, model.nv, model.width) == (5, 7 + 1 + 2 + 4 + 1, 6 + 1 + 2 + 3 + 1, 6)
    np.testing.assert_array_equal(model.neutral(), [0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0])
    np.testing.assert_array_equal(model.dof_body(), [0] * 6 + [1] + [2] * 2 + [3] * 3 + [4])
    v = jnp.arange(model.nv, dtype=float)
    np.testing.assert_array_equal(model.flat_v(model.body_v(v)), v)


def test_model_parameters_are_differentiable_leaves():
    """Masses are array leaves: a traced mass skips the concrete checks, and a gradient flows."""
    model = chain(3, seed=0)

    @jax.jit
    def kinetic(mass):
        m = eqx.tree_at(lambda m: m.mass, model, mass)
        return rigid.kinetic_energy(m, jnp.zeros(model.nq), jnp.ones(model.nv))

    grad = jax.jit(jax.grad(kinetic))(model.mass)
    assert grad.shape == (3,) and np.all(np.isfinite(grad)) and np.all(grad > 0)
    # kinetic energy is linear in the masses at fixed centres of mass and inertias
    np.testing.assert_allclose(jnp.dot(grad, model.mass) + kinetic(jnp.zeros(3)),
                               kinetic(model.mass), rtol=1e-12)


# --------------------------------------------------------------------------------------------
# URDF errors
# --------------------------------------------------------------------------------------------

def _inertial(mass="1.0", inertia='ixx="0.01" iyy="0.01" izz="0.01"', com="0 0 0", rpy="0 0 0"):
    return (f'<inertial><origin xyz="{com}" rpy="{rpy}"/><mass value="{mass}"/>'
            f'<inertia {inertia} ixy="0" ixz="0" iyz="0"/></inertial>')


def _robot(*parts):
    return '<?xml version="1.0"?>\n<robot name="r">\n' + "\n".join(parts) + "\n</robot>\n"


def _link(name, inertial=None):
    return f'<link name="{name}">{_inertial() if inertial is None else inertial}</link>'


LIMIT = '<limit lower="-10" upper="10" effort="100" velocity="100"/>'   # URDF requires them


def _joint(name, kind, parent, child, axis="0 0 1", xyz="0 0 0", rpy="0 0 0"):
    limit = LIMIT if kind in ("revolute", "prismatic") else ""
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>{limit}</joint>')


GOOD = _robot(_link("base"), _link("a"), _joint("j", "revolute", "base", "a"))


@pytest.mark.parametrize("xml, match", [
    ('<robot name="r"><link name="a"></robot>', "malformed XML"),
    ("<model/>", r"root element must be <robot>, got <model>"),
    (_robot(_link("base"), _link("a"), _joint("j", "planar", "base", "a")),
     r"joint 'j' has unknown or unsupported type 'planar'"),
    (_robot(_link("base"), _link("a"), _joint("j", "bogus", "base", "a")),
     r"unsupported type 'bogus'; supported: \["),
    (_robot(_link("base"), _link("a"), _joint("j", "revolute", "base", "b")),
     "joint 'j' refers to undefined link 'b'"),
    (_robot(_link("base"), _link("a"), _link("b"), _joint("j", "revolute", "base", "a")),
     r"expected exactly one root link, found \['base', 'b'\]"),
    (_robot(_link("base"), _link("a"), _link("b"), _link("c"),
            _joint("ja", "revolute", "base", "a"), _joint("jb", "revolute", "base", "b"),
            _joint("jc", "revolute", "a", "c"), _joint("jd", "revolute", "b", "c")),
     r"link 'c' is the child of two joints \('jc' and 'jd'\): a URDF must be a tree"),
    (_robot(_link("a"), _link("b"), _joint("j", "revolute", "a", "b"),
            _joint("k", "revolute", "b", "a")), r"exactly one root link, found none \(a cycle\)"),
    (_robot(_link("base"), _link("base"), _joint("j", "revolute", "base", "base")),
     "link 'base' is defined twice"),
    (_robot(_link("base"), '<link name="a"><inertial><inertia ixx="1" iyy="1" izz="1"/>'
            "</inertial></link>", _joint("j", "revolute", "base", "a")),
     r"link 'a' has <inertial> without <mass value=...>"),
    (_robot(_link("base"), '<link name="a"><inertial><mass value="1"/></inertial></link>',
            _joint("j", "revolute", "base", "a")), "link 'a' has <inertial> without <inertia>"),
    (_robot(_link("base"), _link("a", _inertial(mass="-1")), _joint("j", "revolute", "base", "a")),
     "body 'a': mass must be positive, got -1.0"),
    (_robot(_link("base"), _link("a", _inertial(mass="nan")), _joint("j", "revolute", "base", "a")),
     "link 'a' mass must be finite"),
    (_robot(_link("base"), _link("a", _inertial(inertia='ixx="1" iyy="x" izz="3"')),
            _joint("j", "revolute", "base", "a")), "link 'a' inertia iyy must be a number"),
    (_robot(_link("base"), _link("a"), _joint("j", "revolute", "base", "a", axis="0 0 0")),
     "joint 'j' has a zero axis"),
    (_robot(_link("base"), _link("a"), _joint("j", "revolute", "base", "a", xyz="1 2")),
     "origin xyz must be 3 numbers"),
    (_robot(_link("base"), _link("a"), _joint("j", "fixed", "base", "a")),
     "no movable joint"),
    (_robot(_link("base")), "no movable joint"),
], ids=["malformed", "not_robot", "planar", "bogus", "undefined_link", "two_roots", "two_parents",
        "cycle", "duplicate_link", "missing_mass", "missing_inertia", "negative_mass",
        "nan_mass", "unparsable_inertia", "zero_axis", "bad_origin", "only_fixed", "no_joints"])
def test_urdf_errors(xml, match):
    with pytest.raises(ValueError, match=match):
        mbjax.load_urdf(xml)


def test_urdf_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError, match="URDF file not found"):
        mbjax.load_urdf(tmp_path / "nope.urdf")
    with pytest.raises(FileNotFoundError, match="URDF file not found"):
        mbjax.load_urdf(str(tmp_path / "nope.urdf"))


def test_urdf_from_path_and_from_string_agree(tmp_path):
    path = tmp_path / "robot.urdf"
    path.write_text(FIXED_URDF)
    models = [mbjax.load_urdf(FIXED_URDF), mbjax.load_urdf(path), mbjax.load_urdf(str(path)),
              mbjax.load_urdf("\n  " + FIXED_URDF.split("\n", 1)[1])]    # no <?xml?>
    for other in models[1:]:
        assert other.topology == models[0].topology
        assert other.joint_names == models[0].joint_names
        for a, b in zip(jax.tree.leaves(models[0]), jax.tree.leaves(other), strict=True):
            np.testing.assert_array_equal(a, b)


# --------------------------------------------------------------------------------------------
# A URDF with fixed joints (merged), continuous joints, default axes and a branch
# --------------------------------------------------------------------------------------------

FIXED_URDF = _robot(
    _link("base", _inertial("3.0", com="0 0 0.1")),
    _link("mount", _inertial("0.7", 'ixx="0.01" iyy="0.02" izz="0.025"', "0.02 0 0", "0.1 0.2 0")),
    _link("upper", _inertial("1.2", 'ixx="0.02" iyy="0.021" izz="0.004"', "0 0.01 -0.15")),
    _link("tool", _inertial("0.4", 'ixx="0.002" iyy="0.003" izz="0.004"', "0.03 0 -0.05",
                            "0.3 0 0.2")),
    "<link name=\"spacer\"/>",
    _link("lower", _inertial("0.8", 'ixx="0.01" iyy="0.011" izz="0.002"', "0 0 -0.1", "0 0.1 0")),
    _link("slider", _inertial("0.5", 'ixx="0.001" iyy="0.002" izz="0.002"', "0.05 0 0")),
    _link("hand", _inertial("0.3", 'ixx="0.001" iyy="0.001" izz="0.001"', "0 0 -0.02")),
    _link("finger", _inertial("0.1", 'ixx="0.0002" iyy="0.0003" izz="0.0004"', "0.01 0 0")),
    _joint("base_mount", "fixed", "base", "mount", xyz="0 0 0.2", rpy="0 0 0.5"),
    _joint("shoulder", "revolute", "mount", "upper", axis="0 1 0", xyz="0.1 0 0", rpy="0.2 0 0"),
    # Sibling joint names sorted alphabetically, so every engine numbers the bodies alike.
    _joint("upper_a_tool", "fixed", "upper", "tool", xyz="0 0.05 -0.1", rpy="0 0.4 0"),
    _joint("upper_b_spacer", "fixed", "upper", "spacer", xyz="0 0 -0.3", rpy="0.1 0.2 0.3"),
    _joint("elbow", "continuous", "spacer", "lower", axis="1 0 1", xyz="0 0 -0.05"),
    _joint("slide", "prismatic", "tool", "slider", axis="0 0 1", xyz="0.1 0 0", rpy="0 0 -0.3"),
    # No <axis>: the URDF default (1, 0, 0).
    '<joint name="wrist" type="revolute"><parent link="lower"/><child link="hand"/>'
    '<origin xyz="0 0.02 -0.2" rpy="0 0 0"/>' + LIMIT + '</joint>',
    _joint("grip", "fixed", "hand", "finger", xyz="0 0 -0.05"),
)


def test_fixed_joints_are_merged():
    model = mbjax.load_urdf(FIXED_URDF)
    # depth-first from the root, children in joint-name order: upper's tool branch comes first
    assert model.joint_names == ("shoulder", "slide", "elbow", "wrist")
    assert model.names == ("upper", "slider", "lower", "hand")
    assert model.joint_types == ("revolute", "prismatic", "revolute", "revolute")
    assert model.topology.parents == (-1, 0, 0, 2)
    # mount merges into the ground; tool into upper; finger into hand
    np.testing.assert_allclose(model.mass, [1.2 + 0.4, 0.5, 0.8, 0.3 + 0.1], rtol=1e-15)
    np.testing.assert_allclose(model.axis[2], np.array([1.0, 0.0, 1.0]) / np.sqrt(2), rtol=1e-15)
    np.testing.assert_allclose(model.axis[3], [1.0, 0.0, 0.0])


# --------------------------------------------------------------------------------------------
# Against Pinocchio (which also merges fixed joints) and MuJoCo
# --------------------------------------------------------------------------------------------


def _symmetric(M):
    return np.triu(M) + np.triu(M, 1).T          # Pinocchio's crba fills the upper triangle


@eqx.filter_jit
def _dynamics(model, q, v, tau):
    """Both forward-dynamics routes and the mass matrix in one compiled call per model."""
    return (rigid.forward_dynamics(model, q, v, tau, method=Recursive()),
            rigid.forward_dynamics(model, q, v, tau, method=Dense()),
            rigid.mass_matrix(model, q))


def _compare_with_pinocchio(model, pin_model, seed):
    import pinocchio as pin

    to_pin, vi = pinocchio_maps(model, pin_model)
    data = pin_model.createData()
    q, v, tau = random_state(model, seed)
    qp, vp, tp = to_pin(q), np.zeros(model.nv), np.zeros(model.nv)
    vp[vi], tp[vi] = v, tau
    *accelerations, M = _dynamics(model, jnp.asarray(q), jnp.asarray(v), jnp.asarray(tau))
    for a in accelerations:                                  # recursive, dense
        np.testing.assert_allclose(a, pin.aba(pin_model, data, qp, vp, tp)[vi], rtol=1e-10,
                                   atol=1e-10)
    M_pin = _symmetric(pin.crba(pin_model, data, qp))[np.ix_(vi, vi)]
    np.testing.assert_allclose(M, M_pin, rtol=1e-10, atol=1e-12 * np.abs(M_pin).max())


def test_fixed_joint_urdf_against_pinocchio():
    pin = pytest.importorskip("pinocchio")
    model = mbjax.load_urdf(FIXED_URDF)
    pin_model = pin.buildModelFromXML(FIXED_URDF)
    assert pin_model.nv == model.nv and pin_model.nq == model.nq + 1     # continuous: cos, sin
    assert list(pin_model.names)[1:] == list(model.joint_names)
    _compare_with_pinocchio(model, pin_model, seed=0)


def test_fixed_joint_urdf_against_mujoco():
    mujoco = pytest.importorskip("mujoco")
    model = mbjax.load_urdf(FIXED_URDF)
    mj = mujoco.MjModel.from_xml_string(FIXED_URDF)
    data = mujoco.MjData(mj)
    names = [mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(mj.njnt)]
    assert names == list(model.joint_names)                  # MuJoCo: document order too
    q, v, tau = random_state(model, seed=1)
    data.qpos[:], data.qvel[:], data.qfrc_applied[:] = q, v, tau
    mujoco.mj_forward(mj, data)
    # the same compiled call as the Pinocchio test's (same model)
    *accelerations, M_ours = _dynamics(model, jnp.asarray(q), jnp.asarray(v), jnp.asarray(tau))
    for a in accelerations:                                  # recursive, dense
        np.testing.assert_allclose(a, data.qacc, rtol=1e-10, atol=1e-10)
    M = np.zeros((mj.nv, mj.nv))
    mujoco.mj_fullM(mj, data, M)                        # MuJoCo >= 3.3 signature
    np.testing.assert_allclose(M_ours, M, rtol=1e-10, atol=1e-14)


def test_floating_base_against_pinocchio_free_flyer():
    pin = pytest.importorskip("pinocchio")
    model = mbjax.load_urdf(FIXED_URDF, floating_base=True)
    assert model.joint_types[0] == "free" and model.topology.parents == (-1, 0, 1, 1, 3)
    assert model.names[0] == "base"
    # the root link with the fixed-jointed mount merged in
    np.testing.assert_allclose(model.mass[0], 3.0 + 0.7, rtol=1e-15)
    pin_model = pin.buildModelFromXML(FIXED_URDF, pin.JointModelFreeFlyer())
    assert (pin_model.nq, pin_model.nv) == (model.nq + 1, model.nv)
    for seed in (2, 3):
        _compare_with_pinocchio(model, pin_model, seed)


def test_floating_joint_in_urdf_is_a_free_joint():
    pin = pytest.importorskip("pinocchio")
    xml = _robot(_link("base"), _link("a"), _link("b", _inertial("0.5", com="0.1 0 0")),
                 _joint("float", "floating", "base", "a", xyz="0.1 0.2 0.3", rpy="0.3 0.2 0.1"),
                 _joint("hinge", "revolute", "a", "b", axis="0 1 0", xyz="0 0 0.2"))
    model = mbjax.load_urdf(xml)
    assert model.joint_types == ("free", "revolute")
    _compare_with_pinocchio(model, pin.buildModelFromXML(xml), seed=4)


def test_body_numbering_matches_pinocchio_for_unsorted_sibling_names():
    pin = pytest.importorskip("pinocchio")
    xml = FIXED_URDF.replace("upper_a_tool", "upper_z_tool")
    assert list(pin.buildModelFromXML(xml).names)[1:] == list(mbjax.load_urdf(xml).joint_names)
    # document order is still available, and differs here
    assert (list(mbjax.load_urdf(xml, sibling_order=mbjax.model.InDocument()).joint_names)
            != list(mbjax.load_urdf(xml).joint_names))


def test_sibling_orders_are_strategy_objects():
    """ByName() numbers siblings by joint name (the default, the former "name"), InDocument() in
    document order (the former "document"); the strings are refused with a TypeError."""
    xml = FIXED_URDF.replace("upper_a_tool", "upper_z_tool")
    by_name = mbjax.load_urdf(xml, sibling_order=mbjax.model.ByName()).joint_names
    assert by_name == mbjax.load_urdf(xml).joint_names == ("shoulder", "elbow", "wrist", "slide")
    in_document = mbjax.load_urdf(xml, sibling_order=mbjax.model.InDocument()).joint_names
    assert in_document == ("shoulder", "slide", "elbow", "wrist")
    for string in ("name", "document"):
        with pytest.raises(TypeError, match=r"sibling_order must be .*ByName\(\) or "
                                            r".*InDocument\(\)"):
            mbjax.load_urdf(xml, sibling_order=string)


# --------------------------------------------------------------------------------------------
# to_urdf round trip
# --------------------------------------------------------------------------------------------


def _free_base_model():
    """A free-floating base carrying revolute and prismatic joints (to_urdf writes "floating")."""
    base = random_tree(4, seed=7)
    return Model((-1, 0, 1, 0), ("free", "revolute", "prismatic", "revolute"), mass=base.mass,
                 inertia=base.inertia, com=base.com, axis=base.axis,
                 placement_rotation=base.placement_rotation,
                 placement_translation=base.placement_translation)


def _permutation(model, loaded):
    """Body order of `loaded` in terms of `model` (the loader renumbers depth-first)."""
    return [model.joint_names.index(name) for name in loaded.joint_names]


@pytest.mark.parametrize("build", [
    lambda: chain(4, seed=1),
    lambda: random_tree(7, seed=5),
    _free_base_model,
], ids=["chain", "random_tree", "free_base"])
def test_to_urdf_round_trip(build):
    model = build()
    loaded = mbjax.load_urdf(to_urdf(model))
    perm = _permutation(model, loaded)
    assert sorted(perm) == list(range(model.n))
    assert tuple(model.names[k] for k in perm) == loaded.names
    assert tuple(model.joint_types[k] for k in perm) == loaded.joint_types
    inverse = np.argsort(perm)
    parents = [-1 if p < 0 else int(inverse[p]) for p in np.asarray(model.topology.parents)[perm]]
    assert tuple(parents) == loaded.topology.parents
    for field in ("mass", "com", "inertia", "axis", "placement_rotation", "placement_translation"):
        np.testing.assert_allclose(getattr(loaded, field), np.asarray(getattr(model, field))[perm],
                                   rtol=1e-12, atol=1e-14, err_msg=field)
    np.testing.assert_allclose(loaded.gravity, model.gravity)
    # a second round trip changes nothing (the bodies are now numbered depth-first)
    again = mbjax.load_urdf(to_urdf(loaded))
    assert again.topology == loaded.topology and again.joint_names == loaded.joint_names
    for a, b in zip(jax.tree.leaves(again), jax.tree.leaves(loaded), strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-14)


def test_to_urdf_rejects_joints_without_urdf_counterpart():
    model = Model([-1, 0], ("revolute", "spherical"), mass=[1.0, 1.0], inertia=I3)
    with pytest.raises(ValueError, match="a 'spherical' joint has no URDF counterpart"):
        to_urdf(model)


def test_malformed_urdf_numbers_are_refused_by_name_or_read_exactly():
    """Hypothesis puts arbitrary text, NaN, infinities and huge or negative numbers where a URDF
    has numbers (mass, an inertia, a joint origin, an axis, damping): the model either loads with
    exactly the numbers written, or the error names the link or joint and the field."""
    import math
    import warnings

    from hypothesis import example, given, settings
    from hypothesis import strategies as st

    numbers = st.one_of(st.floats(allow_nan=True, allow_infinity=True).map(repr),
                        st.sampled_from(["", "x", "1e400", "-0", "1,5", "0x10", " 2 "]))
    fields = st.sampled_from(["mass", "ixx", "origin", "axis", "damping"])

    @settings(max_examples=80, deadline=None)
    @given(fields, numbers)
    @example("axis", "1.3407807929942597e+154")   # |axis|^2 overflowed: normalized to zero
    @example("axis", "1e-320")                    # |axis|^2 underflowed: refused as zero
    def check(field, text):
        mass, ixx, xyz, axis, damping = "1.0", "0.01", "0 0 0", "0 0 1", "0.1"
        if field == "mass":
            mass = text
        elif field == "ixx":
            ixx = text
        elif field == "origin":
            xyz = f"0 {text} 0"
        elif field == "axis":
            axis = f"0 {text} 1"
        else:
            damping = text
        joint = _joint("j", "revolute", "base", "a", axis=axis, xyz=xyz).replace(
            "</joint>", f'<dynamics damping="{damping}"/></joint>')
        xml = _robot(_link("base"), _link("a", _inertial(
            mass=mass, inertia=f'ixx="{ixx}" iyy="0.01" izz="0.01"')), joint)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                model = mbjax.load_urdf(xml)
        except ValueError as error:
            assert ("'a'" in str(error) or "'j'" in str(error)), str(error)
            return
        # loaded: every number is the one written, and finite
        value = float(text) if text.strip() not in ("", "x", "1,5", "0x10") else None
        assert value is not None and math.isfinite(value), (field, text)
        if field == "mass":
            assert float(model.mass[0]) == value
        elif field == "origin":
            assert float(model.placement_translation[0, 1]) == value
        elif field == "damping":
            assert float(model.damping[0]) == value
        elif field == "axis":
            expected = np.array([0.0, value, 1.0]) / math.hypot(value, 1.0)
            np.testing.assert_allclose(model.axis[0], expected, rtol=1e-12)
        else:
            assert np.all(np.isfinite(np.asarray(model.inertia[0])))

    check()


def test_a_revolute_joint_without_limit_loads_unlimited_with_a_warning():
    """URDF requires <limit> on revolute and prismatic joints, and its lower and upper default
    to 0: read literally, a joint without it could not move, and every run would report its
    limit exceeded. It loads without position limits, as MuJoCo's URDF import reads it, with a
    warning naming the joint (an error with strict=True); a <limit> element keeps its meaning."""
    no_limit = GOOD.replace(LIMIT, "")
    with pytest.warns(ModelWarning, match="joint 'j' \\(revolute\\) has no <limit>"):
        model = mbjax.load_urdf(no_limit)
    assert np.isneginf(model.lower).all() and np.isposinf(model.upper).all()
    system = rigid.TreeSystem(model)
    sol = mbjax.integrate.simulate(system, mbjax.integrate.RK4(), jnp.array([3.0]),
                                   jnp.array([1.0]), dt=0.01, t1=0.1)
    assert sol.messages() == ["success"]
    with pytest.raises(ValueError, match="has no <limit>.*strict=True"):
        mbjax.load_urdf(no_limit, strict=True)
    limited = mbjax.load_urdf(GOOD)
    assert float(limited.lower[0]) == -10.0 and float(limited.upper[0]) == 10.0
