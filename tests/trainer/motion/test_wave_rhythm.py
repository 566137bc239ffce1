import numpy as np
import pytest

from rlanimate_addon.core import spaces
from trainer.agent.algorithm import clip_objective
from trainer.motion import synthesis as gs
from trainer.motion import wave_rhythm
from trainer.motion.clip import MotionClip


def _clip(spec):
    synthesised = gs.synthesise(spec)
    clip = MotionClip(name="w", source="", fps=synthesised.fps, rotvecs=synthesised.action_rotvecs(),
                      behaviour=spec.behaviour, arm=spec.arm)
    return clip, synthesised


@pytest.mark.parametrize("arm, exaggeration, seed", [("LEFT", 0.1, 3), ("RIGHT", 0.8, 11)])
def test_the_rhythm_read_from_a_synthesised_wave_matches_how_it_was_made(arm, exaggeration, seed):
    clip, synthesised = _clip(gs.GestureSpec("WAVE", arm, exaggeration=exaggeration, seed=seed))
    style = gs.draw_style(seed)
    made_hz = style.wave_frequency - 0.2 * exaggeration
    read = wave_rhythm.clip_rhythm(clip)
    assert read.frequency * clip.fps == pytest.approx(made_hz, rel=0.05)
    first, last = synthesised.phases["wave"]
    span = clip.frames - 1
    assert abs(read.start * span - first) <= 6 and abs(read.stop * span - last) <= 6  # within 0.2 s


def test_a_slow_wave_is_read_at_its_own_rate_not_its_harmonics():
    """Real takes swing at 0.8-1.5 Hz, with strokes that are not sinusoids. The synthesised wave played
    2.5 times slower swings at 0.8-1 Hz; a reader that high-passes at the sample library's rate reads
    no swing there, or a harmonic."""
    clip, synthesised = _clip(gs.GestureSpec("WAVE", "RIGHT", exaggeration=0.6, seed=4))
    slowed = np.linspace(0.0, clip.frames - 1, int(2.5 * clip.frames))
    clip.rotvecs = np.stack(
        [np.interp(slowed, np.arange(clip.frames), channel) for channel in clip.rotvecs.reshape(clip.frames, -1).T],
        axis=1,
    ).reshape(len(slowed), -1, 3)
    made_hz = (gs.draw_style(4).wave_frequency - 0.2 * 0.6) / 2.5
    read = wave_rhythm.clip_rhythm(clip)
    assert read.frequency * clip.fps == pytest.approx(made_hz, rel=0.05)
    first, last = (2.5 * frame for frame in synthesised.phases["wave"])
    span = len(slowed) - 1
    assert abs(read.start * span - first) <= 15 and abs(read.stop * span - last) <= 15  # within 0.5 s


def test_a_clip_without_a_swing_has_no_rhythm_and_a_still_objective():
    clip, _ = _clip(gs.GestureSpec("WAVE", "LEFT", exaggeration=0.5, seed=1))
    clip.rotvecs = np.repeat(clip.rotvecs[:1], clip.frames, axis=0)  # the first pose, held
    clip.attributes = 0.5
    assert wave_rhythm.clip_rhythm(clip) is None
    objective = clip_objective(spaces.PAPER_SPACE, clip)
    assert np.all(objective[:, spaces.OBJECTIVE_ATTRIBUTES][:, 1:] == 0.0)  # the rhythm signals: no swing


def test_the_fitted_model_keeps_each_swinging_waves_arm_in_order_and_skips_a_still_one():
    waves = []
    for arm, seed in (("LEFT", 3), ("RIGHT", 11), ("LEFT", 5)):
        clip, _ = _clip(gs.GestureSpec("WAVE", arm, exaggeration=0.5, seed=seed))
        clip.attributes = 0.5
        waves.append(clip)
    still, _ = _clip(gs.GestureSpec("WAVE", "RIGHT", exaggeration=0.5, seed=1))
    still.rotvecs, still.attributes = np.repeat(still.rotvecs[:1], still.frames, axis=0), 0.5
    model = wave_rhythm.fit_rhythm_model(waves[:2] + [still] + waves[2:])
    assert model.arms == ("LEFT", "RIGHT", "LEFT")
