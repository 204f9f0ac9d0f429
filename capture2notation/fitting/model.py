"""The body model as the solver sees it: free parameters, FK and its Jacobian.

The canonical tree of :mod:`capture2notation.body` is extended with a few
*virtual points* rigidly attached to a joint (nose, ears and heels), so image
landmarks that are not joints can pull on the pose.  The parameter vector of
one frame is ``[root (3), free Euler angles (D)]``: the pelvis rotation is
fully free, every other joint keeps only the axes whose limits are not locked
(``Body.limits[j, k, 0] < Body.limits[j, k, 1]``).

Forward kinematics and its analytic Jacobian are vectorised over frames: the
derivative of a point ``p_i`` below joint ``j`` with respect to one Euler
angle of ``j`` is ``a × (p_i − p_j)``, with ``a`` the rotation axis of that
angle in world coordinates (for ``R = Rz Ry Rx`` under the parent's frame
``G_p``: ``a_x = G_p Rz Ry e_x``, ``a_y = G_p Rz e_y``, ``a_z = G_p e_z``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..body import JOINTS, Body, euler_to_matrix, joint_index
from ..body.landmarks import LANDMARK_ATTACHMENTS

__all__ = ["VIRTUAL_POINTS", "PoseModel"]

#: Virtual points: name -> (joint they ride on, rest position as fractions of
#: body height, x right / y forward / z up).  Face and heel points are those
#: the renderer uses (:data:`capture2notation.body.landmarks.LANDMARK_ATTACHMENTS`);
#: ``head_centre`` (the head point of a Kinect skeleton or of a BVH head
#: joint) is half-way from the neck to the top of the head.
VIRTUAL_POINTS: dict[str, tuple[str, tuple[float, float, float]]] = {
    **{n: LANDMARK_ATTACHMENTS[n] for n in ("nose", "left_ear", "right_ear", "left_heel", "right_heel")},
    "head_centre": ("neck", (0.0, 0.0, 0.909)),
}

#: The segment whose per-clip length scales each joint's virtual points.
_SCALE_CHILD = {"neck": "head", "left_ankle": "left_toe", "right_ankle": "right_toe"}


@dataclass(frozen=True, eq=False)
class PoseModel:
    """The articulated model with per-clip segment offsets.

    Parameters
    ----------
    body : Body
        Supplies the tree, the rest directions of segments and the limits.
    offsets : (J, 3) ndarray, optional
        Per-clip offsets of each joint from its parent, metres (default
        ``body.offsets``).

    Attributes
    ----------
    names : tuple of str
        The J joints followed by the virtual points (P names in all).
    parents : (P,) ndarray of int
    offsets : (P, 3) ndarray
    dof_joint, dof_axis : (D,) ndarray of int
        Joint and Euler axis of every free angle.
    lower, upper : (3 + D,) ndarray
        Box limits of the parameter vector (root unbounded).
    below : (D, P) ndarray of bool
        Whether a point moves with the joint of each free angle.
    """

    body: Body
    offsets_joints: np.ndarray | None = None

    def __post_init__(self):
        body = self.body
        J = len(JOINTS)
        off_j = body.offsets if self.offsets_joints is None else np.asarray(self.offsets_joints, float)
        names = list(JOINTS)
        parents = list(body.parents)
        offs = [off_j[j] for j in range(J)]
        for name, (parent, frac) in VIRTUAL_POINTS.items():
            names.append(name)
            parents.append(joint_index(parent))
            j = joint_index(parent)
            rest_offset = np.asarray(frac) * body.height - body.rest[j]
            offs.append(rest_offset * self._scale(off_j, _SCALE_CHILD[parent]))
        parents = np.asarray(parents)
        lim = body.limits
        free = lim[..., 1] > lim[..., 0]
        free[0] = True
        dof_joint, dof_axis = np.nonzero(free)
        below = np.zeros((len(dof_joint), len(names)), bool)
        anc = _ancestors(parents)
        for d, j in enumerate(dof_joint):
            below[d] = [j in anc[i] for i in range(len(names))]
        lower = np.concatenate([np.full(3, -np.inf), lim[dof_joint, dof_axis, 0]])
        upper = np.concatenate([np.full(3, np.inf), lim[dof_joint, dof_axis, 1]])
        # The pelvis may turn without bound; wrap it instead of clipping.
        pel = np.nonzero(dof_joint == 0)[0] + 3
        lower[pel], upper[pel] = -np.inf, np.inf
        for k, v in dict(
            names=tuple(names),
            parents=parents,
            offsets=np.asarray(offs),
            dof_joint=dof_joint,
            dof_axis=dof_axis,
            below=below,
            lower=lower,
            upper=upper,
        ).items():
            object.__setattr__(self, k, v)

    def _scale(self, off_j: np.ndarray, child: str) -> float:
        """Ratio of the clip's length of the segment ending at `child` to the body's."""
        c = joint_index(child)
        base = np.linalg.norm(self.body.offsets[c])
        return float(np.linalg.norm(off_j[c]) / base) if base > 0 else 1.0

    @property
    def n_params(self) -> int:
        """3 root coordinates plus the free angles."""
        return 3 + len(self.dof_joint)

    def index(self, name: str) -> int:
        """Index of a joint or virtual point in :attr:`names`."""
        return self.names.index(name)

    def angles(self, params: np.ndarray) -> np.ndarray:
        """Full ``(T, J, 3)`` Euler angles from ``(T, 3 + D)`` parameters."""
        params = np.asarray(params, float)
        a = np.zeros((params.shape[0], len(JOINTS), 3))
        a[:, self.dof_joint, self.dof_axis] = params[:, 3:]
        return a

    def params(self, angles: np.ndarray, root: np.ndarray) -> np.ndarray:
        """Inverse of :meth:`angles`: ``(T, 3 + D)`` from angles and root."""
        return np.concatenate(
            [np.asarray(root, float), np.asarray(angles, float)[:, self.dof_joint, self.dof_axis]], axis=1
        )

    def forward(self, params: np.ndarray, jacobian: bool = False):
        """Positions of all points, optionally with their Jacobian.

        Parameters
        ----------
        params : (T, 3 + D) ndarray
        jacobian : bool

        Returns
        -------
        points : (T, P, 3) ndarray
            World positions, metres.
        jac : (T, P, 3, 3 + D) ndarray
            Only when `jacobian` is true.
        """
        params = np.asarray(params, float)
        T = params.shape[0]
        J = len(JOINTS)
        ang = self.angles(params)
        local = euler_to_matrix(ang)
        P = len(self.names)
        glob = np.empty((T, J, 3, 3))
        pts = np.empty((T, P, 3))
        pts[:, 0] = params[:, :3]
        glob[:, 0] = local[:, 0]
        for i in range(1, P):
            p = self.parents[i]
            pts[:, i] = pts[:, p] + glob[:, p] @ self.offsets[i]
            if i < J:
                glob[:, i] = glob[:, p] @ local[:, i]
        if not jacobian:
            return pts
        axes = self._axes(ang, glob)[:, None]  # (T, 1, D, 3)
        lever = pts[:, :, None, :] - pts[:, self.dof_joint][:, None, :, :]  # (T, P, D, 3)
        mask = self.below.T  # (P, D)
        ax, ay, az = axes[..., 0], axes[..., 1], axes[..., 2]
        lx, ly, lz = lever[..., 0], lever[..., 1], lever[..., 2]
        jac = np.empty((T, P, 3, self.n_params))
        jac[..., :3] = np.eye(3)
        # The cross product a × lever written out (np.cross is slow on small axes).
        jac[:, :, 0, 3:] = (ay * lz - az * ly) * mask
        jac[:, :, 1, 3:] = (az * lx - ax * lz) * mask
        jac[:, :, 2, 3:] = (ax * ly - ay * lx) * mask
        return pts, jac

    def _axes(self, ang: np.ndarray, glob: np.ndarray) -> np.ndarray:
        """World rotation axis of every free angle, ``(T, D, 3)``."""
        T = ang.shape[0]
        parent_glob = np.empty_like(glob)
        parent_glob[:, 0] = np.eye(3)
        parent_glob[:, 1:] = glob[:, self.parents[1 : len(JOINTS)]]
        j, k = self.dof_joint, self.dof_axis
        a = ang[:, j]  # (T, D, 3)
        cz, sz = np.cos(a[..., 2]), np.sin(a[..., 2])
        cy, sy = np.cos(a[..., 1]), np.sin(a[..., 1])
        zero = np.zeros_like(cz)
        # Axes in the parent's frame: x -> Rz Ry e_x, y -> Rz e_y, z -> e_z.
        ax = np.stack([cz * cy, sz * cy, -sy], -1)
        ay = np.stack([-sz, cz, zero], -1)
        az = np.broadcast_to(np.array([0.0, 0.0, 1.0]), ax.shape)
        local_axis = np.where((k == 0)[None, :, None], ax, np.where((k == 1)[None, :, None], ay, az))
        return np.einsum("tdij,tdj->tdi", parent_glob[:, j], local_axis).reshape(T, len(j), 3)


def _ancestors(parents: np.ndarray) -> list[set[int]]:
    """Strict ancestors of every point (a point does not move with its own rotation)."""
    out = []
    for i in range(len(parents)):
        s, p = set(), parents[i]
        while p >= 0:
            s.add(int(p))
            p = parents[p]
        out.append(s)
    return out
