"""Seeded mutations of an agent file, aimed at its zip structure, its npy headers and its metadata.

`mutations(original, rng)` yields (kind, bytes) without end; `outcome(path, reference)` loads a file
through the extension's loader and names what happened. Shared by tests/core/test_agent_file_fuzz.py
and benchmarks/agent_fuzz_benchmark.py.

Kinds:
    zip_local, zip_central, zip_end   bytes of a local file header, the central directory or its end
                                      record changed (bit flips, bytes, 2- and 4-byte fields set to edge
                                      values, bytes inserted or deleted, the file cut there)
    npy_raw, metadata_raw             bytes of an npy header or of the metadata text changed in place
                                      (the zip CRC no longer matches)
    npy_header                        an npy header rewritten (shapes of 2**40 and more, other dtypes,
                                      characters changed, added or removed) in a valid zip
    metadata_value                    one metadata value the add-on reads replaced (1e300, inf, NaN,
                                      1e12, strings, lists, huge integers, arms...) or removed, in a valid
                                      zip: the config, bounds, lengths, behaviours and every wave_rhythm
                                      field (its arms, phases and flags added where the file has none)
    metadata_text                     characters of the metadata JSON changed, in a valid zip
    deflate_bomb                      an entry replaced by megabytes of deflated zeros behind a valid header
    compressed_raw                    bytes of an entry's deflated data changed (the archive deflated first)
    other_method                      the archive, or one entry, compressed with LZMA or bzip2 (sometimes with
                                      bytes of the compressed data changed), or the compression method field
                                      of a stored entry set to another method (bzip2, LZMA, zstd, AES...)
    npy_length                        an npy header's length field set to an edge value: in place, or as a
                                      version 2.0 header of 2 to 4 GiB in a valid zip, 4 MB of deflated spaces
                                      behind it
    entry_bomb                        1,025 to 1,000,000 empty entries in the central directory (zip64 end
                                      records past 65,535)
    weight_value                      one weight array as float64 scaled by up to 1e300, or one of its
                                      values set to an edge value, in a valid zip
"""
import io
import json
import struct
import zipfile

import numpy as np

import fuzz_json
from rlanimate_addon.core import agent_file, gesture, runtime
from rlanimate_addon.core.errors import RLAnimateError

KINDS = ("zip_local", "zip_central", "zip_end", "npy_raw", "metadata_raw", "npy_header", "metadata_value",
         "metadata_text", "deflate_bomb", "compressed_raw", "other_method", "npy_length", "entry_bomb",
         "weight_value")
#: Outcomes the loader may have: refused with an RLAnimateError, the original agent exactly, or a
#: still-valid changed file read exactly as numpy reads it and baking finite keys. Anything else fails.
ACCEPTED = ("refused", "identical", "valid other file")
_EDGE_FIELDS = (0, 1, 0x7FFF, 0xFFFF, 0x7FFFFFFF, 0x80000000, 0xFFFFFFFF)
_EDGE_VALUES = (1e300, -1e300, float("inf"), float("-inf"), float("nan"), 1e12, 1e8, 0, -3, 1, 2.5, True, None,
                "abc", "", [], {}, [1.0, 2.0], {"POINT": 1e300}, 10 ** 400, [[0.0, 1.0]] * 45, [[[[[]]]]],
                ["LEFT", "RIGHT"], [["LEFT"]], "LEFT", {"name": "point", "kind": "target"})
_METADATA_PATHS = (("action_bounds", 0, 0), ("action_bounds", 44, 1), ("action_bounds", 7), ("action_bounds",),
                   ("average_frames", "POINT"), ("average_frames", "WAVE"), ("average_frames",),
                   ("agent_config", "hidden_layers"), ("agent_config", "hidden_size"),
                   ("agent_config", "task_size"), ("agent_config", "stochastic_size"), ("agent_config", "min_std"),
                   ("agent_config", "concentration_scale"), ("agent_config",), ("variant",), ("format_version",),
                   ("format",), ("wave_rhythm", "examples", 0, 1), ("wave_rhythm", "examples", 1, 0),
                   ("wave_rhythm", "phase"), ("wave_rhythm", "ramp"), ("wave_rhythm", "bandwidth"), ("wave_rhythm",),
                   ("wave_rhythm", "examples", 0), ("wave_rhythm", "examples"), ("wave_rhythm", "phases"),
                   ("wave_rhythm", "arms"), ("wave_rhythm", "typical_tempo"), ("wave_rhythm", "by_arm"),
                   ("wave_rhythm", "tempo_bandwidth"), ("behaviours",), ("behaviours", 0), ("behaviours", 1, "kind"),
                   ("behaviours", 0, "name"))
_SHAPES = ("(1099511627776,)", "(1048576, 1048576)", "(-1, 64)", "(10000000000000000000000000000,)", "(0,)",
           "()", "(64,)", "(192, 64)", "(8796093022208, 8)")
_DESCRS = ("'<f8'", "'|O'", "'<U2000000000000'", "'>f4'", "'|V0'", "'<i4'", "[('a', '<f4')]", "'garbage'",
           "'<f4'", "('<f4', (1000000000,))", "'<U1'")
_HEADER_CHARACTERS = "{}()[],:'\" 0123456789\n\x00\\eéU<>|fO"
#: Compression methods a zip header may name: bzip2, LZMA, zstd, xz, JPEG, WavPack, PPMd, AES, and unknown.
_METHODS = (12, 14, 93, 95, 96, 97, 98, 99, 1, 6, 9, 0xFFFF)
_HEADER_LENGTHS = (0, 1, 0x7FFF, 0xFFFF, 0x10000, 0x7FFFFFFF, 0x80000000, 0xFFFFFFFF)
_ENTRY_COUNTS = (1025, 65535, 1_000_000)
_WEIGHT_VALUES = (1e300, -1e300, 1e30, 1e5, float("inf"), float("-inf"), float("nan"), 0.0)
_FRAMES = 40


class Reference:
    """The unmutated agent: its bytes, weights, metadata and the keys every identical load must give."""

    def __init__(self, path):
        self.data = path.read_bytes()
        self.weights, self.metadata = agent_file.load_agent_file(path)
        self.keys = _keys(runtime.GestureAgent(self.weights, self.metadata))


def _keys(agent):
    """The output of an agent: the quaternions Generate Gesture would key for a 40-frame gesture of each
    behaviour it was trained for, concatenated over bones (40, B, 4)."""
    targets = np.tile([-1.2, -2.5, 1.7], (_FRAMES, 1))
    requests = [gesture.GestureRequest(b, "RIGHT", _FRAMES, targets=targets) if agent.space.kind(b) == "target"
                else gesture.GestureRequest(b, "RIGHT", _FRAMES, exaggeration=0.7) for b in agent.behaviours]
    return np.concatenate([gesture.gesture_rotations(agent, request, gesture.canonical_rig())[1]
                           for request in requests], axis=1)


def outcome(path, reference):
    """What the extension's loader (core.runtime.load_agent) made of the file at `path`, as a short string.

    A load is followed by the gesture it would bake; an RLAnimateError there (non-finite keys) means the
    loader let a bad file through, as with bounds of 1e300, and counts as a changed output.
    """
    try:
        agent = runtime.load_agent(path)
    except RLAnimateError:
        return "refused"
    except Exception as error:  # noqa: BLE001  (what the fuzz looks for)
        return f"other exception {type(error).__name__}: {str(error)[:200]}"
    try:
        keys = _keys(agent)
        weights, metadata = agent_file.load_agent_file(path)
    except Exception as error:  # noqa: BLE001
        return f"changed output ({type(error).__name__}: {str(error)[:200]})"
    if not np.all(np.isfinite(keys)):
        return "changed output (non-finite keys)"
    if _same(weights, metadata, reference.weights, reference.metadata):
        return "identical" if np.array_equal(keys, reference.keys) else "changed output"
    numpy_weights, numpy_metadata = _numpy_reading(path)
    if numpy_weights is None or not _same(weights, metadata, numpy_weights, numpy_metadata):
        return "changed output"
    return "valid other file"


def _same(weights, metadata, other_weights, other_metadata):
    return json.dumps(metadata, sort_keys=True) == json.dumps(other_metadata, sort_keys=True) \
        and weights.keys() == other_weights.keys() \
        and all(weights[k].dtype == other_weights[k].dtype and np.array_equal(weights[k], other_weights[k])
                for k in weights)


def _numpy_reading(path):
    """The file as numpy's own loader reads it (weights, metadata), or (None, None)."""
    try:
        with np.load(path, allow_pickle=False) as archive:
            arrays = {name: archive[name] for name in archive.files}
        return arrays, json.loads(str(arrays.pop(agent_file.METADATA_KEY)))
    except Exception:  # noqa: BLE001  (numpy's reading is only the reference)
        return None, None


def mutations(original, rng):
    """Endless (kind, mutated bytes) from the agent file's bytes `original`, drawn with the numpy Generator rng."""
    layout = _Layout(original)
    while True:
        kind = KINDS[rng.integers(len(KINDS))]
        yield kind, _MUTATORS[kind](layout, rng)


class _Layout:
    """Where the parts of a (stored) npz sit: local headers, npy headers, metadata text, central directory."""

    def __init__(self, data):
        self.data = data
        with zipfile.ZipFile(io.BytesIO(data)) as archive:
            self.infos = archive.infolist()
            self.contents = {info.filename: archive.read(info) for info in self.infos}
        self.local, self.npy = [], []
        for info in self.infos:
            start = info.header_offset
            name_length, extra_length = struct.unpack_from("<HH", data, start + 26)
            body = start + 30 + name_length + extra_length
            self.local.append((start, body))
            header_length = struct.unpack_from("<H", data, body + 8)[0]
            self.npy.append((body, body + 10 + header_length))
            if info.filename == agent_file.METADATA_KEY + ".npy":
                self.metadata_text = (body + 10 + header_length, body + info.file_size)
        names = [info.filename for info in self.infos]
        self.bomb_entries = [agent_file.METADATA_KEY + ".npy"] + names[:2]
        self.bombs = {}
        self.end = len(data) - 22
        size, offset = struct.unpack_from("<II", data, self.end + 12)
        self.central = (offset, offset + size)
        self.central_headers = [offset]  # where each central directory header starts
        while len(self.central_headers) < len(self.infos):
            start = self.central_headers[-1]
            self.central_headers.append(start + 46 + sum(struct.unpack_from("<HHH", data, start + 28)))
        self.repacked = {}  # compression method -> (archive bytes, [(start, stop) of each entry's data])

    def repack(self, method):
        """The archive with every entry compressed by `method`, and where each entry's compressed data lies."""
        if method not in self.repacked:
            data = _rezip(self, {}, None, method)
            with zipfile.ZipFile(io.BytesIO(data)) as archive:
                regions = []
                for info in archive.infolist():
                    body = info.header_offset + 30 + sum(struct.unpack_from("<HH", data, info.header_offset + 26))
                    regions.append((body, body + info.compress_size))
            self.repacked[method] = data, regions
        return self.repacked[method]


def _raw(data, region, rng):
    data = bytearray(data)
    start, stop = region
    position = int(rng.integers(start, max(stop, start + 1)))
    operation = rng.integers(6)
    if operation == 0:
        data[position] ^= 1 << int(rng.integers(8))
    elif operation == 1:
        data[position] = int(rng.choice([0, 0xFF, 0x7F, 0x80, int(rng.integers(256))]))
    elif operation == 2:
        width = int(rng.choice([2, 4]))
        value = int(rng.choice(_EDGE_FIELDS)) & (0xFFFF if width == 2 else 0xFFFFFFFF)
        data[position:position + width] = value.to_bytes(width, "little")
    elif operation == 3:
        data[position:position] = rng.integers(256, size=int(rng.integers(1, 9)), dtype=np.uint8).tobytes()
    elif operation == 4:
        del data[position:position + int(rng.integers(1, 9))]
    else:
        del data[position:]
    return bytes(data)


def _pick(items, rng):
    return items[int(rng.integers(len(items)))]


def _zip_local(layout, rng):
    return _raw(layout.data, _pick(layout.local, rng), rng)


def _zip_central(layout, rng):
    return _raw(layout.data, layout.central, rng)


def _zip_end(layout, rng):
    return _raw(layout.data, (layout.end, len(layout.data)), rng)


def _npy_raw(layout, rng):
    return _raw(layout.data, _pick(layout.npy, rng), rng)


def _metadata_raw(layout, rng):
    return _raw(layout.data, layout.metadata_text, rng)


def _rezip(layout, replaced, rng, method=None):
    """The archive again with some entries' bytes replaced, stored or deflated, with valid CRCs."""
    buffer = io.BytesIO()
    method = method or (zipfile.ZIP_DEFLATED if rng.random() < 0.3 else zipfile.ZIP_STORED)
    with zipfile.ZipFile(buffer, "w", compression=method) as archive:
        for info in layout.infos:
            archive.writestr(info.filename, replaced.get(info.filename, layout.contents[info.filename]))
    return buffer.getvalue()


def _npy_bytes(header_text, body):
    header = header_text.encode("latin1", errors="replace")
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header + body


def _npy_header(layout, rng):
    name = _pick(list(layout.contents), rng)
    content = layout.contents[name]
    header_length = struct.unpack_from("<H", content, 8)[0]
    text, body = content[10:10 + header_length].decode("latin1"), content[10 + header_length:]
    operation = rng.integers(4)
    if operation == 0:
        start, stop = text.index("'shape': ") + 9, text.index(")", text.index("'shape': ")) + 1
        text = text[:start] + _pick(_SHAPES, rng) + text[stop:]
    elif operation == 1:
        start = text.index("'descr': ") + 9
        text = text[:start] + _pick(_DESCRS, rng) + text[text.index(",", start):]
    elif operation == 2:
        characters = list(text)
        for _ in range(int(rng.integers(1, 4))):
            characters[int(rng.integers(len(characters)))] = _pick(_HEADER_CHARACTERS, rng)
        text = "".join(characters)
    else:
        position = int(rng.integers(len(text)))
        text = text[:position] + text[position + int(rng.integers(1, 4)):] if rng.random() < 0.5 \
            else text[:position] + _pick(_HEADER_CHARACTERS, rng) + text[position:]
    return _rezip(layout, {name: _npy_bytes(text, body)}, rng)


def _metadata_entry(text):
    buffer = io.BytesIO()
    np.save(buffer, np.array(text))
    return buffer.getvalue()


def _metadata_value(layout, rng):
    metadata = fuzz_json.set_or_remove(json.loads(_metadata_text(layout)), _pick(_METADATA_PATHS, rng), rng,
                                       _EDGE_VALUES)
    text = json.dumps(metadata)  # inf and NaN as JSON's Infinity and NaN, as Python writes them
    return _rezip(layout, {agent_file.METADATA_KEY + ".npy": _metadata_entry(text)}, rng)


def _metadata_text(layout):
    return str(np.load(io.BytesIO(layout.contents[agent_file.METADATA_KEY + ".npy"])))


def _metadata_text_mutation(layout, rng):
    characters = list(_metadata_text(layout))
    for _ in range(int(rng.integers(1, 4))):
        characters[int(rng.integers(len(characters)))] = _pick('{}[]:,"0123456789.-eE naNInfinity\\', rng)
    return _rezip(layout, {agent_file.METADATA_KEY + ".npy": _metadata_entry("".join(characters))}, rng)


def _deflate_bomb(layout, rng):
    """An entry whose deflated data inflates to megabytes of zeros after a valid header of its own shape."""
    name = _pick(layout.bomb_entries, rng)
    megabytes = int(rng.choice([16, 64]))
    if (name, megabytes) not in layout.bombs:
        content = layout.contents[name]
        header = content[:10 + struct.unpack_from("<H", content, 8)[0]]
        layout.bombs[name, megabytes] = _rezip(layout, {name: header + bytes(megabytes * 2 ** 20)}, None,
                                               zipfile.ZIP_DEFLATED)
    return layout.bombs[name, megabytes]


def _compressed_raw(layout, rng):
    data, regions = layout.repack(zipfile.ZIP_DEFLATED)
    return _raw(data, _pick(regions, rng), rng)


def _other_method(layout, rng):
    operation = rng.integers(3)
    method = int(rng.choice([zipfile.ZIP_LZMA, zipfile.ZIP_BZIP2]))
    if operation == 0:  # the whole archive repacked, its compressed data changed half the time
        data, regions = layout.repack(method)
        return _raw(data, _pick(regions, rng), rng) if rng.random() < 0.5 else data
    if operation == 1:  # one entry compressed with another method, as zipfile writes it
        name = _pick(list(layout.contents), rng)
        buffer = io.BytesIO()
        with zipfile.ZipFile(buffer, "w") as archive:
            for info in layout.infos:
                archive.writestr(info.filename, layout.contents[info.filename],
                                 compress_type=method if info.filename == name else zipfile.ZIP_STORED)
        return buffer.getvalue()
    data = bytearray(layout.data)  # a stored entry's method field changed (0 -> 14 is the audit's 2-byte change)
    value = _pick(_METHODS, rng)
    entry = int(rng.integers(len(layout.infos)))
    for offset in ((layout.local[entry][0] + 8,), (layout.central_headers[entry] + 10,),
                   (layout.local[entry][0] + 8, layout.central_headers[entry] + 10))[rng.integers(3)]:
        data[offset:offset + 2] = struct.pack("<H", value)
    return bytes(data)


def _npy_length(layout, rng):
    if rng.random() < 0.5:  # in place: the field of a version 1.0 header (2 bytes), the CRC then wrong
        data = bytearray(layout.data)
        start = _pick(layout.npy, rng)[0] + 8
        data[start:start + 2] = struct.pack("<H", _pick(_HEADER_LENGTHS, rng) & 0xFFFF)
        return bytes(data)
    name = _pick(layout.bomb_entries[:2], rng)
    length = _pick(_HEADER_LENGTHS[-3:], rng)
    key = name, "length", length
    if key not in layout.bombs:  # a version 2.0 header claiming `length` bytes, and 4 MB of spaces behind it
        entry = b"\x93NUMPY\x02\x00" + struct.pack("<I", length) + b" " * (4 * 2 ** 20)
        layout.bombs[key] = _rezip(layout, {name: entry}, None, zipfile.ZIP_DEFLATED)
    return layout.bombs[key]


def _entry_bomb(layout, rng):
    count = _pick(_ENTRY_COUNTS, rng)
    if ("entries", count) not in layout.bombs:
        layout.bombs["entries", count] = with_empty_entries(layout.data, count)
    return layout.bombs["entries", count]


def with_empty_entries(data, count):
    """The archive `data` (no comment) with `count` more empty entries in its central directory, and
    zip64 end records, as zipfile writes them, past 65,535 entries."""
    end = len(data) - 22
    entries, size, offset = struct.unpack_from("<HII", data, end + 10)
    header = struct.pack("<4s6H3I5H2I", b"PK\x01\x02", 20, 20, 0, 0, 0, 0, 0, 0, 0, 12, 0, 0, 0, 0, 0, 0)
    directory = data[offset:offset + size] + b"".join([header + b"e%07d.npy" % k for k in range(count)])
    total = entries + count
    tail = b""
    if total > 0xFFFF:
        tail = struct.pack("<4sQ2H2I4Q", b"PK\x06\x06", 44, 45, 45, 0, 0, total, total, len(directory), offset) + \
            struct.pack("<4sIQI", b"PK\x06\x07", 0, offset + len(directory), 1)
    tail += struct.pack("<4s4H2IH", b"PK\x05\x06", 0, 0, min(total, 0xFFFF), min(total, 0xFFFF), len(directory),
                        offset, 0)
    return data[:offset] + directory + tail


def _weight_value(layout, rng):
    names = [name for name in layout.contents if name != agent_file.METADATA_KEY + ".npy"]
    name = _pick(names, rng)
    array = np.load(io.BytesIO(layout.contents[name])).astype(np.float64)
    value = _pick(_WEIGHT_VALUES, rng)
    if rng.random() < 0.5:
        array *= value if abs(value) >= 1 else 1.0
    else:
        array.flat[int(rng.integers(array.size))] = value
    buffer = io.BytesIO()
    np.save(buffer, array)
    return _rezip(layout, {name: buffer.getvalue()}, rng)


_MUTATORS = {"zip_local": _zip_local, "zip_central": _zip_central, "zip_end": _zip_end, "npy_raw": _npy_raw,
             "metadata_raw": _metadata_raw, "npy_header": _npy_header, "metadata_value": _metadata_value,
             "metadata_text": _metadata_text_mutation, "deflate_bomb": _deflate_bomb,
             "compressed_raw": _compressed_raw, "other_method": _other_method, "npy_length": _npy_length,
             "entry_bomb": _entry_bomb, "weight_value": _weight_value}
