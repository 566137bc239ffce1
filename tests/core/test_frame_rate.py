"""core.frame_rate: a gesture's seconds at the scene's rate and at the agent's 30 fps."""
import pytest

from rlanimate_addon.core import frame_rate


@pytest.mark.parametrize("fps", [24, 25, 30, 50, 60, 30 / 1.001, 24 / 1.001])
def test_agent_frames_span_the_same_seconds_and_come_back(fps):
    for count in (3, 46, 93, 116, 120, 174):
        span = frame_rate.agent_frames(count, fps)
        assert (
            abs((span - 1) / frame_rate.AGENT_FPS - frame_rate.seconds(count, fps)) <= 0.5 / frame_rate.AGENT_FPS + 1e-9
        )
        assert abs(frame_rate.scene_frames(span, fps) - count) <= max(1, round(fps / frame_rate.AGENT_FPS))


def test_at_the_agents_rate_frames_are_unchanged():
    assert [frame_rate.agent_frames(n, 30) for n in (3, 46, 120)] == [3, 46, 120]
    assert frame_rate.agent_frames(120, 24) == 150 and frame_rate.agent_frames(120, 60) == 61
