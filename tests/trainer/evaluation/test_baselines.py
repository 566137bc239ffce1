"""Baselines: nearest-clip retrieval answers requests with valid clips that the one scorer scores."""
import numpy as np
import pytest

from rlanimate_addon.core import skeleton
from rlanimate_addon.core.errors import RLAnimateError
from tests.trainer.synthetic_library import make_clip
from trainer.evaluation import baselines, scoring
from trainer.motion.fk import ClipReferences, NumpyFKEnvironment

JOINTS = len(skeleton.ACTION_JOINTS)


def _wave(exaggeration, frames):
    return make_clip(f"wave_{exaggeration}", "WAVE", "RIGHT", exaggeration, frames)


def _valid(motion, frames):
    assert motion.shape == (frames, JOINTS, 3)
    assert np.all(np.isfinite(motion))


def test_time_warp_keeps_the_ends_and_resamples_the_length():
    rng = np.random.default_rng(0)
    clip = rng.normal(0.0, 0.4, (40, JOINTS, 3))
    warped = baselines.time_warp(clip, 73)
    _valid(warped, 73)
    np.testing.assert_allclose(warped[[0, -1]], clip[[0, -1]], atol=1e-9)
    np.testing.assert_allclose(baselines.time_warp(clip, 40), clip, atol=1e-9)


def test_nearest_clip_retrieves_the_closest_label():
    library = [_wave(e, 60 + int(100 * e)) for e in (0.1, 0.5, 0.9)]
    library.append(make_clip("point_up", "POINT", "LEFT", [1.0, -2.0, 2.5], 70))
    up = library[-1].attributes
    nearest = baselines.NearestClip(library)
    assert nearest.nearest("WAVE", "RIGHT", 0.62).name == "wave_0.5"
    motion = nearest.generate("WAVE", "RIGHT", 0.62, 97)
    _valid(motion, 97)
    np.testing.assert_allclose(motion[[0, -1]], library[1].rotvecs[[0, -1]], atol=1e-9)
    assert nearest.nearest("POINT", "LEFT", [0.3, -1.0, 0.4]).name == "point_up"
    with pytest.raises(RLAnimateError, match="right arm"):
        nearest.generate("POINT", "RIGHT", up, 50)


def test_with_a_tempo_nearest_clip_weighs_the_swing_rate_beside_the_exaggeration():
    library = [make_clip(name, "WAVE", "RIGHT", e, 150, hz) for name, e, hz in
               (("slow", 0.50, 1.2), ("same_label", 0.52, 2.5), ("big", 0.9, 2.4), ("small", 0.1, 1.0))]
    nearest = baselines.NearestClip(library)
    assert nearest.nearest("WAVE", "RIGHT", 0.52).name == "same_label"
    assert nearest.nearest("WAVE", "RIGHT", 0.52, tempo=1.3).name == "slow"
    assert nearest.nearest("WAVE", "RIGHT", 0.52, tempo=2.4).name == "same_label"
    assert nearest.nearest("WAVE", "RIGHT", 0.52, tempo=2.4, exclude=library[1]).name == "big", "leave one out"
    with pytest.raises(RLAnimateError, match="No wave training clip uses the right arm"):
        baselines.NearestClip(library[:1]).nearest("WAVE", "RIGHT", 0.5, exclude=library[0])
    assert baselines.request_tempo(library[0], True) == pytest.approx(1.2, rel=0.05)
    assert baselines.request_tempo(library[0], False) is None


def test_a_take_whose_tempo_cannot_be_read_is_asked_with_its_label_and_named():
    """A take under a second (or one whose hand does not swing) names no tempo: its request falls back to the
    label, and the fallback names the take and why, where reading its tempo used to stop the whole set."""
    library = [make_clip("slow", "WAVE", "RIGHT", 0.5, 150, 1.2), make_clip("fast", "WAVE", "RIGHT", 0.55, 150, 2.5)]
    short = make_clip("short", "WAVE", "RIGHT", 0.5, 19, 1.2)
    still = make_clip("still", "WAVE", "RIGHT", 0.5, 90, 1.2)
    still.rotvecs[:] = still.rotvecs[:1]
    tempos, fallbacks = baselines.request_tempos([library[0], short, still], True)
    assert tempos[0] == pytest.approx(1.2, rel=0.05) and tempos[1:] == [None, None]
    assert set(fallbacks) == {"short", "still"}
    assert "19 frames, under 1 s" in fallbacks["short"] and "does not swing" in fallbacks["still"]
    assert baselines.request_tempos([short], False) == ([None], {})
    nearest = baselines.NearestClip(library + [short])  # a short training take is ranked as one without a tempo
    motions = baselines.generate_for(nearest, [library[0], short], with_tempo=True)
    assert [len(m) for m in motions] == [150, 19]
    assert nearest.nearest("WAVE", "RIGHT", 0.55, tempo=2.4).name == "fast"


def test_the_evaluator_scores_baseline_clips():
    env = NumpyFKEnvironment()
    reference, other = _wave(1.0, 80), _wave(0.0, 60)
    references = ClipReferences(env)
    for baseline in (baselines.NearestClip([other]), baselines.NearestClip([reference, other])):
        motions = baselines.generate_for(baseline, [reference])
        _valid(motions[0], 80)
        result = scoring.score_motions(env, motions, [reference], references)
        assert np.isfinite(result["score"]) and 0.0 <= result["smoothness"] <= 100.0
        assert result["clips"][0]["name"] == "wave_1.0" and set(result["by_behaviour"]) == {"wave"}
    exact = scoring.score_motions(env, [reference.rotvecs], [reference], references)
    assert exact["score"] == pytest.approx(100.0)
    copied = scoring.score_motions(env, baselines.generate_for(baselines.NearestClip([other]), [reference]),
                                   [reference], references)
    assert copied["score"] < exact["score"] - 0.5  # a different exaggeration costs score


def test_the_agent_plays_a_tempo_beyond_what_it_learned_at_the_nearest_it_allows(tmp_path):
    import torch

    from rlanimate_addon.core import rhythm, runtime
    from trainer.agent.agent_export import export_agent
    from trainer.agent.config import load_preset
    from trainer.agent.models import RLAnimateAgent

    torch.manual_seed(0)
    model = rhythm.RhythmModel.fit([0.2, 0.8], [rhythm.Rhythm(0.05, 0.3, 0.7, 0.2, 9.0),
                                                rhythm.Rhythm(0.08, 0.3, 0.7, 0.4, 9.0)])
    path = tmp_path / "agent.npz"
    export_agent(RLAnimateAgent(load_preset("debug")[0]), path,
                 {"average_frames": {"POINT": 80, "WAVE": 95}, "wave_rhythm": model.to_dict()})
    agent = runtime.load_agent(path)
    low, high = agent.tempo_range()
    for beyond, nearest in ((0.2, low), (9.0, high)):
        np.testing.assert_array_equal(baselines.agent_motion(agent, "WAVE", "LEFT", 0.5, 90, tempo=beyond),
                                      baselines.agent_motion(agent, "WAVE", "LEFT", 0.5, 90, tempo=nearest))
    assert not np.array_equal(baselines.agent_motion(agent, "WAVE", "LEFT", 0.5, 90, tempo=low),
                              baselines.agent_motion(agent, "WAVE", "LEFT", 0.5, 90, tempo=high))
