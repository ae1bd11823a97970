"""Any described mechanism against Pinocchio, a second independent engine (``robomech verify --engine
pinocchio``).

The model is :func:`robomech.multibody.to_pinocchio` of the description; the checks use Pinocchio's own
algorithms along the generic test trajectory of :mod:`robomech.verify._generic`: the closure of its rigid
constraint models (frame placements), the admissible velocity (its frame Jacobians), the body frames
(``framesForwardKinematics``), the mass matrix (``crba``) and the inverse dynamics (``rnea`` projected
through the null space of its constraint Jacobian onto the actuators, by least squares); a floating
base at random states: ``rnea``, ``crba`` and (a tree) ``aba`` under random actuator forces.
"""

from __future__ import annotations

import numpy as np

from . import _generic as g
from ._core import Check
from ._mujoco import null_space

# Null-space rank decision on the stacked constraint Jacobian (frame Jacobians and coupling rows).
PIN_RANK_RTOL = 1e-9

__all__ = ["check_mechanism_pinocchio"]


def check_mechanism_pinocchio(mech, name: str | None = None) -> list[Check]:
    """The Pinocchio checks of ``mech`` (rows of the ``robomech verify --engine pinocchio`` table)."""
    import pinocchio as pin

    from robomech import multibody as mb
    from robomech.multibody._compile import compile_model
    from robomech.multibody._compiled import compiled_body_poses

    name = f"{name or mech.name} (pinocchio)"
    mech, virtual = g._virtually_actuated(mech)
    if virtual is None:  # a floating base: its tree dynamics at random states
        return _floating_checks(mech, name)
    assembly, mo = g.driven_motion(mech, name)
    checks = [assembly]
    if mo is None:
        return checks
    tree = compile_model(mech).tree
    q, inv = mo.q, mo.inv
    M_engine = mb.mass_matrix(mech, q)
    P = mb.to_pinocchio(mech)
    model = P.model
    pairs = []  # per constraint model: its two frames and whether it holds orientation too
    for i, cm in enumerate(P.constraints):
        op = pin.FrameType.OP_FRAME
        f1 = model.addFrame(pin.Frame(f"closure{i}_1", cm.joint1_id, cm.joint1_placement, op))
        f2 = model.addFrame(pin.Frame(f"closure{i}_2", cm.joint2_id, cm.joint2_placement, op))
        pairs.append((f1, f2, cm.type == pin.ContactType.CONTACT_6D))
    data = model.createData()
    E = np.zeros((mech.nv, len(mech.actuated)))
    E[tree.act_dof, np.arange(len(mech.actuated))] = 1.0
    LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    L = tree.length
    closure = adm = frames = 0.0
    tau_err = tau_scale = m_err = m_scale = vscale = 0.0
    Tw = compiled_body_poses(compile_model(mech), q)
    for i in range(len(q)):
        qp, vp, ap = P.state(q[i], inv.qd[i], inv.qdd[i])
        T = P.velocity_map(q[i])
        pin.forwardKinematics(model, data, qp)
        pin.updateFramePlacements(model, data)
        pin.computeJointJacobians(model, data, qp)
        rows = []
        for f1, f2, six in pairs:
            o1, o2 = data.oMf[f1], data.oMf[f2]
            closure = max(closure, float(np.abs(o1.translation - o2.translation).max()) / L)
            if six:
                closure = max(closure, float(np.abs(pin.log3(o1.rotation.T @ o2.rotation)).max()))
            J = pin.getFrameJacobian(model, data, f1, LWA) - pin.getFrameJacobian(model, data, f2, LWA)
            rows.append(J if six else J[:3])
        for c in mech.couplings:  # q1 - ref1 = poly(q2 - ref2): a velocity row v1 - poly'(x) v2 = 0
            row = np.zeros(model.nv)
            row[model.joints[model.getJointId(c.joint1)].idx_v] = 1.0
            if c.joint2 is not None:
                k2 = tree.joint_index(c.joint2)
                x = q[i, tree.jnt_qadr[k2]] - tree.jnt_ref[k2]
                a = np.asarray(c.polycoef, float)
                slope = a[1] + 2 * a[2] * x + 3 * a[3] * x**2 + 4 * a[4] * x**3
                row[model.joints[model.getJointId(c.joint2)].idx_v] -= slope
            rows.append(row[None])
        K = np.concatenate(rows) if rows else np.zeros((0, model.nv))
        vscale = max(vscale, float(np.abs(vp).max()))
        adm = max(adm, float(np.abs(K @ vp).max()) if len(K) else 0.0)
        for b, fid in P.body_frames.items():
            gap = float(np.abs(data.oMf[fid].homogeneous - Tw[i, tree.body_index(b)]).max())
            frames = max(frames, gap / L)
        Mp = pin.crba(model, data, qp)
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        Me = T.T @ M_engine[i] @ T
        m_err, m_scale = max(m_err, float(np.abs(Mp - Me).max())), max(m_scale, float(np.abs(Me).max()))
        f = pin.rnea(model, data, qp, vp, ap)
        Nn = null_space(K, PIN_RANK_RTOL)
        tau = np.linalg.lstsq(Nn.T @ (T.T @ E), Nn.T @ f, rcond=None)[0]
        tau_err = max(tau_err, float(np.abs(tau - inv.tau[i]).max()))
        tau_scale = max(tau_scale, float(np.abs(inv.tau[i]).max()))
    na, why_na = g._open_chain(len(pairs) + len(mech.couplings))
    checks += [
        Check(name, "closure (constraint-model frames)", closure, g.TOL_CLOSURE, "", na, why_na),
        Check(name, "admissible velocity (frame Jacobians . v)", g._rel(adm, vscale * L), g.TOL_VELOCITY, "",
              na, why_na),
        Check(name, "body frames (framesForwardKinematics)", frames, g.TOL_CLOSURE, ""),
        Check(name, "mass matrix (crba)", g._rel(m_err, m_scale), g.TOL_TORQUE, ""),
        Check(name, "inverse dynamics (rnea through the constraint Jacobian)", g._rel(tau_err, tau_scale),
              g.TOL_TORQUE, ""),
    ]  # fmt: skip
    return checks


def _floating_checks(mech, name: str) -> list[Check]:
    """A floating base against Pinocchio at the random states of the MuJoCo check
    (:func:`_generic.floating_states`): ``rnea`` and ``crba`` against :func:`multibody.generalized_forces`
    and :func:`multibody.mass_matrix` (mapped by the model's ``velocity_map``) and, for a tree, ``aba``
    under random actuator forces against :func:`multibody.forward_dynamics`."""
    import pinocchio as pin

    from robomech import multibody as mb

    rng = np.random.default_rng(0)
    q, qd, qdd = g.floating_states(mech, g.N_FLOAT, rng)
    P = mb.to_pinocchio(mech)
    model = P.model
    data = model.createData()
    f, M = mb.generalized_forces(mech, q, qd, qdd), mb.mass_matrix(mech, q)
    f_pin, f_mine = np.zeros_like(f), np.zeros_like(f)
    M_pin, M_mine = np.zeros_like(M), np.zeros_like(M)
    for i in range(g.N_FLOAT):
        qp, vp, ap = P.state(q[i], qd[i], qdd[i])
        T = P.velocity_map(q[i])
        f_pin[i], f_mine[i] = pin.rnea(model, data, qp, vp, ap), T.T @ f[i]
        Mp = pin.crba(model, data, qp)
        M_pin[i], M_mine[i] = np.triu(Mp) + np.triu(Mp, 1).T, T.T @ M[i] @ T
    states = f"{g.N_FLOAT} random states of the floating tree"
    checks = [
        Check(name, "generalized forces (vs rnea)", g._rel_diff(f_mine, f_pin), g.TOL_TREE, states),
        Check(name, "mass matrix (vs crba)", g._rel_diff(M_mine, M_pin), g.TOL_TREE, states),
    ]
    if not (mech.closures or mech.couplings):
        tau = float(np.max(np.abs(f_pin))) * rng.standard_normal((g.N_FLOAT, len(mech.actuated)))
        fd = mb.forward_dynamics(mech, q, tau=tau, qd=qd)
        a_pin, a_mine = np.zeros_like(fd.qdd), np.zeros_like(fd.qdd)
        for i in range(g.N_FLOAT):
            qp, vp, a_mine[i] = P.state(q[i], qd[i], fd.qdd[i])
            force = np.zeros(mech.nv)
            force[mech.tree.act_dof] = tau[i]
            a_pin[i] = pin.aba(model, data, qp, vp, P.velocity_map(q[i]).T @ force)
        err = g._rel_diff(a_mine, a_pin) if bool(np.all(fd.valid)) else 1.0
        checks.append(Check(name, "forward dynamics under actuator forces (vs aba)", err, g.TOL_TREE, states))
    return checks
