"""A clip library loaded for training and evaluation: its clips (imported through Blender) and the bpy FK
environment, loaded once and shared by the runs of an experiment."""
from trainer.agent.algorithm import ClipReferences
from trainer.blender_io.clip_import import load_clip_set
from trainer.blender_io.fk_env import FKEnvironment
from trainer.motion.manifest import manifest_path
from trainer.paths import SAMPLE_RIG_BLEND


class LibrarySession:
    """What a run needs besides the trainer (trainer.agent.run.train's `session`): env, references,
    train_clips, test_clips, problems."""

    def __init__(self, clips, rig_path=SAMPLE_RIG_BLEND):
        self.manifest = manifest_path(clips)
        self.clip_set = load_clip_set(self.manifest)
        self.env = FKEnvironment(rig_path)
        self.references = ClipReferences(self.env)

    @property
    def train_clips(self):
        return self.clip_set.train

    @property
    def test_clips(self):
        return self.clip_set.test

    @property
    def problems(self):
        """One message per clip of the manifest that could not be used (the run's report lists them)."""
        return self.clip_set.problems
