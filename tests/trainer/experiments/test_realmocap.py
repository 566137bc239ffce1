"""Real motion capture: labels on import, and the experiment pipeline end to end."""
import numpy as np
import pytest

from rlanimate_addon.core import skeleton
from trainer.blender_io.fk_env import FKEnvironment
from trainer.blender_io.procedural_ik import ProceduralIK
from trainer.blender_io.rig_session import new_empty_scene
from trainer.evaluation import baselines
from trainer.experiments import realmocap
from trainer.experiments.realmocap import RealMocapSettings
from trainer.experiments.run import train as train_run
from trainer.motion import autolabel, wave_rhythm
from trainer.motion.fk import ClipReferences
from trainer.motion.realmocap_takes import wave_split
from trainer.motion.synthesis import neutral_pose
from trainer.paths import REALMOCAP_DIR
from trainer.reporting.realmocap_report import frames_figure, seed_summary

needs_data = pytest.mark.skipif(not (REALMOCAP_DIR / "wave").is_dir(),
                                reason=f"real motion capture not found at {REALMOCAP_DIR} "
                                       "(../shared/realmocap/ beside the repository)")


@needs_data
def test_imported_clips_are_labelled_from_their_motion(tmp_path):
    wave = realmocap.import_real_clip(REALMOCAP_DIR / "wave" / "dataset-2_wave-right-hand_normal_003.bvh",
                                      tmp_path)
    assert (wave.behaviour, wave.arm, wave.named_arm, wave.style, wave.take) == (
        "WAVE",
        "RIGHT",
        "RIGHT",
        "normal",
        "003",
    )
    assert 0.0 <= wave.exaggeration <= 1.0 and wave.attributes == wave.exaggeration
    assert np.allclose(wave.rotvecs[:, skeleton.ACTION_JOINTS.index("RightHandIndex1")],
                       neutral_pose()["RightHandIndex1"])
    guide = realmocap.import_real_clip(REALMOCAP_DIR / "guide" / "dataset-1_guide_normal_001.bvh", tmp_path)
    assert guide.behaviour == "POINT" and guide.arm == "RIGHT"
    assert abs(np.linalg.norm(guide.attributes) - 1.0) < 1e-9
    assert 0 < guide.label.hold_frame < guide.frames - 1


@needs_data
def test_experiment_pipeline_runs_end_to_end_on_a_few_clips(tmp_path):
    new_empty_scene()
    folder = REALMOCAP_DIR / "wave"
    clips = [realmocap.import_real_clip(folder / name, tmp_path / "cache") for name in
             ("dataset-2_wave-left-hand_feminine_001.bvh", "dataset-2_wave-left-hand_active_002.bvh",
              "dataset-2_wave-left-hand_normal_009.bvh")]
    train, test = wave_split(clips)
    env = FKEnvironment(instances=4)
    references = ClipReferences(env)
    session = realmocap.RealSession(env, references, train, test)
    run = realmocap.real_run("wave", train, test, 0, RealMocapSettings(epochs=1, preset="debug", runs=str(tmp_path)))
    assert run.settings.output == str(tmp_path / "wave_debug") and run.train_takes == tuple(c.source for c in train)
    report, _ = train_run(run.settings, session)
    agent = baselines.AgentMethod(tmp_path / "wave_debug" / "agent.npz")
    assert report["episodes"] == 1 and agent.agent.metadata["training"]["clips"].endswith("realmocap:wave")
    methods = {"rlanimate": agent, "nearest_clip": baselines.NearestClip(train),
               "procedural_ik": ProceduralIK(baselines.mean_start_pose(train))}
    comparison = realmocap.compare(methods, test, env, references)
    for result in comparison.values():
        assert np.isfinite(result["score"]) and 0.0 <= result["smoothness"] <= 100.0
        assert 0.0 <= result["label_error"] <= 1.0
    asked = realmocap.compare({name: methods[name] for name in ("nearest_clip", "procedural_ik")}, test, env,
                              references, with_tempo=True)
    tempo = wave_rhythm.clip_tempo(test[0])
    assert 0.5 < tempo < 5.0 and all(np.isfinite(result["score"]) for result in asked.values())
    assert asked["procedural_ik"]["clips"][0]["frequency_ratio"] == pytest.approx(
        1.0, abs=0.2
    )  # it swings at the tempo
    tempos = realmocap.tempo_table(clips, references)
    assert set(tempos) == {"feminine", "active", "normal"} and tempos["active"]["takes"] == 1
    assert tempos["active"]["spectrum_hz"] == pytest.approx(tempos["active"]["strokes_hz"], rel=0.1)  # a clear swing
    assert tempos["normal"]["spectrum_hz"] == pytest.approx(tempo) and tempos["active"]["stroke_cm"] > 10.0
    assert tempos["normal"]["by_takes"] == {"009-010": {"takes": 1, "exaggeration": test[0].exaggeration,
                                                        "spectrum_hz": pytest.approx(tempo)}}
    assert list(tempos["feminine"]["by_takes"]) == ["001-006"]
    summary = seed_summary(comparison["rlanimate"])
    assert summary["clips"] == len(test) and 0 <= summary["accepted"] <= len(test)
    assert summary["aligned_score"] == comparison["rlanimate"]["by_behaviour"]["wave"]["aligned_score"]
    # The nearest clip to the normal wave (e ~ 0.7) is the active one, not the feminine one.
    assert methods["nearest_clip"].nearest("WAVE", "LEFT", test[0].exaggeration).style == "active"
    angles = realmocap.guide_angles(methods["procedural_ik"], [_as_point(test[0])], env)
    assert 0.0 <= angles["mean_forearm_angle_deg"] <= 180.0
    picture = tmp_path / "frames.png"
    generated = methods["rlanimate"].generate("WAVE", "LEFT", test[0].exaggeration, test[0].frames)
    frames_figure(env, [("t", test[0].rotvecs, generated)], picture, times=(0.5,))
    assert picture.stat().st_size > 1000
    # One experiment's entry as run_experiments writes it: every method and request, each seed's agent.
    entry, first = realmocap._experiment("wave", train, {"test": test}, {0: (run.settings.output, report)}, env,
                                         references)
    assert first.path == agent.path and entry["train_cpu_seconds"] == {"0": report["train_cpu_seconds"]}
    assert set(entry) >= {"seen", "test", "test_tempo", "test_seeds", "test_tempo_seeds"}
    assert entry["test"]["rlanimate"]["score"] == comparison["rlanimate"]["score"]
    assert entry["test_seeds"] == {"0": seed_summary(entry["test"]["rlanimate"])}


def _as_point(clip):
    import copy
    label = autolabel.label_point(clip.rotvecs, clip.arm)
    point = copy.copy(clip)
    point.behaviour, point.attributes, point.label = "POINT", label.direction, label
    return point
