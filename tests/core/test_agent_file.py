"""The agent-file loader: a real exported file loads; every kind of bad file gets its own clear error."""
import io
import json
import pickle
import re
import struct
import time
import zipfile

import numpy as np
import pytest
import torch

from rlanimate_addon.core import agent_file, runtime, spaces
from rlanimate_addon.core.agent_file import load_agent_file
from rlanimate_addon.core.errors import RLAnimateError
from trainer.agent.agent_export import export_agent
from trainer.agent.config import load_preset
from trainer.agent.models import RLAnimateAgent

torch.set_num_threads(1)


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    path = tmp_path_factory.mktemp("agent") / "agent.npz"
    torch.manual_seed(0)
    export_agent(RLAnimateAgent(load_preset("debug")[0]), path)
    return path


def rewrite(path, weights, metadata, **extra):
    np.savez(path, **weights, **{agent_file.METADATA_KEY: np.array(json.dumps(metadata))}, **extra)
    return path


def test_a_real_exported_file_loads(exported):
    weights, metadata = load_agent_file(exported)
    assert metadata["variant"] == "rlanimate"
    assert set(weights) == set(agent_file.expected_weight_shapes(metadata["agent_config"], "rlanimate", 7))


def test_missing_file(tmp_path):
    with pytest.raises(RLAnimateError, match="No agent file"):
        load_agent_file(tmp_path / "nowhere.npz")


@pytest.mark.parametrize("fraction", [0.0, 0.1, 0.5, 0.99])
def test_truncated_file(tmp_path, exported, fraction):
    data = exported.read_bytes()
    path = tmp_path / "truncated.npz"
    path.write_bytes(data[:int(len(data) * fraction)])
    with pytest.raises(RLAnimateError, match="truncated or damaged"):
        load_agent_file(path)


def test_flipped_bytes_inside_a_weight_array(tmp_path, exported):
    data = bytearray(exported.read_bytes())
    middle = len(data) // 2
    data[middle:middle + 16] = bytes(255 - b for b in data[middle:middle + 16])
    path = tmp_path / "flipped.npz"
    path.write_bytes(bytes(data))
    with pytest.raises(RLAnimateError, match="truncated or damaged"):
        load_agent_file(path)


def test_wrong_format_version(tmp_path, exported):
    weights, metadata = load_agent_file(exported)
    path = rewrite(tmp_path / "v99.npz", weights, {**metadata, "format_version": 99})
    with pytest.raises(RLAnimateError, match="format version 99"):
        load_agent_file(path)


def test_a_file_declares_its_behaviours_and_a_version_3_file_loads_as_point_and_wave(tmp_path, exported):
    weights, metadata = load_agent_file(exported)
    assert metadata["format_version"] == agent_file.FORMAT_VERSION == 4
    assert metadata["behaviours"] == [{"name": "POINT", "kind": "target"}, {"name": "WAVE", "kind": "intensity"}]
    old = {key: value for key, value in metadata.items() if key != "behaviours"}
    _, loaded = load_agent_file(rewrite(tmp_path / "v3.npz", weights, {**old, "format_version": 3}))
    assert agent_file.objective_space(loaded) == spaces.PAPER_SPACE
    with pytest.raises(RLAnimateError, match="lacks metadata behaviours"):
        load_agent_file(rewrite(tmp_path / "v4.npz", weights, old))


def test_what_a_behaviour_does_is_read_from_the_file_else_from_its_shipped_name(tmp_path, exported):
    weights, metadata = load_agent_file(exported)
    space = agent_file.objective_space(metadata)
    assert space.behaviour("POINT").aims and space.behaviour("WAVE").oscillates  # written before "does" existed
    declared = [{"name": "POINT", "kind": "target"}, {"name": "WAVE", "kind": "intensity", "does": "raise"}]
    _, loaded = load_agent_file(rewrite(tmp_path / "raise.npz", weights, {**metadata, "behaviours": declared}))
    space = agent_file.objective_space(loaded)
    assert space.behaviour("WAVE").does == "raise" and not space.behaviour("WAVE").oscillates
    assert space.oscillating() == () and [b.to_dict() for b in space.behaviours] == declared


@pytest.mark.parametrize("declared, message", [
    ([], "a list of 1 to 64 behaviours"),
    ([{"name": "POINT", "kind": "target"}], "invalid average_frames.*among POINT"),  # WAVE is not declared
    ([{"name": "POINT", "kind": "target", "extra": 1}, {"name": "WAVE", "kind": "intensity"}], "a list of 1 to 64"),
    ([{"name": "POINT", "kind": "aim"}, {"name": "WAVE", "kind": "intensity"}], "kind 'aim'"),
    ([{"name": "POINT", "kind": "target", "does": "wave"}, {"name": "WAVE", "kind": "intensity"}], "cannot do 'wave'"),
    ([{"name": "POINT", "kind": "target", "does": 1}, {"name": "WAVE", "kind": "intensity"}], "optionally, \"does\""),
    ([{"name": "WAVE", "kind": "intensity"}, {"name": "POINT", "kind": "target"}], "not in objective order"),
    ([{"name": "POINT", "kind": "target"}, {"name": "POINT", "kind": "target"}], "name one behaviour twice"),
    ([{"name": "point", "kind": "target"}, {"name": "WAVE", "kind": "intensity"}], "upper case"),
    ([{"name": "import os", "kind": "target"}, {"name": "WAVE", "kind": "intensity"}], "not a behaviour name"),
])
def test_invalid_declared_behaviours_are_refused(tmp_path, exported, declared, message):
    weights, metadata = load_agent_file(exported)
    with pytest.raises(RLAnimateError, match=message):
        load_agent_file(rewrite(tmp_path / "declared.npz", weights, {**metadata, "behaviours": declared}))


def test_a_version_1_file_from_before_the_wave_rhythm_is_refused_with_the_fix(tmp_path, exported):
    weights, metadata = load_agent_file(exported)
    old = {key: value for key, value in metadata.items() if key != "wave_rhythm"}
    with pytest.raises(RLAnimateError, match="format version 1, from before waves carried their rhythm.*retrain"):
        load_agent_file(rewrite(tmp_path / "v1.npz", weights, {**old, "format_version": 1}))


def test_a_version_2_file_with_a_line_for_its_wave_rhythm_is_refused_with_the_fix(tmp_path, exported):
    weights, metadata = load_agent_file(exported)
    lines = {name: {"intercept": 0.08, "slope": 0.0, "sd": 0.0, "low": 0.0, "high": 0.0}
             for name in ("frequency", "start", "stop")}
    old = {**metadata, "format_version": 2, "wave_rhythm": {"lines": lines, "phase": 0.0, "ramp": 9.0}}
    with pytest.raises(RLAnimateError, match="format version 2, whose wave rhythm is a line.*retrain"):
        load_agent_file(rewrite(tmp_path / "v2.npz", weights, old))


def test_a_broken_wave_rhythm_is_refused(tmp_path, exported):
    weights, metadata = load_agent_file(exported)
    path = tmp_path / "rhythm.npz"
    with pytest.raises(RLAnimateError, match=f"{path} has an invalid wave_rhythm .wave_rhythm lacks phase, ramp"):
        load_agent_file(rewrite(path, weights, {**metadata, "wave_rhythm": {"examples": []}}))
    for broken, field in (("fast", "wave_rhythm is a string"), ([1.0], "wave_rhythm is a list"),
                          (2.5, "wave_rhythm is a number"),
                          ({"examples": [[0.5, 0.03, 0.1, 0.9]] * 2, "phase": 0.0, "ramp": 9.0, "bandwidth": 0.1,
                            "arms": [["LEFT"]] * 2}, r"wave_rhythm\.arms must be")):
        with pytest.raises(RLAnimateError, match=f"{path} has an invalid wave_rhythm .{field}"):
            load_agent_file(rewrite(path, weights, {**metadata, "wave_rhythm": broken}))


def test_wrong_array_shape(tmp_path, exported):
    weights, metadata = load_agent_file(exported)
    weights["animation.layers.0.weight"] = weights["animation.layers.0.weight"][:, :-1]
    with pytest.raises(RLAnimateError, match=r"wrong shape animation\.layers\.0\.weight"):
        load_agent_file(rewrite(tmp_path / "shape.npz", weights, metadata))


def test_missing_array(tmp_path, exported):
    weights, metadata = load_agent_file(exported)
    del weights["behaviour_cell.weight_hh"]
    with pytest.raises(RLAnimateError, match=r"missing behaviour_cell\.weight_hh"):
        load_agent_file(rewrite(tmp_path / "missing.npz", weights, metadata))


def test_config_that_does_not_match_the_arrays(tmp_path, exported):
    weights, metadata = load_agent_file(exported)
    metadata["agent_config"]["stochastic_size"] += 1
    with pytest.raises(RLAnimateError, match="does not match its own config"):
        load_agent_file(rewrite(tmp_path / "config.npz", weights, metadata))


def test_pickled_object_array_is_refused(tmp_path, exported):
    weights, metadata = load_agent_file(exported)
    path = tmp_path / "pickled.npz"
    rewrite(path, weights, metadata, payload=np.array([{"run": "code"}], dtype=object))
    with pytest.raises(RLAnimateError, match="pickled Python object in payload"):
        load_agent_file(path)


def test_pickled_object_in_place_of_a_weight(tmp_path, exported):
    weights, metadata = load_agent_file(exported)
    weights["decoder.layers.0.bias"] = np.array([None] * len(weights["decoder.layers.0.bias"]), dtype=object)
    with pytest.raises(RLAnimateError, match=r"pickled Python object in decoder\.layers\.0\.bias"):
        load_agent_file(rewrite(tmp_path / "pickled_weight.npz", weights, metadata))


@pytest.mark.parametrize("bad, named", [(np.nan, "1 NaN value"), (np.inf, "1 infinite value"),
                                        (-np.inf, "1 infinite value"), (2e4, "values as large as 2e\\+04")])
def test_non_finite_or_huge_weight_is_named(tmp_path, exported, bad, named):
    weights, metadata = load_agent_file(exported)
    weights["posterior.layers.1.weight"][0, 0] = bad
    with pytest.raises(RLAnimateError, match=rf"has {named} in posterior\.layers\.1\.weight \(a trained agent's "
                                             rf"weights are finite and within \+-10000\).*train it again"):
        load_agent_file(rewrite(tmp_path / "nan.npz", weights, metadata))


def test_integer_weights_are_refused(tmp_path, exported):
    weights, metadata = load_agent_file(exported)
    weights["prior.layers.0.bias"] = weights["prior.layers.0.bias"].astype(np.int64)
    with pytest.raises(RLAnimateError, match="not floats"):
        load_agent_file(rewrite(tmp_path / "int.npz", weights, metadata))


def test_archive_without_metadata_is_not_an_agent(tmp_path):
    path = tmp_path / "other.npz"
    np.savez(path, x=np.zeros(3))
    with pytest.raises(RLAnimateError, match="not an RLAnimate agent file"):
        load_agent_file(path)


def test_bare_npy_is_not_an_agent(tmp_path):
    path = tmp_path / "array.npz"
    with open(path, "wb") as handle:
        np.save(handle, np.zeros(3))
    with pytest.raises(RLAnimateError, match="not an RLAnimate agent file"):
        load_agent_file(path)


@pytest.mark.parametrize("content", [b"just some text, not an archive", pickle.dumps({"weights": [1, 2]})])
def test_other_files_are_not_agents(tmp_path, content):
    path = tmp_path / "other.npz"
    path.write_bytes(content)
    with pytest.raises(RLAnimateError, match="not an RLAnimate agent file"):
        load_agent_file(path)


def test_other_format_name_is_not_an_agent(tmp_path, exported):
    weights, metadata = load_agent_file(exported)
    with pytest.raises(RLAnimateError, match="not an RLAnimate agent file"):
        load_agent_file(rewrite(tmp_path / "other.npz", weights, {**metadata, "format": "something-else"}))


def test_damaged_metadata_text(tmp_path, exported):
    weights, _ = load_agent_file(exported)
    path = tmp_path / "text.npz"
    np.savez(path, **weights, **{agent_file.METADATA_KEY: np.array('{"format": "rlanimate-agent", ')})
    with pytest.raises(RLAnimateError, match="truncated or damaged"):
        load_agent_file(path)


@pytest.mark.parametrize("field, value, message", [
    ("action_bounds", [[0.0, 1.0]] * 44, "action_bounds"),
    ("action_bounds", [[1.0, 0.0]] * 45, "action_bounds"),
    ("average_frames", {}, "average_frames"),
    ("average_frames", {"POINT": 90, "JUMP": 50}, "average_frames"),
    ("average_frames", {"POINT": 1}, "average_frames"),
    ("variant", "bigger", "unknown agent variant .bigger."),
    ("still_free_arm", "WAVE", "still_free_arm"),
    ("still_free_arm", ["JUMP"], "still_free_arm"),
    ("still_free_arm", [["WAVE"]], "still_free_arm"),
])
def test_invalid_metadata_values(tmp_path, exported, field, value, message):
    weights, metadata = load_agent_file(exported)
    with pytest.raises(RLAnimateError, match=message):
        load_agent_file(rewrite(tmp_path / "meta.npz", weights, {**metadata, field: value}))


def test_missing_metadata_field(tmp_path, exported):
    weights, metadata = load_agent_file(exported)
    del metadata["average_frames"]
    with pytest.raises(RLAnimateError, match="lacks metadata average_frames"):
        load_agent_file(rewrite(tmp_path / "meta.npz", weights, metadata))


def _rezip(path, replaced, compression=zipfile.ZIP_STORED):
    """A copy of the agent at `path` with some entries' bytes replaced (valid zip CRCs)."""
    with zipfile.ZipFile(path) as source:
        contents = {info.filename: source.read(info) for info in source.infolist()}
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", compression=compression) as archive:
        for name, data in contents.items():
            archive.writestr(name, replaced.get(name, data))
    return out.getvalue()


def _npy_header_text(path, entry):
    with zipfile.ZipFile(path) as archive:
        data = archive.read(entry)
    length = struct.unpack_from("<H", data, 8)[0]
    return data[10:10 + length].decode("latin1"), data[10 + length:]


def _with_header(text, body):
    header = text.encode("latin1")
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header + body


def test_an_npy_header_claiming_terabytes_is_refused_before_anything_is_allocated(tmp_path, exported):
    entry = "animation.layers.0.weight.npy"
    text, body = _npy_header_text(exported, entry)
    huge = re.sub(r"'shape': \([^)]*\)", "'shape': (1099511627776, 2)", text)  # 8 TiB of float32
    path = tmp_path / "huge.npz"
    path.write_bytes(_rezip(exported, {entry: _with_header(huge, body)}))
    start = time.perf_counter()
    with pytest.raises(RLAnimateError, match=r"wrong shape animation\.layers\.0\.weight \(1099511627776, 2\)"):
        load_agent_file(path)
    assert time.perf_counter() - start < 1.0


def test_metadata_declaring_gigabytes_is_refused(tmp_path, exported):
    entry = agent_file.METADATA_KEY + ".npy"
    text, body = _npy_header_text(exported, entry)
    huge = re.sub(r"'descr': '<U\d+'", "'descr': '<U2000000000'", text)
    path = tmp_path / "huge_metadata.npz"
    path.write_bytes(_rezip(exported, {entry: _with_header(huge, body)}))
    with pytest.raises(RLAnimateError, match="declares more metadata than any agent has"):
        load_agent_file(path)


def test_a_deflate_bomb_is_refused_without_inflating_it(tmp_path, exported):
    entry = "decoder.layers.0.weight.npy"
    text, body = _npy_header_text(exported, entry)
    bomb = _with_header(text, body + bytes(256 * 2 ** 20))  # 256 MB of zeros behind the array's own header
    path = tmp_path / "bomb.npz"
    path.write_bytes(_rezip(exported, {entry: bomb}, zipfile.ZIP_DEFLATED))
    assert path.stat().st_size < 2 * 2 ** 20
    start = time.perf_counter()
    with pytest.raises(RLAnimateError, match=r"truncated or damaged \(entry 'decoder\.layers\.0\.weight\.npy' declares "
                                             r"268,436,224 bytes, more than any agent's"):
        load_agent_file(path)
    assert time.perf_counter() - start < 0.5


def test_an_unparseable_npy_header_is_refused(tmp_path, exported):
    entry = "prior.layers.0.bias.npy"
    text, body = _npy_header_text(exported, entry)
    path = tmp_path / "token.npz"
    path.write_bytes(_rezip(exported, {entry: _with_header(text.replace("}", "(", 1), body)}))
    with pytest.raises(RLAnimateError, match="truncated or damaged"):
        load_agent_file(path)


def test_an_unsupported_zip_version_is_refused(tmp_path, exported):
    data = bytearray(exported.read_bytes())
    central = data.index(b"PK\x01\x02")
    data[central + 6:central + 8] = struct.pack("<H", 0xFF)  # "version needed to extract": 25.5
    path = tmp_path / "version.npz"
    path.write_bytes(bytes(data))
    with pytest.raises(RLAnimateError, match="truncated or damaged"):
        load_agent_file(path)


@pytest.mark.parametrize("field, value, message", [
    ("action_bounds", [[-1e300, 1e300]] * 45, "action_bounds"),
    ("action_bounds", [["a", "b"]] * 45, "action_bounds"),
    ("action_bounds", [[0.0, float("nan")]] * 45, "action_bounds"),
    ("action_bounds", [[0.0, True]] * 45, "action_bounds"),
    ("average_frames", {"POINT": float("inf")}, "average_frames"),
    ("average_frames", {"POINT": 1e12}, "average_frames"),
    ("average_frames", {"POINT": 10 ** 400}, "average_frames"),
    ("average_frames", {"POINT": "90"}, "average_frames"),
    ("average_frames", [90], "average_frames"),
    ("variant", ["rlanimate"], "names no agent variant"),
    ("format_version", True, "format version True"),
])
def test_metadata_values_of_the_wrong_type_or_range(tmp_path, exported, field, value, message):
    weights, metadata = load_agent_file(exported)
    with pytest.raises(RLAnimateError, match=message):
        load_agent_file(rewrite(tmp_path / "meta.npz", weights, {**metadata, field: value}))


@pytest.mark.parametrize("key, value", [("hidden_layers", 10 ** 8), ("hidden_size", 10 ** 6), ("task_size", 0),
                                        ("min_std", float("inf")), ("concentration_scale", "100"),
                                        ("hidden_layers", True)])
def test_agent_config_values_out_of_range_are_refused_at_once(tmp_path, exported, key, value):
    weights, metadata = load_agent_file(exported)
    metadata["agent_config"][key] = value
    path = rewrite(tmp_path / "config.npz", weights, metadata)
    start = time.perf_counter()
    with pytest.raises(RLAnimateError, match="invalid agent_config"):
        load_agent_file(path)
    assert time.perf_counter() - start < 0.5


@pytest.mark.parametrize("flags, message", [({"tempo_input": "yes"}, "invalid agent_config phase_input or tempo_input"),
                                            ({"tempo_input": True}, "tempo_input without phase_input")])
def test_a_tempo_input_needs_the_phase_input_beside_it(tmp_path, exported, flags, message):
    weights, metadata = load_agent_file(exported)
    metadata["agent_config"].update(flags)
    with pytest.raises(RLAnimateError, match=message):
        load_agent_file(rewrite(tmp_path / "tempo.npz", weights, metadata))


def test_an_agent_too_large_to_run_is_refused(tmp_path, exported):
    weights, metadata = load_agent_file(exported)
    metadata["agent_config"].update(hidden_size=4096, hidden_layers=16)
    with pytest.raises(RLAnimateError, match="more than the add-on runs"):
        load_agent_file(rewrite(tmp_path / "big.npz", weights, metadata))


def test_the_behaviours_that_hold_the_free_arm_still_are_read_and_old_files_hold_none(tmp_path, exported):
    weights, metadata = load_agent_file(exported)
    old = {key: value for key, value in metadata.items() if key != "still_free_arm"}
    assert runtime.load_agent(rewrite(tmp_path / "old.npz", weights, old)).still_free_arm == frozenset()
    held = runtime.load_agent(rewrite(tmp_path / "held.npz", weights, {**old, "still_free_arm": ["WAVE"]}))
    assert held.still_free_arm == frozenset({"WAVE"})
