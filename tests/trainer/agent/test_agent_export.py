"""Exporting an agent: one atomic, data-only .npz whose weights and metadata load back unchanged."""
import json

import numpy as np
import pytest
import torch

from rlanimate_addon.core import agent_file, skeleton, spaces
from rlanimate_addon.core.agent_file import load_agent_file
from trainer.agent.agent_export import export_agent
from trainer.agent.config import load_preset
from trainer.agent.models import VARIANTS, RLAnimateAgent
from trainer.paths import INSTALLED_AGENT

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
