"""The agent-file holes of issue 29: memory and time bombs read before the checks (npy header-length
fields, entry counts), compression methods other than stored and deflate, huge values that still bake,
and inf named as NaN. Each is refused with a message naming the file, the field and the fix, quickly,
and the file is left as it was."""
import io
import json
import re
import struct
import time
import tracemalloc
import zipfile
from pathlib import Path

import numpy as np
import pytest

import agent_fuzz
from rlanimate_addon.core import agent_file, runtime
from rlanimate_addon.core.errors import RLAnimateError

SHIPPED = Path(__file__).resolve().parents[2] / "rlanimate_addon" / "agents" / "default.npz"


def _contents(data):
    with zipfile.ZipFile(io.BytesIO(data)) as archive:
        return {info.filename: archive.read(info) for info in archive.infolist()}


def _zip(contents, methods=None):
    """An archive of `contents` {name: bytes}, each entry compressed with methods.get(name, stored)."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        for name, data in contents.items():
            archive.writestr(name, data, compress_type=(methods or {}).get(name, zipfile.ZIP_STORED))
    return buffer.getvalue()


def _refused(path, pattern):
    """Load `path` as the panel and Generate do, expecting a refusal matching `pattern` that names the file,
    in well under a second and 10 MB, with the file unchanged."""
    before = path.read_bytes()
    tracemalloc.start()
    start = time.perf_counter()
    with pytest.raises(RLAnimateError) as refused:
        runtime.load_agent(path)
    seconds, peak = time.perf_counter() - start, tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    message = str(refused.value)
    assert str(path) in message
    assert re.search(pattern, message), message
    assert seconds < 0.5 and peak < 10 * 2 ** 20, (seconds, peak)
    assert path.read_bytes() == before
    return message


@pytest.fixture(scope="module")
def shipped():
    return SHIPPED.read_bytes()


@pytest.mark.parametrize("method, name", [(zipfile.ZIP_LZMA, "LZMA"), (zipfile.ZIP_BZIP2, "bzip2")])
def test_an_lzma_or_bzip2_entry_is_refused_naming_the_entry_and_the_fix(tmp_path, shipped, method, name):
    path = tmp_path / "repacked.npz"
    path.write_bytes(_zip(_contents(shipped), {"prior.layers.0.bias.npy": method}))
    _refused(path, rf"compresses 'prior\.layers\.0\.bias\.npy' with zip method {method} \({name}\); agents are "
                   r"stored or deflated.*re-export it with trainer/agent/agent_export\.py, or re-zip it")


@pytest.mark.parametrize("where", ["central", "both"])
def test_the_audits_two_byte_change_of_the_shipped_file_to_lzma_is_refused(tmp_path, shipped, where):
    data = bytearray(shipped)
    central = data.index(b"PK\x01\x02")
    data[central + 10:central + 12] = struct.pack("<H", zipfile.ZIP_LZMA)  # stored (0) -> LZMA (14)
    if where == "both":
        data[8:10] = struct.pack("<H", zipfile.ZIP_LZMA)
    path = tmp_path / "lzma.npz"
    path.write_bytes(bytes(data))
    _refused(path, r"with zip method 14 \(LZMA\)")


def test_damaged_lzma_data_is_a_domain_error_too(tmp_path, shipped):
    """Were the method check to miss an entry, what the LZMA decompressor raises is still 'damaged'."""
    data = bytearray(_zip(_contents(shipped), {name: zipfile.ZIP_LZMA for name in _contents(shipped)}))
    body = 30 + struct.unpack_from("<H", data, 26)[0]
    data[body + 4:body + 12] = bytes(8)
    with zipfile.ZipFile(io.BytesIO(bytes(data))) as archive, pytest.raises(RLAnimateError, match="damaged"):
        with agent_file._unreadable("lzma.npz"):
            archive.read(archive.infolist()[0])


@pytest.mark.parametrize("length", [0xFFFFFFFF, 2 ** 31, 10_001])
def test_an_npy_header_length_field_claiming_gigabytes_is_refused_before_numpy_reads_it(tmp_path, shipped, length):
    contents = _contents(shipped)
    name = agent_file.METADATA_KEY + ".npy"
    contents[name] = b"\x93NUMPY\x02\x00" + struct.pack("<I", length) + b" " * 2 ** 20  # 1 MB of the "header"
    path = tmp_path / "header.npz"
    path.write_bytes(_zip(contents, {name: zipfile.ZIP_DEFLATED}))
    _refused(path, rf"is truncated or damaged \(the npy header of {agent_file.METADATA_KEY} claims {length:,} bytes, "
                   r"more than 10,000\): export or copy it again")


def test_an_archive_of_65535_entries_is_refused_from_its_end_record(tmp_path, shipped):
    path = tmp_path / "entries.npz"
    path.write_bytes(agent_fuzz.with_empty_entries(shipped, 0xFFFF - 39))
    _refused(path, r"declares 65,535 entries in a 3,[0-9,]+-byte directory, more than any agent \(1,024 entries "
                   r"in 262,144 bytes at most\): choose a \.npz written by trainer/agent/agent_export\.py")


def test_an_archive_of_a_million_entries_is_refused_from_its_end_record(tmp_path, shipped):
    path = tmp_path / "entries.npz"
    path.write_bytes(agent_fuzz.with_empty_entries(shipped, 1_000_000))
    _refused(path, r"is a zip64 archive, made for more entries or bytes than any agent has: choose a \.npz")


def test_a_large_directory_of_few_entries_is_refused_too(tmp_path, shipped):
    """zipfile parses the central directory by its size, whatever the count says."""
    data = bytearray(agent_fuzz.with_empty_entries(shipped, 20_000))
    data[-14:-10] = struct.pack("<2H", 39, 39)  # the end record claims the original 39 entries
    path = tmp_path / "entries.npz"
    path.write_bytes(bytes(data))
    _refused(path, r"declares 39 entries in a [0-9,]+-byte directory, more than any agent")


def _rewritten(shipped, weights=None, metadata=None):
    contents = _contents(shipped)
    for name, array in (weights or {}).items():
        buffer = io.BytesIO()
        np.save(buffer, array)
        contents[name + ".npy"] = buffer.getvalue()
    if metadata is not None:
        buffer = io.BytesIO()
        np.save(buffer, np.array(json.dumps(metadata)))
        contents[agent_file.METADATA_KEY + ".npy"] = buffer.getvalue()
    return _zip(contents)


def test_a_float64_agent_scaled_by_1e300_is_refused_naming_the_array(tmp_path, shipped):
    weights, _ = agent_file.load_agent_file(SHIPPED)
    path = tmp_path / "huge.npz"
    path.write_bytes(_rewritten(shipped, {name: array.astype(np.float64) * 1e300 for name, array in weights.items()}))
    _refused(path, r"has values as large as [0-9.]+e\+(299|300) in animation\.layers\.0\.bias \(a trained agent's "
                   r"weights are finite and within \+-10000\): .*train it again")


def test_a_float64_copy_of_the_agent_still_loads_exactly(tmp_path, shipped):
    weights, metadata = agent_file.load_agent_file(SHIPPED)
    path = tmp_path / "float64.npz"
    path.write_bytes(_rewritten(shipped, {name: array.astype(np.float64) for name, array in weights.items()}))
    loaded, loaded_metadata = agent_file.load_agent_file(path)
    assert loaded_metadata == metadata and all(np.array_equal(loaded[k], weights[k]) for k in weights)


@pytest.mark.parametrize("bad, named", [(np.inf, "1 infinite value"), (np.nan, "1 NaN value")])
def test_inf_and_nan_are_named_as_what_they_are(tmp_path, shipped, bad, named):
    weights, _ = agent_file.load_agent_file(SHIPPED)
    array = weights["decoder.layers.1.weight"].copy()
    array[3, 4] = bad
    path = tmp_path / "nonfinite.npz"
    path.write_bytes(_rewritten(shipped, {"decoder.layers.1.weight": array}))
    message = _refused(path, rf"has {named} in decoder\.layers\.1\.weight")
    assert ("NaN" in message) == np.isnan(bad)


@pytest.mark.parametrize("field, value, named", [("bandwidth", 1e300, "1e+300"), ("phase", 10 ** 400, "about 1e400"),
                                                 ("ramp", float("inf"), "infinite"), ("ramp", float("nan"), "NaN")],
                         ids=["1e300", "10**400", "inf", "nan"])
def test_wave_rhythm_magnitudes_are_checked(tmp_path, shipped, field, value, named):
    _, metadata = agent_file.load_agent_file(SHIPPED)
    metadata["wave_rhythm"][field] = value
    path = tmp_path / "rhythm.npz"
    path.write_bytes(_rewritten(shipped, metadata=metadata))
    _refused(path, rf"has a wave_rhythm value of {re.escape(named)}, beyond \+-1000 .*re-export it with "
                   r"trainer/agent/agent_export\.py")
