"""Rotation conversions in plain numpy (Blender's Python has no scipy).

Quaternions are (w, x, y, z), Blender's order. Rotation vectors (exponential map) are axis * angle,
with angle in [0, pi]. Every function takes arrays with any leading batch shape.
"""
import numpy as np

_SMALL = 1e-8


def quat_to_rotvec(quat):
    """(..., 4) unit quaternions -> (..., 3) rotation vectors, on the short arc (angle <= pi)."""
    q = np.asarray(quat, dtype=np.float64)
    q = np.where(q[..., :1] < 0.0, -q, q)  # same rotation, w >= 0 gives angle <= pi
    w = np.clip(q[..., 0], -1.0, 1.0)
    xyz = q[..., 1:]
    sin_half = np.linalg.norm(xyz, axis=-1)
    angle = 2.0 * np.arctan2(sin_half, w)
    # angle / sin(angle/2), with its limit 2 (+ angle^2 / 12) near zero
    scale = np.where(sin_half > _SMALL, angle / np.maximum(sin_half, _SMALL), 2.0 + angle**2 / 12.0)
    return xyz * scale[..., None]


def rotvec_to_quat(rotvec):
    """(..., 3) rotation vectors -> (..., 4) unit quaternions with w >= 0."""
    r = np.asarray(rotvec, dtype=np.float64)
    angle = np.linalg.norm(r, axis=-1)
    half = 0.5 * angle
    # sin(angle/2) / angle, with its limit 1/2 (- angle^2 / 48) near zero
    scale = np.where(angle > _SMALL, np.sin(half) / np.maximum(angle, _SMALL), 0.5 - angle**2 / 48.0)
    return np.concatenate([np.cos(half)[..., None], r * scale[..., None]], axis=-1)


def quat_to_matrix(quat):
    """(..., 4) quaternions -> (..., 3, 3) rotation matrices (columns are the rotated axes)."""
    q = np.asarray(quat, dtype=np.float64)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    m = np.stack([
        1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
        2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
        2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
    ], axis=-1)
    return m.reshape(q.shape[:-1] + (3, 3))


def matrix_to_quat(matrix):
    """(..., 3, 3) rotation matrices -> (..., 4) unit quaternions with w >= 0 (Shepperd's method)."""
    m = np.asarray(matrix, dtype=np.float64)
    batch = m.shape[:-2]
    m = m.reshape(-1, 3, 3)
    trace = np.trace(m, axis1=1, axis2=2)
    # Pick the numerically largest of w, x, y, z per matrix and derive the rest from it.
    candidates = np.stack([trace, m[:, 0, 0], m[:, 1, 1], m[:, 2, 2]], axis=1)
    choice = np.argmax(candidates, axis=1)
    q = np.empty((m.shape[0], 4))
    for k in range(4):
        sel = choice == k
        if not np.any(sel):
            continue
        s = m[sel]
        if k == 0:
            r = np.sqrt(1.0 + trace[sel]) * 2.0
            q[sel] = np.stack([0.25 * r, (s[:, 2, 1] - s[:, 1, 2]) / r,
                               (s[:, 0, 2] - s[:, 2, 0]) / r, (s[:, 1, 0] - s[:, 0, 1]) / r], axis=1)
        elif k == 1:
            r = np.sqrt(1.0 + s[:, 0, 0] - s[:, 1, 1] - s[:, 2, 2]) * 2.0
            q[sel] = np.stack([(s[:, 2, 1] - s[:, 1, 2]) / r, 0.25 * r,
                               (s[:, 0, 1] + s[:, 1, 0]) / r, (s[:, 0, 2] + s[:, 2, 0]) / r], axis=1)
        elif k == 2:
            r = np.sqrt(1.0 + s[:, 1, 1] - s[:, 0, 0] - s[:, 2, 2]) * 2.0
            q[sel] = np.stack([(s[:, 0, 2] - s[:, 2, 0]) / r, (s[:, 0, 1] + s[:, 1, 0]) / r,
                               0.25 * r, (s[:, 1, 2] + s[:, 2, 1]) / r], axis=1)
        else:
            r = np.sqrt(1.0 + s[:, 2, 2] - s[:, 0, 0] - s[:, 1, 1]) * 2.0
            q[sel] = np.stack([(s[:, 1, 0] - s[:, 0, 1]) / r, (s[:, 0, 2] + s[:, 2, 0]) / r,
                               (s[:, 1, 2] + s[:, 2, 1]) / r, 0.25 * r], axis=1)
    q = np.where(q[:, :1] < 0.0, -q, q)
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return q.reshape(batch + (4,))


def rotvec_to_matrix(rotvec):
    """(..., 3) rotation vectors -> (..., 3, 3) rotation matrices."""
    return quat_to_matrix(rotvec_to_quat(rotvec))


def matrix_to_rotvec(matrix):
    """(..., 3, 3) rotation matrices -> (..., 3) rotation vectors."""
    return quat_to_rotvec(matrix_to_quat(matrix))
