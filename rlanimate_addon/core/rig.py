"""A user's armature as plain arrays, and its forward kinematics, in its own armature space and units.

Blender's pose evaluation without constraints: pose = parent_pose @ parent_rest^-1 @ rest @ basis,
with rest a bone's `matrix_local` and basis its `matrix_basis` (the keyed location, rotation, scale).
"""
import numpy as np


class RigSkeleton:
    """Bone names, parent names (None for a root), (B, 4, 4) rest matrices and (B,) rest lengths."""

    def __init__(self, names, parents, rest, lengths):
        self.names = tuple(names)
        self.index = {name: i for i, name in enumerate(self.names)}
        self.parents = np.array([-1 if p is None else self.index[p] for p in parents])
        self.rest = np.asarray(rest, dtype=np.float64)
        self.lengths = np.asarray(lengths, dtype=np.float64)
        # Rest of each bone relative to its parent's rest (B, 4, 4).
        self._rest_local = np.array([r if p < 0 else np.linalg.inv(self.rest[p]) @ r
                                     for r, p in zip(self.rest, self.parents)])

    def rest_frame(self, name):
        """(3, 3) armature-space rest rotation of a bone (columns: its local X, Y, Z axes, unit length)."""
        rotation = self.rest[self.index[name], :3, :3]
        return rotation / np.linalg.norm(rotation, axis=0, keepdims=True)

    def rest_head(self, name):
        return self.rest[self.index[name], :3, 3].copy()

    def tails(self, pose, name):
        """(..., 3) tail positions of a bone from (..., B, 4, 4) pose matrices (head + length along Y)."""
        i = self.index[name]
        return pose[..., i, :3, 3] + self.lengths[i] * pose[..., i, :3, 1]

    def ancestors(self, name):
        """Indices of the bone and all its ancestors, root first."""
        chain, i = [], self.index[name]
        while i >= 0:
            chain.append(i)
            i = self.parents[i]
        return chain[::-1]

    def pose_matrices(self, basis, only):
        """(..., B, 4, 4) armature-space pose matrices from (..., B, 4, 4) basis matrices.

        Only the bones named in `only` and their ancestors are evaluated; the others are NaN.
        """
        evaluated = sorted({i for name in only for i in self.ancestors(name)}, key=lambda i: len(self.ancestors(self.names[i])))
        pose = np.full(np.shape(basis), np.nan)
        for i in evaluated:
            local = self._rest_local[i] @ basis[..., i, :, :]
            parent = self.parents[i]
            pose[..., i, :, :] = local if parent < 0 else pose[..., parent, :, :] @ local
        return pose
