"""The paper's evaluation metrics (Section 4): score out of 100 and smoothness out of 100.

Both take joint-position sequences (F, J, 3) in metres, normally the 10 description joints
(`spaces.description_joint_positions`). Definitions, the paper's ambiguities and the calibration are
in docs/METRICS.md.

score = 100 - total_error / F, with
    error_t     = sum_j |dx| + |dy| + |dz|                      (metres, per frame)
    total_error = sum_t error_t + sum_t max(0, log_1.01 error_t)  (the log penalty is per frame)

smoothness = 100 * (1 - GAIN * roughness), clipped to [0, 100], with
    roughness = sum_t,j |p - savgol(p)| / sum_t,j |p_t+1 - p_t|
the high-frequency residual that a Savitzky-Golay filter removes, relative to the clip's own motion
(its joints' path length), so it does not depend on the character's size or the gesture's extent.
"""
import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike

from .errors import RLAnimateError

#: Savitzky-Golay window (frames, odd) and polynomial order of the smoothness filter, at 30 fps: a
#: 0.3 s window whose degree-6 fit follows a 3 Hz wave but not frame-to-frame jitter.
SMOOTHING_WINDOW = 9
SMOOTHING_ORDER = 6
#: Scales roughness to the paper's 0-100 range: 5 mm of jitter on a gesture falls below the
#: paper's visible-artefact threshold ARTEFACT_THRESHOLD, smooth minimum-jerk motion stays above 99.5.
SMOOTHNESS_GAIN = 0.25
ARTEFACT_THRESHOLD = 98.5
#: Base of the paper's per-frame error penalty log_1.01(error_t).
PENALTY_BASE = 1.01


def _check_sequence(positions: ArrayLike, name: str) -> npt.NDArray[np.float64]:
    p = np.asarray(positions, dtype=np.float64)
    if p.ndim != 3 or p.shape[-1] != 3 or p.shape[0] == 0:
        raise RLAnimateError(f"{name} must be joint positions of shape (frames, joints, 3), got {p.shape}.")
    if not np.all(np.isfinite(p)):
        raise RLAnimateError(f"{name} contains NaN or infinite positions: re-import or regenerate the clip.")
    return p


def frame_errors(generated: ArrayLike, reference: ArrayLike) -> npt.NDArray[np.float64]:
    """(F,) per-frame error: the sum over joints of |dx| + |dy| + |dz|, in metres."""
    gen = _check_sequence(generated, "The generated clip")
    ref = _check_sequence(reference, "The reference clip")
    if gen.shape != ref.shape:
        raise RLAnimateError(f"The generated clip has shape {gen.shape} but the reference has {ref.shape}: "
                             "generate the same number of frames as the reference clip.")
    errors: npt.NDArray[np.float64] = np.abs(gen - ref).sum(axis=(1, 2))
    return errors


def frame_penalties(errors: ArrayLike) -> npt.NDArray[np.float64]:
    """(F,) the paper's penalty max(0, log_1.01 error_t): zero for errors of 1 m or less."""
    e = np.asarray(errors, dtype=np.float64)
    over = np.maximum(e, 1.0)  # log of anything <= 1 is <= 0, which the max clips to 0
    penalties: npt.NDArray[np.float64] = np.log(over) / np.log(PENALTY_BASE)
    return penalties


def score(generated: ArrayLike, reference: ArrayLike) -> float:
    """The paper's score out of 100 (it can go negative for very poor imitations)."""
    errors = frame_errors(generated, reference)
    total_error = errors.sum() + frame_penalties(errors).sum()
    return float(100.0 - total_error / len(errors))


def savgol_coefficients(window: int = SMOOTHING_WINDOW, order: int = SMOOTHING_ORDER) -> npt.NDArray[np.float64]:
    """(window, window) least-squares projection: row k evaluates at offset k the polynomial of
    degree `order` fitted to `window` equally spaced samples."""
    if window % 2 == 0 or order >= window:
        raise ValueError(f"need an odd window longer than the order, got window={window}, order={order}")
    offsets = np.arange(window) - window // 2
    basis = np.vander(offsets, order + 1, increasing=True)  # (W, order+1)
    return basis @ np.linalg.pinv(basis)  # (W, W)


def savgol_smooth(values: ArrayLike, window: int = SMOOTHING_WINDOW,
                  order: int = SMOOTHING_ORDER) -> npt.NDArray[np.float64]:
    """Savitzky-Golay smoothing along axis 0 of (F, ...) values.

    Equals scipy.signal.savgol_filter(values, window, order, axis=0) in its default 'interp' mode:
    interior frames use the centred window; the first and last window//2 frames evaluate the
    polynomial fitted to the first and last full window.
    """
    x = np.asarray(values, dtype=np.float64)
    frames = x.shape[0]
    if frames < window:
        raise RLAnimateError(f"The clip has {frames} frames; smoothness needs at least {window}: "
                             "use a longer clip.")
    projection = savgol_coefficients(window, order)
    half = window // 2
    flat = x.reshape(frames, -1)  # (F, D)
    windows = np.lib.stride_tricks.sliding_window_view(flat, window, axis=0)  # (F-W+1, D, W)
    smoothed = np.empty_like(flat)
    smoothed[half:frames - half] = windows @ projection[half]
    smoothed[:half] = projection[:half] @ flat[:window]
    smoothed[frames - half:] = projection[half + 1:] @ flat[frames - window:]
    return smoothed.reshape(x.shape)


def roughness(positions: ArrayLike) -> float:
    """High-frequency residual relative to the motion: sum|p - savgol(p)| / path length (both in metres)."""
    p = _check_sequence(positions, "The clip")
    residual = np.linalg.norm(p - savgol_smooth(p), axis=-1).sum()
    path_length = np.linalg.norm(np.diff(p, axis=0), axis=-1).sum()
    if path_length < 1e-9:
        return 0.0  # a still pose is perfectly smooth
    return float(residual / path_length)


def smoothness(positions: ArrayLike) -> float:
    """Smoothness out of 100 of a (F, J, 3) joint-position sequence; below 98.5 artefacts show."""
    return float(np.clip(100.0 * (1.0 - SMOOTHNESS_GAIN * roughness(positions)), 0.0, 100.0))
