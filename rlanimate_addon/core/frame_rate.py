"""Real time at any frame rate: the agent plays at its clips' 30 fps, a scene at its own rate.

A gesture of N scene frames at `fps` lasts (N - 1) / fps seconds from its first key to its last, so
the agent plays it over `agent_frames(N, fps)` of its own frames and its actions are resampled to
the scene's N: a wave swings at the same Hz, and a point holds for the same seconds, at 24, 25, 30,
50 or 60 fps and at fractional rates (fps / fps_base, 29.97).
"""
#: The frame rate of the clips the agent learned from.
AGENT_FPS = 30.0


def agent_frames(frame_count: int, fps: float) -> int:
    """Frames at the agent's rate spanning the seconds of `frame_count` scene frames at `fps`."""
    return int(round((int(frame_count) - 1) * AGENT_FPS / float(fps))) + 1


def scene_frames(agent_frame_count: float, fps: float) -> int:
    """Scene frames at `fps` spanning the seconds of `agent_frame_count` frames at the agent's rate."""
    return int(round((float(agent_frame_count) - 1.0) * float(fps) / AGENT_FPS)) + 1


def seconds(frame_count: int, fps: float) -> float:
    """Seconds a gesture of `frame_count` frames lasts at `fps`, first key to last."""
    return max(int(frame_count) - 1, 0) / float(fps)
