"""Exporting an agent: one atomic, data-only .npz whose weights and metadata load back unchanged."""
import json

import numpy as np
import pytest
import torch

from rlanimate_addon.core import agent_file, runtime, skeleton, spaces
from rlanimate_addon.core.agent_file import load_agent_file
from trainer.agent.agent_export import export_agent
from trainer.agent.config import AgentConfig, load_preset
from trainer.agent.models import VARIANTS, RLAnimateAgent
from trainer.experiments.run import NEW_RUN_DEFAULTS
from trainer.motion.manifest import manifest_path
from trainer.paths import DEFAULT_MANIFEST, INSTALLED_AGENT, REPO_ROOT

torch.set_num_threads(1)


@pytest.mark.parametrize("variant", VARIANTS)
def test_round_trip_keeps_every_weight_and_the_metadata(tmp_path, variant):
    agent_config, train_config = load_preset("debug")
    torch.manual_seed(0)
    agent = RLAnimateAgent(agent_config, variant)
    bounds = spaces.DEFAULT_ACTION_BOUNDS * 0.9
    path = tmp_path / "agent.npz"
    export_agent(agent, path, {"train_config": train_config, "average_frames": {"POINT": 84, "WAVE": 101.5},
                               "action_bounds": bounds, "training": {"seed": 3, "epochs": 7, "clips": "x"},
                               "evaluation": {"held_out_score": 99.1, "episodes": np.int64(200)}})
    weights, metadata = load_agent_file(path)
    state = agent.state_dict()
    assert set(weights) == set(state)
    for name, tensor in state.items():
        assert weights[name].dtype == np.float32
        np.testing.assert_array_equal(weights[name], tensor.numpy().astype(np.float32))
    assert metadata["format"] == agent_file.FORMAT_NAME
    assert metadata["format_version"] == agent_file.FORMAT_VERSION
    assert metadata["variant"] == variant
    assert metadata["agent_config"] == agent_config.to_dict()
    assert metadata["train_config"] == train_config.to_dict()
    assert metadata["average_frames"] == {"POINT": 84.0, "WAVE": 101.5}
    np.testing.assert_allclose(metadata["action_bounds"], bounds)
    assert metadata["training"]["seed"] == 3 and metadata["training"]["epochs"] == 7
    assert metadata["training"]["date"] and "git_commit" in metadata["training"]
    assert metadata["evaluation"] == {"held_out_score": 99.1, "episodes": 200}
    assert metadata["spaces"]["action_joints"] == list(skeleton.ACTION_JOINTS)
    assert metadata["spaces"]["action_size"] == spaces.ACTION_SIZE
    assert metadata["rig"]["required_bones"] == list(skeleton.REQUIRED_BONES)


def test_the_file_needs_no_pickle_and_holds_json_text(tmp_path):
    path = tmp_path / "agent.npz"
    export_agent(RLAnimateAgent(load_preset("debug")[0]), path)
    with np.load(path, allow_pickle=False) as archive:
        entry = archive[agent_file.METADATA_KEY]
        assert entry.dtype.kind == "U"
        assert json.loads(str(entry))["format"] == agent_file.FORMAT_NAME
        assert all(archive[name].dtype.kind in "fU" for name in archive.files)


def test_export_replaces_atomically_and_leaves_no_temporary_file(tmp_path):
    path = tmp_path / "agents" / "agent.npz"
    export_agent(RLAnimateAgent(load_preset("debug")[0], "single_state"), path)
    export_agent(RLAnimateAgent(load_preset("debug")[0], "single_dynamics"), path)
    assert load_agent_file(path)[1]["variant"] == "single_dynamics"
    assert [p.name for p in path.parent.iterdir()] == ["agent.npz"]


def test_the_shipped_default_agent_loads():
    weights, metadata = load_agent_file(INSTALLED_AGENT)
    assert metadata["variant"] in VARIANTS
    assert (INSTALLED_AGENT).stat().st_size < 2_000_000


@pytest.mark.parametrize("clips, recorded", [(str(DEFAULT_MANIFEST), "sample_rigs/clips/manifest.json"),
                                             ("/home/ann/mocap/library/manifest.json", "manifest.json"),
                                             (None, None)])
def test_training_paths_are_recorded_relative_to_the_repository_or_as_a_file_name(tmp_path, clips, recorded):
    path = tmp_path / "agent.npz"
    metadata = export_agent(RLAnimateAgent(load_preset("debug")[0]), path, {"training": {"clips": clips, "seed": 1}})
    assert metadata["training"]["clips"] == recorded
    assert load_agent_file(path)[1]["training"] == metadata["training"]
    text = json.dumps(metadata)
    assert str(REPO_ROOT) not in text and "/home/ann" not in text


def test_the_shipped_agent_is_what_the_readme_run_exports_and_names_no_machine_path(tmp_path):
    """Exporting the shipped weights with the metadata the README's training run gives (run.py's
    defaults, the clips' manifest as its report records it) writes the shipped file again: every array
    bit for bit, the metadata equal but for the git commit and the date of the run."""
    weights, shipped = load_agent_file(INSTALLED_AGENT)
    assert "/" + str(REPO_ROOT).split("/")[1] not in json.dumps(shipped), "the shipped metadata names no machine path"
    space = runtime.load_agent(INSTALLED_AGENT).space
    assert space.names == ("POINT", "WAVE", "GUIDE", "RAISE_HAND"), "every behaviour of the sample library"
    assert sorted(shipped["still_free_arm"]) == sorted(space.names), "the sample clips leave every free arm still"
    agent = RLAnimateAgent(AgentConfig.from_dict(shipped["agent_config"]), shipped["variant"], space)
    agent.load_state_dict({name: torch.from_numpy(array) for name, array in weights.items()})
    training = {key: shipped["training"][key] for key in ("behaviour", "variant", "preset", "seed", "epochs",
                                                          "episodes", "train_seconds")}
    training["clips"] = str(manifest_path(NEW_RUN_DEFAULTS["clips"]))  # as run.py's report records it
    path = tmp_path / "agent.npz"
    written = export_agent(agent, path, {
        "training": training, "train_config": shipped["train_config"], "action_bounds": shipped["action_bounds"],
        "average_frames": shipped["average_frames"], "wave_rhythm": shipped["wave_rhythm"],
        "still_free_arm": shipped["still_free_arm"], "evaluation": shipped["evaluation"]})
    for metadata in (written, shipped):
        metadata["training"] = {k: v for k, v in metadata["training"].items() if k not in ("git_commit", "date")}
    assert shipped["format_version"] == agent_file.FORMAT_VERSION and shipped["training"]["behaviour"] == "all"
    assert written == shipped
    with np.load(path) as new, np.load(INSTALLED_AGENT) as old:
        assert new.files == old.files
        assert all(new[name].dtype == old[name].dtype and new[name].tobytes() == old[name].tobytes()
                   for name in old.files if name != agent_file.METADATA_KEY)
