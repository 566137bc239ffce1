"""The development command that writes an untrained default-config agent."""
from rlanimate_addon.core.agent_file import load_agent_file
from trainer.agent.config import load_preset
from trainer.paths import INSTALLED_AGENT
from trainer.scripts import export_untrained_agent


def test_writes_an_untrained_default_agent_under_two_megabytes(tmp_path):
    path = tmp_path / "default.npz"
    export_untrained_agent.main(["export_untrained_agent", str(path)])
    _, metadata = load_agent_file(path)
    assert path.stat().st_size < 2_000_000
    assert metadata["agent_config"] == load_preset("default")[0].to_dict()
    assert metadata["training"]["untrained"] is True


def test_without_a_path_it_writes_the_add_ons_default_agent():
    assert export_untrained_agent.parse_settings(["export_untrained_agent"]).path == INSTALLED_AGENT
