"""The play-time rhythm ablation on real capture: its experiment selector, the phases it reads again for
agent files that lack them, and the variant methods (trainer/experiments/realmocap_ablation.py)."""
import numpy as np
import pytest

from rlanimate_addon.core import rhythm
from rlanimate_addon.core.errors import RLAnimateError
from rlanimate_addon.core.rhythm import RhythmModel
from tests.trainer.synthetic_library import make_clip
from trainer.evaluation import baselines
from trainer.experiments import realmocap_ablation
from trainer.motion import wave_rhythm
from trainer.paths import INSTALLED_AGENT
from trainer.scripts.realmocap_ablation import parse_settings


def test_the_script_runs_only_the_experiments_it_is_given():
    settings = parse_settings(["prog", "--experiments", "wave", "wave", "--seed", "1", "--epochs", "3"])
    assert (settings.experiments, settings.seed, settings.epochs) == (("wave",), 1, 3)
    assert parse_settings(["prog"]).experiments == ("wave", "holdout")
    assert "--experiments wave --seed 1 --epochs 3" in realmocap_ablation.command_line(settings)
    with pytest.raises(SystemExit):
        parse_settings(["prog", "--experiments", "guide"])
    with pytest.raises(RLAnimateError, match="Unknown real-capture experiment"):
        realmocap_ablation.AblationSettings(experiments=("bye",))


def test_an_agent_file_without_phases_gets_its_training_waves_phases_read_again():
    waves = [make_clip(f"wave_{k}", "WAVE", ("LEFT", "RIGHT")[k % 2], 0.1 + 0.15 * k, 90 + 7 * k) for k in range(5)]
    read = [(clip.attributes, wave_rhythm.clip_rhythm(clip)) for clip in waves]
    assert all(r is not None for _, r in read)
    fitted = RhythmModel.fit([e for e, _ in read], [r for _, r in read])
    older = RhythmModel(fitted.examples, fitted.phase, fitted.ramp, fitted.bandwidth)  # as files before phases
    again = realmocap_ablation.rhythm_with_phases(older, waves)
    assert again.phases is not None and np.array_equal(again.phases, fitted.phases) and not again.typical_tempo
    assert realmocap_ablation.rhythm_with_phases(fitted, []) is fitted
    with pytest.raises(RLAnimateError, match="retrain"):
        realmocap_ablation.rhythm_with_phases(older, waves[::-1])
    for clip in waves:
        clip.style = "normal" if clip.arm == "LEFT" else "active"
    phases = realmocap_ablation.style_phases(wave_rhythm.swinging(waves))
    left = np.exp(1j * fitted.phases[::2])
    assert phases["normal"] == {"phase": pytest.approx(np.angle(left.mean())),
                                "concentration": pytest.approx(abs(left.mean())), "waves": 3}


@pytest.mark.skipif(not INSTALLED_AGENT.is_file(), reason="no shipped agent")
def test_a_variant_plays_its_own_rhythm_model_and_seed_and_leaves_the_agent_alone():
    agent = baselines.AgentMethod(INSTALLED_AGENT)
    model = agent.agent.rhythm_model
    seeded = realmocap_ablation.VariantMethod(agent, model, rhythm_seed=3, state_seed=3)
    assert np.array_equal(seeded.generate("WAVE", "LEFT", 0.6, 60), agent.generate("WAVE", "LEFT", 0.6, 60, seed=3))
    mean = realmocap_ablation.VariantMethod(agent, model)
    assert np.array_equal(mean.generate("WAVE", "LEFT", 0.6, 60), agent.generate("WAVE", "LEFT", 0.6, 60))
    sampled = realmocap_ablation.VariantMethod(agent, model, state_seed=3).generate("WAVE", "LEFT", 0.6, 60)
    assert not np.allclose(sampled, mean.generate("WAVE", "LEFT", 0.6, 60))
    shifted = RhythmModel(model.examples, model.phase + np.pi, model.ramp, model.bandwidth)
    turned = realmocap_ablation.VariantMethod(agent, shifted)
    assert agent.agent.rhythm_model is model
    assert not np.allclose(turned.generate("WAVE", "LEFT", 0.6, 60), agent.generate("WAVE", "LEFT", 0.6, 60))


@pytest.mark.skipif(not INSTALLED_AGENT.is_file(), reason="no shipped agent")
def test_the_own_rhythm_diagnostic_plays_each_take_at_the_rhythm_read_from_it():
    agent = baselines.AgentMethod(INSTALLED_AGENT)
    takes = [make_clip(f"wave_{k}", "WAVE", arm, 0.3 + 0.2 * k, 90 + 10 * k) for k, arm in enumerate(("LEFT", "RIGHT"))]
    own = realmocap_ablation.OwnRhythm(agent, takes)
    for clip in takes:
        read = wave_rhythm.clip_rhythm(clip)
        signals = rhythm.signals(read, len(clip.rotvecs))
        played = own.generate("WAVE", clip.arm, clip.attributes, len(clip.rotvecs))
        assert np.array_equal(played, baselines.agent_motion(agent.agent, "WAVE", clip.arm, clip.attributes,
                                                             len(clip.rotvecs), rhythm_signals=signals))
        assert not np.allclose(played, agent.generate("WAVE", clip.arm, clip.attributes, len(clip.rotvecs)))
    with pytest.raises(KeyError):  # only the takes it was given
        own.generate("WAVE", "LEFT", 0.31, 90)
