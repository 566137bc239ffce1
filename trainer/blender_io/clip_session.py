"""A clip library loaded for training and evaluation: its clips (imported through Blender) and the bpy FK
environment, loaded once and shared by the runs of an experiment."""
import sys

import numpy as np

from trainer.blender_io.clip_import import load_clip_set
from trainer.blender_io.fk_env import FKEnvironment
from trainer.blender_io.rig_session import blender_output
from trainer.motion.fk import ClipReferences
from trainer.motion.manifest import manifest_path
from trainer.paths import SAMPLE_RIG_BLEND, shown


class LibrarySession:
    """What a run needs besides the trainer (trainer.experiments.run.train's `session`): env, references,
    train_clips, test_clips, problems."""

    def __init__(self, clips, rig_path=SAMPLE_RIG_BLEND, verbose=False, import_workers=1, import_limits=None):
        """Load the library with a progress bar and Blender's own prints held back (shown with `verbose`),
        then say in one line what was loaded, and name every file that was skipped. The clips the import
        cache lacks are imported by `import_workers` import workers at once, each clip within
        `import_limits` (an ImportLimits; None: the default)."""
        self.manifest = manifest_path(clips)
        with blender_output(verbose) as terminal:
            self.clip_set = load_clip_set(self.manifest, progress=terminal, workers=import_workers,
                                          limits=import_limits)
            self.env = FKEnvironment(rig_path)
        self.references = ClipReferences(self.env)
        problems = self.clip_set.problems
        print(f"clips: {len(self.clip_set.clips)} from {shown(self.manifest)} ({len(self.train_clips)} training, "
              f"{len(self.test_clips)} held out){f'; {len(problems)} skipped' if problems else ''}", file=sys.stderr)
        for problem in problems:
            print(f"  skipped: {problem}", file=sys.stderr)

    @property
    def train_clips(self):
        return self.clip_set.train

    @property
    def test_clips(self):
        return self.clip_set.test

    def describe(self, rotvecs):
        """(F, 42) self-descriptions of canonical rotations (F, 15, 3), by the session's Blender FK."""
        return np.asarray(self.env.evaluate(np.asarray(rotvecs, dtype=np.float64)).descriptions)

    @property
    def problems(self):
        """One message per clip of the manifest that could not be used (the run's report lists them)."""
        return self.clip_set.problems
