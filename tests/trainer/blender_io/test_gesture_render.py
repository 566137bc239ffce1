"""Generate Gesture rendered by Blender: the operator bakes, Cycles renders the character and the target."""
import numpy as np
import pytest

pytest.importorskip("bpy")

from trainer.blender_io import gesture_render  # noqa: E402


def test_renders_the_baked_gesture_and_its_target(tmp_path, monkeypatch):
    import matplotlib.pyplot as plt

    monkeypatch.setattr(gesture_render, "KEY_FRACTIONS", (0.0, 0.5))
    request = gesture_render.RenderRequest("point", {"behaviour": "POINT", "arm": "RIGHT", "exact_aim": True},
                                           target=(-0.9, -2.0, 1.7))
    (done,) = gesture_render.render_requests([request], tmp_path)
    assert [offset for offset, _ in done.frames][0] == 0
    start, middle = (plt.imread(str(path))[..., :3] for _, path in done.frames)
    red = middle[..., 0] - middle[..., 1:].max(axis=-1) > 0.12  # the only saturated colour in the scene
    assert red.sum() > 5, "the target sphere must show"
    moved = np.abs(middle - start).max(axis=-1) > 0.1
    assert moved.sum() > 100, "the arm must move between the first frame and the middle of the gesture"
