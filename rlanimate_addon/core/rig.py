"""A user's armature as plain arrays, and its forward kinematics, in its own armature space and units.

Blender's pose evaluation without constraints: pose = parent_pose @ parent_rest^-1 @ rest @ basis,
with rest a bone's `matrix_local` and basis its `matrix_basis` (the keyed location, rotation, scale).
`pose_after` predicts the pose of a rig whose bones follow one another through constraints or
helper bones (Rigify's FK controls and the bones that copy them): from the pose Blender evaluated,
a bone whose basis changes, or whose parent moves, moves rigidly with them.
"""
from collections.abc import Callable, Collection, Iterable, Sequence

import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike


def _orthonormal(rotation: npt.NDArray[np.float64]) -> bool:
    """Whether R^T R is the identity for every (..., 3, 3) matrix, as np.allclose(R^T R, I, atol=1e-6)
    tests it: entry by entry over all matrices at once (a product per 3x3 matrix costs several times more)."""
    columns = np.ascontiguousarray(np.moveaxis(rotation, (-2, -1), (0, 1))).reshape(3, 3, -1)  # (3, 3, M)
    for i in range(3):
        for j in range(i, 3):
            gram = columns[0, i] * columns[0, j] + columns[1, i] * columns[1, j] + columns[2, i] * columns[2, j]
            identity = float(i == j)
            if not (np.abs(gram - identity) <= 1e-6 + 1e-5 * identity).all():
                return False
    return True


def inverse(matrices: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """Inverses of (..., 4, 4) affine matrices: by transposition where the 3x3 part is a rotation
    (bones' pose matrices, unless scaled), else by np.linalg.inv."""
    rotation = matrices[..., :3, :3]
    if not _orthonormal(rotation):
        return np.linalg.inv(matrices)
    out = np.zeros_like(matrices)
    out[..., :3, :3] = np.swapaxes(rotation, -1, -2)
    out[..., :3, 3] = -np.einsum("...ji,...j->...i", rotation, matrices[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


def each_frame(function: Callable[[npt.NDArray[np.float64]], npt.NDArray[np.float64]],
               values: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """function(values) of (N, ...) per-frame values whose result is per frame too; when the frames are one
    frame broadcast (a rig standing still: stride 0) it runs on that frame once and its result is broadcast."""
    if len(values) > 1 and values.strides[0] == 0:
        once = function(values[:1])
        return np.broadcast_to(once, (len(values),) + once.shape[1:])
    return function(values)


def _frames_inverse(matrices: npt.NDArray[np.float64], bones: Sequence[int]) -> npt.NDArray[np.float64]:
    """(N, len(bones), 4, 4) `inverse` of (N, B, 4, 4) matrices' bones at indices `bones`, frame by frame
    (`each_frame`), laid out frame after frame as the products that read them expect."""
    return np.ascontiguousarray(each_frame(lambda m: inverse(m[:, bones]), matrices))


class RigSkeleton:
    """Bone names, parent names (None for a root), (B, 4, 4) rest matrices and (B,) rest lengths."""

    def __init__(self, names: Iterable[str], parents: Iterable[str | None], rest: ArrayLike,
                 lengths: ArrayLike) -> None:
        self.names = tuple(names)
        self.index = {name: i for i, name in enumerate(self.names)}
        self.parents = np.array([-1 if p is None else self.index[p] for p in parents])
        self.rest = np.asarray(rest, dtype=np.float64)
        self.lengths = np.asarray(lengths, dtype=np.float64)
        # Rest of each bone relative to its parent's rest (B, 4, 4).
        self._rest_local = np.where((self.parents < 0)[:, None, None], self.rest,
                                    inverse(self.rest[self.parents]) @ self.rest)

    def rest_frame(self, name: str) -> npt.NDArray[np.float64]:
        """(3, 3) armature-space rest rotation of a bone (columns: its local X, Y, Z axes, unit length)."""
        rotation = self.rest[self.index[name], :3, :3]
        frame: npt.NDArray[np.float64] = rotation / np.linalg.norm(rotation, axis=0, keepdims=True)
        return frame

    def rest_head(self, name: str) -> npt.NDArray[np.float64]:
        return self.rest[self.index[name], :3, 3].copy()

    def tails(self, pose: npt.NDArray[np.float64], name: str) -> npt.NDArray[np.float64]:
        """(..., 3) tail positions of a bone from (..., B, 4, 4) pose matrices (head + length along Y)."""
        i = self.index[name]
        length = float(self.lengths[i])
        tails: npt.NDArray[np.float64] = pose[..., i, :3, 3] + length * pose[..., i, :3, 1]
        return tails

    def ancestors(self, name: str) -> list[int]:
        """Indices of the bone and all its ancestors, root first."""
        chain: list[int] = []
        i = self.index[name]
        while i >= 0:
            chain.append(i)
            i = int(self.parents[i])
        return chain[::-1]

    def pose_after(self, pose: npt.NDArray[np.float64], basis: npt.NDArray[np.float64],
                   new_basis: npt.NDArray[np.float64], changed: Iterable[int],
                   only: Collection[str]) -> npt.NDArray[np.float64]:
        """(N, B, 4, 4) pose matrices once the bones at indices `changed` take `new_basis`.

        pose, basis: (N, B, 4, 4) the evaluated pose and basis matrices underneath; new_basis: (N, B, 4, 4)
        (only the changed bones' are read). A changed bone, or one below a changed bone, keeps where it
        sits relative to its parent and plays its new basis:
        pose' = parent_pose' @ parent_pose^-1 @ pose @ basis^-1 @ basis'.
        Only the bones named in `only` and their ancestors are updated; the others keep `pose`.
        """
        changed = set(changed)
        bones = self._evaluation_order(only)
        slot = {i: k for k, i in enumerate(bones)}
        pose_inverse, basis_inverse = (
            _frames_inverse(pose, bones),
            _frames_inverse(basis, bones),
        )  # (N, len(bones), 4, 4)
        still = pose.strides[0] == 0 and basis.strides[0] == 0  # one frame broadcast: a rig standing still
        out = np.array(pose, dtype=np.float64)
        moved = np.zeros(len(self.names), dtype=bool)
        for i in bones:
            parent = self.parents[i]
            follows = parent >= 0 and moved[parent]
            if i not in changed and not follows:
                continue
            local = basis[:, i] if i not in changed else new_basis[:, i]
            frames = slice(0, 1) if still else slice(None)  # a still rig's offset is the same every frame
            offset = pose[frames, i] @ basis_inverse[frames, slot[i]]  # pose @ basis^-1
            placed = np.broadcast_to(offset, local.shape) @ local
            out[:, i] = out[:, parent] @ pose_inverse[:, slot[parent]] @ placed if follows else placed
            moved[i] = True
        return out

    def pose_matrices(self, basis: npt.NDArray[np.float64], only: Collection[str]) -> npt.NDArray[np.float64]:
        """(..., B, 4, 4) armature-space pose matrices from (..., B, 4, 4) basis matrices.

        Only the bones named in `only` and their ancestors are evaluated; the others are NaN.
        """
        pose = np.full(np.shape(basis), np.nan)
        for i in self._evaluation_order(only):
            local = self._rest_local[i] @ basis[..., i, :, :]
            parent = self.parents[i]
            pose[..., i, :, :] = local if parent < 0 else pose[..., parent, :, :] @ local
        return pose

    def _evaluation_order(self, only: Iterable[str]) -> list[int]:
        """Indices of the bones named in `only` and their ancestors, parents before children."""
        return sorted({i for name in only for i in self.ancestors(name)},
                      key=lambda i: len(self.ancestors(self.names[i])))
