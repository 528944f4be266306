"""Helpers the cross-engine tests share: mbjax's coordinates in Pinocchio's order."""

import jax.numpy as jnp
import numpy as np

import mbjax


def pinocchio_maps(model, pin_model):
    """(q -> Pinocchio q, v_index): mbjax dof i is Pinocchio dof v_index[i]. Joints are matched
    by name. Pinocchio's free flyer has q = (xyz, quaternion xyzw) and v = (v_local; omega_local),
    mbjax's (xyz, wxyz) and (omega; v); a continuous joint has q = (cos, sin) in Pinocchio."""
    v_index, q_parts = [], []
    for k, kind in enumerate(model.joint_types):
        jid = pin_model.getJointId(model.joint_names[k])
        assert jid < pin_model.njoints, model.joint_names[k]
        iv, iq, nq = pin_model.idx_vs[jid], pin_model.idx_qs[jid], pin_model.nqs[jid]
        v_index += [iv + j for j in ((3, 4, 5, 0, 1, 2) if kind == "free"
                                      else range(mbjax.model.JOINT_TYPES[kind].nv))]
        q_parts.append((iq, nq, kind))

    q_start = np.cumsum([0] + [mbjax.model.JOINT_TYPES[k].nq for k in model.joint_types])

    def to_pin(q):
        q = np.asarray(q)
        out = np.zeros(pin_model.nq)
        for k, (iq, nq, kind) in enumerate(q_parts):
            qk = q[q_start[k]:q_start[k + 1]]
            if kind == "free":
                qk = np.concatenate([qk[:3], qk[4:7], qk[3:4]])
            elif nq == 2:                                    # continuous: (cos, sin)
                qk = np.array([np.cos(qk[0]), np.sin(qk[0])])
            out[iq:iq + nq] = qk
        return out

    return to_pin, np.asarray(v_index)


def random_state(model, seed):
    """(q, v, tau) with q normalized, from `numpy.random.default_rng(seed)`."""
    rng = np.random.default_rng(seed)
    q = np.asarray(model.neutral()) + rng.normal(size=model.nq)
    q = np.asarray(model.normalize(jnp.asarray(q)))
    return q, rng.normal(size=model.nv), rng.normal(size=model.nv)
