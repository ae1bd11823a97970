"""The MuJoCo harness every engine check shares: one place for what the checks ask of the engine.

* the engine model of a description (``mb.to_mjcf``) with the options a check simulates with
  (:func:`engine_options`, :func:`engine_model`);
* state setting (:meth:`Engine.set_state`, whole vectors or the addresses of named joints,
  :meth:`Engine.joint_addresses`);
* the equality-constraint rows (:meth:`Engine.equality`: ``efc_J`` dense, ``efc_pos``) and their null
  space (:func:`null_space`);
* projected inverse dynamics (:meth:`Engine.inverse_dynamics`): the engine's tree dynamics
  ``M qacc + c + g`` (``mj_rne``) less applied generalized forces, balanced by the actuators in the
  admissible motions, ``N^T (E tau - f) = 0`` with ``N = null(efc_J)`` (least squares, minimum norm);
* energies (:meth:`Engine.energies`: ``mj_energyPos``, ``mj_energyVel``) and the mass matrix;
* simulation (:meth:`Engine.simulate`): stepping to output times with an optional controller called
  before every step (servoed or force-driven) or none (passive);
* branch-following assembly along a path of actuated inputs (:func:`assemble_along`), used by the
  generic checks and open to the rest of the package.

MuJoCo is imported on first use (the optional ``verify`` extra).
"""

from __future__ import annotations

import hashlib
import xml.etree.ElementTree as ET
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._core import optional_module

if TYPE_CHECKING:
    import mujoco
else:  # imported on first use: importing the harness must not need the optional engine
    mujoco = optional_module("mujoco")

__all__ = [
    "BRANCH_TOL",
    "CONTINUATION_STEPS",
    "ENGINE_RANK_RTOL",
    "Engine",
    "assemble_along",
    "engine_model",
    "engine_options",
    "model_digest",
    "null_space",
]

Array = NDArray[np.float64]
T = TypeVar("T")

# Null-space rank decision on the engine's efc_J (equality rows in m and rad, columns per dof): a
# singular value below this fraction of the largest is zero (as in the multibody layer).
ENGINE_RANK_RTOL = 1e-10
# Assembly along a path: the first batch solve continues from the reference in this many stages.
CONTINUATION_STEPS = 4
# A frame solved from the previous frame that lands farther than this (in q, rad or m) from the batch
# solution is on another branch: the batch jumped, so the path is followed frame by frame from there.
BRANCH_TOL = 1e-6


def engine_options(
    xml: str,
    *,
    timestep: float,
    integrator: str | None = None,
    jacobian: str | None = None,
    solref: str | None = None,
    solimp: str | None = None,
    contact: bool = True,
) -> ET.Element:
    """The exported MJCF ``xml`` with the engine options a check simulates with (not part of a mechanism
    description): ``<option timestep integrator jacobian>``, contacts off with ``contact=False``, and
    ``solref`` / ``solimp`` on every equality constraint; ``None`` leaves MuJoCo's default. Returns the
    root element (serialise with ``ET.tostring(root, encoding="unicode")``)."""
    root = ET.fromstring(xml)
    opt = root.find("option")
    if opt is None:  # to_mjcf always writes <option gravity=...>; kept robust
        opt = ET.SubElement(root, "option")
    opt.set("timestep", repr(timestep))
    for key, value in (("integrator", integrator), ("jacobian", jacobian)):
        if value is not None:
            opt.set(key, value)
    if not contact:
        ET.SubElement(opt, "flag", contact="disable")
    eq = root.find("equality")
    for e in [] if eq is None else list(eq):
        for key, value in (("solref", solref), ("solimp", solimp)):
            if value is not None:
                e.set(key, value)
    return root


def engine_model(mech: Any, **options: Any) -> mujoco.MjModel:
    """MuJoCo model of ``mech`` from ``mb.to_mjcf``; ``options`` (``timestep=`` and the rest of
    :func:`engine_options`) set the simulation options, none leaves the exported model as it is."""
    from robomech import multibody as mb

    xml = mb.to_mjcf(mech)
    if options:
        xml = ET.tostring(engine_options(xml, **options), encoding="unicode")
    return mujoco.MjModel.from_xml_string(xml)


def null_space(J: Array, rtol: float = ENGINE_RANK_RTOL) -> Array:
    """Orthonormal basis ``(n, n - rank)`` of the null space of ``J (m, n)``; rank by singular values
    above ``rtol`` times the largest (the identity for no rows)."""
    if J.shape[0] == 0:
        return np.eye(J.shape[1])
    _, s, Vt = np.linalg.svd(J)
    r = int(np.sum(s > rtol * max(float(s[0]), 1e-300)))
    return np.asarray(Vt[r:].T)


class Engine:
    """A MuJoCo model with one data, and the operations the checks share.

    Parameters
    ----------
    model : mujoco.MjModel
        The engine model (usually :func:`engine_model` of a description).
    data : mujoco.MjData, optional
        Its data (default: a new one).
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData | None = None) -> None:
        self.model = model
        self.data = mujoco.MjData(model) if data is None else data

    def joint_addresses(self, names: Sequence[str]) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
        """``qpos`` and ``qvel`` addresses of the named joints (ValueError for a name the model lacks)."""
        m = self.model
        jid = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n) for n in names]
        missing = [n for n, j in zip(names, jid, strict=True) if j < 0]
        if missing:
            raise ValueError(f"Expected the engine model to have joints {missing!r}.")
        return (
            np.array([m.jnt_qposadr[j] for j in jid], dtype=np.intp),
            np.array([m.jnt_dofadr[j] for j in jid], dtype=np.intp),
        )

    def set_state(
        self,
        qpos: ArrayLike,
        qvel: ArrayLike | None = None,
        qacc: ArrayLike | None = None,
        *,
        qpos_index: NDArray[np.intp] | None = None,
        dof_index: NDArray[np.intp] | None = None,
        forward: bool = True,
    ) -> mujoco.MjData:
        """Write a state (whole vectors, or at the given addresses), then ``mj_forward`` (unless
        ``forward=False``); ``qacc`` is written after the forward pass (for :meth:`tree_forces` and
        ``mj_rnePostConstraint``). Returns the data."""
        d = self.data
        d.qpos[slice(None) if qpos_index is None else qpos_index] = qpos
        dofs = slice(None) if dof_index is None else dof_index
        if qvel is not None:
            d.qvel[dofs] = qvel
        if forward:
            mujoco.mj_forward(self.model, d)
        if qacc is not None:
            d.qacc[dofs] = qacc
        return d

    def equality(self) -> tuple[Array, Array]:
        """The equality-constraint rows of the current state: ``efc_J`` (dense, sparse models too) and
        ``efc_pos``."""
        m, d = self.model, self.data
        if d.nefc == 0:
            return np.zeros((0, m.nv)), np.zeros(0)
        eq = d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        if mujoco.mj_isSparse(m):
            J = np.zeros((d.nefc, m.nv))
            mujoco.mju_sparse2dense(J, d.efc_J, d.efc_J_rownnz, d.efc_J_rowadr, d.efc_J_colind)
        else:
            J = np.array(d.efc_J)[: d.nefc * m.nv].reshape(d.nefc, m.nv)
        return J[eq], np.array(d.efc_pos[: d.nefc])[eq]

    def tree_forces(self) -> Array:
        """``M qacc + c + g`` of the current state and ``qacc`` (``mj_rne``; constraint forces excluded)."""
        f = np.zeros(self.model.nv)
        mujoco.mj_rne(self.model, self.data, 1, f)
        return f

    def mass_matrix(self) -> Array:
        """The dense mass matrix of the current state (``mj_fullM``)."""
        M = np.zeros((self.model.nv, self.model.nv))
        mujoco.mj_fullM(self.model, self.data, M)
        return M

    def inverse_dynamics(
        self,
        qpos: Array,
        qvel: Array,
        qacc: Array,
        actuated_dofs: Sequence[int] | NDArray[np.intp],
        *,
        applied: Array | Callable[[mujoco.MjData], Array] | None = None,
        qpos_index: NDArray[np.intp] | None = None,
        dof_index: NDArray[np.intp] | None = None,
    ) -> Array:
        """Forces of the actuators on ``actuated_dofs`` (engine dof addresses) that produce ``qacc``:
        the tree forces ``f = M qacc + c + g - applied`` (``mj_rne``) balanced in the admissible motions,
        ``N^T (E tau - f) = 0`` with ``N`` the null space of the engine's own ``efc_J`` (least squares,
        minimum norm). ``applied`` (nv) are generalized forces acting besides the actuators (e.g.
        ``J^T F`` of an external force), or a function of the data that returns them at the state."""
        d = self.set_state(qpos, qvel, qacc, qpos_index=qpos_index, dof_index=dof_index)
        f = self.tree_forces()
        if applied is not None:
            f = f - (applied(d) if callable(applied) else applied)
        N = null_space(self.equality()[0])
        act = np.asarray(actuated_dofs, dtype=np.intp)
        E = np.zeros((self.model.nv, len(act)))
        E[act, np.arange(len(act))] = 1.0
        return np.asarray(np.linalg.lstsq(N.T @ E, N.T @ f, rcond=None)[0])

    def energies(self, qpos: Array, qvel: Array, **index: Any) -> tuple[float, float]:
        """Potential and kinetic energy ``(U, T)`` of a state (``mj_energyPos``, ``mj_energyVel``; the
        energy flag is switched on for the call and restored: the model is left as it was, so that its
        bytes, :func:`model_digest`, do not depend on the checks run before); ``index`` as in
        :meth:`set_state`."""
        flags = self.model.opt.enableflags
        self.model.opt.enableflags = flags | int(mujoco.mjtEnableBit.mjENBL_ENERGY)
        try:
            d = self.set_state(qpos, qvel, **index)
            mujoco.mj_energyPos(self.model, d)
            mujoco.mj_energyVel(self.model, d)
        finally:
            self.model.opt.enableflags = flags
        return float(d.energy[0]), float(d.energy[1])

    def simulate(
        self,
        times: Array,
        read: Callable[[mujoco.MjData], T],
        control: Callable[[mujoco.MjData], None] | None = None,
    ) -> list[T]:
        """Step the current state to each output time (``mj_step``; ``times`` increasing, at or after
        the current time) and return ``read(data)`` there; ``control(data)`` sets ``ctrl`` /
        ``qfrc_applied`` before every step (None: a passive motion under the model's own forces)."""
        m, d = self.model, self.data
        half = 0.5 * m.opt.timestep
        out = []
        for tk in times:
            while d.time < tk - half:
                if control is not None:
                    control(d)
                mujoco.mj_step(m, d)
            out.append(read(d))
        return out


def model_digest(model: mujoco.MjModel) -> str:
    """SHA-256 (hex) of a compiled engine model's bytes (``mj_saveModel``): equal models, equal digests."""
    buf = np.zeros(mujoco.mj_sizeModel(model), dtype=np.uint8)
    mujoco.mj_saveModel(model, None, buf)
    return hashlib.sha256(buf.tobytes()).hexdigest()


def assemble_along(mech: Any, q_act: Array) -> Any:
    """Assemble ``mech`` at each row of ``q_act (nt, n_act)`` on the branch of its reference pose.

    All frames are solved in one batch from ``mech.q0`` (continuation in ``CONTINUATION_STEPS``
    stages), then each frame again from the frame before it (a second batch); where that continuation
    lands elsewhere (more than ``BRANCH_TOL``) or fails, the batch jumped branch and the frames from
    there on are solved one by one, each from the previous solution.  So the result is what following
    the path frame by frame gives, at the cost of two batched solves when the path stays on one
    branch.  Returns the stacked :class:`robomech.multibody.FKResult` (``q (nt, nq)``, ``residual``,
    ``converged``, ``iterations``, ``mode_changed``).
    """
    from robomech import multibody as mb

    qa = np.asarray(q_act, dtype=float)
    fields = ("q", "residual", "converged", "iterations", "mode_changed")
    fk = mb.forward_kinematics(mech, qa, steps=CONTINUATION_STEPS)
    out = {f: np.array(getattr(fk, f)) for f in fields}
    q, conv = out["q"], out["converged"]
    if qa.shape[0] > 1:
        again = mb.forward_kinematics(mech, qa[1:], q[:-1])
        off = (np.max(np.abs(again.q - q[1:]), axis=-1) > BRANCH_TOL) | ~again.converged
        for k in range(int(np.argmax(off)) + 1, qa.shape[0]) if np.any(off) else ():
            guess = q[k - 1] if conv[k - 1] else None  # frame by frame from the first jump
            r = mb.forward_kinematics(mech, qa[k], guess, steps=CONTINUATION_STEPS if guess is None else 1)
            for f in fields:
                out[f][k] = getattr(r, f)
    return mb.FKResult(**out)
