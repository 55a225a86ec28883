"""Damped-least-squares inverse kinematics for the arm's tool site.

Solved once per Cartesian waypoint on a private ``MjData`` (never the live one), so
it can run in an action server's thread while physics steps in its own.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np


def tool_down_rotation(yaw: float) -> np.ndarray:
    """Rotation of a tool pointing straight down (tool z = world -z), turned by ``yaw``.

    At yaw 0 the tool x axis points along world -x (the arm's natural wrist-down pose).
    """
    c, s = math.cos(yaw), math.sin(yaw)
    rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return rz @ np.diag([-1.0, 1.0, -1.0])


class IKSolver:
    """DLS IK on the joints ``joint_names`` for the site ``site_name``."""

    def __init__(self, model: mujoco.MjModel, site_name: str, joint_names: list[str]):
        self.model = model
        self.data = mujoco.MjData(model)
        self.site_id = model.site(site_name).id
        jids = [model.joint(n).id for n in joint_names]
        self.qadr = np.array([model.jnt_qposadr[j] for j in jids])
        self.dofadr = np.array([model.jnt_dofadr[j] for j in jids])
        self.lo = model.jnt_range[jids, 0].copy()
        self.hi = model.jnt_range[jids, 1].copy()
        self._jacp = np.zeros((3, model.nv))
        self._jacr = np.zeros((3, model.nv))

    def forward(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Tool position and rotation matrix at joint vector ``q``."""
        d = self.data
        d.qpos[self.qadr] = q
        mujoco.mj_kinematics(self.model, d)
        return d.site_xpos[self.site_id].copy(), d.site_xmat[self.site_id].reshape(3, 3).copy()

    def _error(self, pos_t: np.ndarray, quat_t: np.ndarray) -> np.ndarray:
        d = self.data
        err = np.empty(6)
        err[:3] = pos_t - d.site_xpos[self.site_id]
        q_site = np.empty(4)
        mujoco.mju_mat2Quat(q_site, d.site_xmat[self.site_id])
        q_inv = np.empty(4)
        mujoco.mju_negQuat(q_inv, q_site)
        q_err = np.empty(4)
        mujoco.mju_mulQuat(q_err, quat_t, q_inv)
        mujoco.mju_quat2Vel(err[3:], q_err, 1.0)
        return err

    def solve(
        self,
        q0: np.ndarray,
        pos: np.ndarray,
        rot: np.ndarray,
        *,
        max_iter: int = 150,
        tol_pos: float = 5e-4,
        tol_rot: float = 5e-3,
        damping: float = 0.03,
        max_step: float = 0.25,
    ) -> np.ndarray | None:
        """Joint vector reaching ``pos``/``rot`` starting from ``q0``, or None."""
        pos = np.asarray(pos, dtype=float)
        quat_t = np.empty(4)
        mujoco.mju_mat2Quat(quat_t, np.asarray(rot, dtype=float).reshape(9))
        m, d = self.model, self.data
        q = np.clip(np.asarray(q0, dtype=float).copy(), self.lo, self.hi)
        lam2 = damping * damping
        for _ in range(max_iter):
            d.qpos[self.qadr] = q
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)
            err = self._error(pos, quat_t)
            if np.linalg.norm(err[:3]) < tol_pos and np.linalg.norm(err[3:]) < tol_rot:
                return q
            mujoco.mj_jacSite(m, d, self._jacp, self._jacr, self.site_id)
            jac = np.vstack([self._jacp[:, self.dofadr], self._jacr[:, self.dofadr]])
            # weight rotation less than position (metres vs radians)
            w = np.array([1, 1, 1, 0.3, 0.3, 0.3])
            jw = jac * w[:, None]
            dq = jw.T @ np.linalg.solve(jw @ jw.T + lam2 * np.eye(6), err * w)
            n = np.linalg.norm(dq)
            if n > max_step:
                dq *= max_step / n
            q = np.clip(q + dq, self.lo, self.hi)
        return None

    def solve_robust(self, q0: np.ndarray, pos, rot, seeds=()) -> np.ndarray | None:
        """Try ``q0`` first, then each extra seed; None if none converges."""
        for seed in (q0, *seeds):
            q = self.solve(seed, pos, rot)
            if q is not None:
                return q
        return None
