"""The exported agent file: one `.npz` of float weight arrays plus JSON metadata, read without pickle.

Layout (format FORMAT_NAME, version FORMAT_VERSION):
    "__metadata__"   0-d numpy unicode array holding JSON text (see docs/AGENT.md for its fields)
    "<module>.<parameter>"   one float32 array per torch parameter, named as in the torch state_dict:
        portrayal.layers.K.{weight,bias}        o_t -> self-description d_t     (absent in single_state)
        task_rnn.{weight,bias}_{ih,hh}_l0       GRU h_t = f1(h_{t-1}, o_t)      (absent in single_state and
                                                                         single_dynamics)
        behaviour_cell.{weight,bias}_{ih,hh}    GRUCell e_t = f2(e_{t-1}; x_t)
        prior.layers.K.*, posterior.layers.K.*  Gaussian p(z_t | e_t), q(z_t | e_t, d_t)
        animation.layers.K.*, decoder.layers.K.*  Beta over a_t, and p(d_t | h_t, b_t)
`expected_weight_shapes` is the single statement of which arrays an agent of a given config and
variant has; the torch model, the exporter and the numpy runtime all agree with it.
"""
import contextlib
import io
import json
import math
import os
import struct
import tokenize
import warnings
import zipfile
import zlib
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import IO, Any, TypeGuard

import numpy as np
import numpy.typing as npt

from . import behaviours, rhythm, spaces
from .errors import RLAnimateError


def _lzma_error() -> type[Exception]:
    """lzma's error, or zlib's for a Python built without lzma, whose zipfile cannot inflate LZMA either."""
    try:
        from lzma import LZMAError
    except ImportError:
        return zlib.error
    return LZMAError


_LZMAError = _lzma_error()

FORMAT_NAME = "rlanimate-agent"
#: 2: waves' objectives carry their rhythm (core/rhythm.py) and the file its `wave_rhythm` model.
#: 3: that model holds the training waves' rhythms, not a line through them.
#: 4: the file declares its behaviours (`behaviours`: name and kind each), which lay out its objective
#:    (core/spaces.py); a version 3 file holds point and wave, and still loads as them.
FORMAT_VERSION = 4
#: Versions still read, as FORMAT_VERSION with the defaults it adds.
_READ_VERSIONS = (3, FORMAT_VERSION)
#: Older versions, and why this add-on cannot play them.
_RETIRED_VERSIONS = {1: "from before waves carried their rhythm in the objective",
                     2: "whose wave rhythm is a line through the training waves, not the waves themselves"}
METADATA_KEY = "__metadata__"
VARIANTS = ("rlanimate", "single_state", "single_dynamics", "supervised")
#: a_0, the previous action of a sequence's first frame (the middle of every channel's range): part
#: of the agent's definition, shared by the torch model and the numpy runtime.
INITIAL_ACTION = 0.5
#: Metadata fields every agent file has.
REQUIRED_METADATA = ("format", "format_version", "variant", "agent_config", "action_bounds", "average_frames",
                     "wave_rhythm")
#: ... and those every file of FORMAT_VERSION has besides.
REQUIRED_SINCE_4 = ("behaviours",)
_AGENT_SIZES = ("task_size", "behaviour_size", "stochastic_size", "hidden_size", "portrayal_hidden_size",
                "hidden_layers")
_AGENT_SCALARS = ("min_std", "concentration_floor", "concentration_scale")
#: An array's shape, and what an npy header holds: (shape, Fortran order, dtype).
Shape = tuple[int, ...]
NpyHeader = tuple[Shape, bool, np.dtype[Any]]
#: What sees an entry's (shape, dtype) before its data is read.
HeaderCheck = Callable[[Shape, np.dtype[Any]], None]


def uses_portrayal(variant: str) -> bool:
    """Whether the variant self-describes with a portrayal model (all but single_state)."""
    return variant != "single_state"


def uses_task_state(variant: str) -> bool:
    """Whether the variant keeps a separate task state h_t: not single_dynamics (one latent space) and
    not single_state (the objective is the agent's only state; paper Section 4.3)."""
    return variant not in ("single_state", "single_dynamics")


def mlp_shapes(name: str, inputs: int, hidden: int, layers: int, outputs: int) -> dict[str, Shape]:
    """Shapes of an MLP's arrays: `layers` hidden Linear(+tanh) layers of width `hidden`, then a Linear."""
    widths = [inputs] + [hidden] * layers + [outputs]
    shapes: dict[str, Shape] = {}
    for k, (n_in, n_out) in enumerate(zip(widths[:-1], widths[1:], strict=True)):
        shapes[f"{name}.layers.{k}.weight"] = (n_out, n_in)
        shapes[f"{name}.layers.{k}.bias"] = (n_out,)
    return shapes


def gru_shapes(name: str, inputs: int, size: int, suffix: str = "") -> dict[str, Shape]:
    """Shapes of a torch GRU / GRUCell's arrays (gates r, z, n stacked along the first axis)."""
    return {f"{name}.weight_ih{suffix}": (3 * size, inputs), f"{name}.weight_hh{suffix}": (3 * size, size),
            f"{name}.bias_ih{suffix}": (3 * size,), f"{name}.bias_hh{suffix}": (3 * size,)}


def task_width(agent_config: Mapping[str, Any], variant: str, objective_size: int) -> int:
    """How wide the task input of f2 and the heads is: the task state, with the wave's phase features beside it
    for an agent with `phase_input` (rhythm.PHASE_FEATURES) and its swing rate with `tempo_input` (1), or the
    objective itself without a task state."""
    if not uses_task_state(variant):
        return objective_size
    width: int = agent_config["task_size"] + (rhythm.PHASE_FEATURES if agent_config.get("phase_input", False) else 0)
    return width + (1 if agent_config.get("tempo_input", False) else 0)


def expected_weight_shapes(agent_config: Mapping[str, Any], variant: str, objective_size: int) -> dict[str, Shape]:
    """{array name: shape} of an agent with `agent_config` (a dict of AgentConfig fields), `variant` and
    objectives of `objective_size` (its ObjectiveSpace's size)."""
    if variant not in VARIANTS:
        raise RLAnimateError(f"Unknown agent variant {variant!r}: the file must name one of "
                             f"{', '.join(VARIANTS)}.")
    c = agent_config
    O, D, A = objective_size, spaces.DESCRIPTION_SIZE, spaces.ACTION_SIZE  # noqa: E741 (the paper's sizes)
    E, Z, hid, n = c["behaviour_size"], c["stochastic_size"], c["hidden_size"], c["hidden_layers"]
    task = task_width(c, variant, O)  # what f2 and the heads see of the task
    head_inputs = (task if uses_task_state(variant) else 0) + E + Z
    shapes: dict[str, Shape] = {}
    if uses_portrayal(variant):
        shapes.update(mlp_shapes("portrayal", O, c["portrayal_hidden_size"], n, D))
    if uses_task_state(variant):
        shapes.update(gru_shapes("task_rnn", O, c["task_size"], suffix="_l0"))
    shapes.update(gru_shapes("behaviour_cell", task + Z + A, E))
    shapes.update(mlp_shapes("prior", E, hid, n, 2 * Z))
    shapes.update(mlp_shapes("posterior", E + D, hid, n, 2 * Z))
    shapes.update(mlp_shapes("animation", head_inputs, hid, n, 2 * A))
    shapes.update(mlp_shapes("decoder", head_inputs, hid, n, D))
    return shapes


def objective_space(metadata: Mapping[str, Any]) -> spaces.ObjectiveSpace:
    """The ObjectiveSpace of a loaded file's metadata: its declared behaviours, or point and wave for a
    version 3 file (which declares none)."""
    if metadata["format_version"] == 3:
        return spaces.PAPER_SPACE
    return spaces.ObjectiveSpace(tuple(behaviours.from_dict(b) for b in metadata["behaviours"]))


def load_agent_file(path: str | os.PathLike[str]) -> tuple[dict[str, npt.NDArray[Any]], dict[str, Any]]:
    """(weights {name: float array}, metadata dict) from the agent file at `path`, fully validated.

    A version 3 file declares no behaviours: it holds point and wave (`objective_space`).

    Nothing is allocated or inflated before its declared size is checked: the metadata against
    MAX_METADATA_BYTES, each weight array's npy header against the shape the metadata implies. Every
    failure is an RLAnimateError.
    """
    path = Path(path)
    if not path.is_file():
        raise RLAnimateError(f"No agent file at {path}: choose an existing .npz agent in the add-on preferences.")
    with _open_archive(path) as archive:
        entries = _entries(path, archive)
        metadata = _parse_metadata(path, _read_metadata(path, archive, entries.pop(METADATA_KEY, None)))
        expected = _check_metadata_values(path, metadata)
        weights = _read_weights(path, archive, entries, expected)
    return weights, metadata


#: Hard caps, far above any agent the trainer writes (the paper preset's file is under 10 MB), checked
#: before anything is read or allocated.
MAX_FILE_BYTES = 256 * 2 ** 20
MAX_ENTRIES = 1024
#: A central directory of MAX_ENTRIES entries with names of up to 200 characters.
MAX_DIRECTORY_BYTES = MAX_ENTRIES * 256
#: numpy writes headers of a few hundred bytes; its own parser stops at 10,000.
MAX_NPY_HEADER_BYTES = 10_000
MAX_METADATA_BYTES = 4 * 2 ** 20
MAX_PARAMETERS = 16 * 2 ** 20
#: Any one entry: the largest array MAX_PARAMETERS allows, as float64.
MAX_ENTRY_BYTES = 8 * MAX_PARAMETERS + 2 ** 16
MAX_SIZE = 4096  # any one agent_config width
MAX_HIDDEN_LAYERS = 16
MAX_AVERAGE_FRAMES = 10_000
MAX_ABS_BOUND = 2.0 * np.pi  # radians per rotation-vector component
MAX_CONFIG_SCALAR = 1e6
#: Trained weights stay within a few units (the shipped agent's largest is 2.8); 1e300 ones saturate
#: every tanh and still bake finite keys, so they are refused.
MAX_ABS_WEIGHT = 1e4
#: Any number of the wave_rhythm model (exaggerations, frequencies, fractions, phase, ramp, bandwidth).
MAX_RHYTHM_VALUE = 1e3
#: What a hostile archive can raise from zipfile, its decompressors and numpy's npy header parser (ast, tokenize,
#: dtype) before a check of ours sees it: `_unreadable` turns each into an RLAnimateError.
_UNREADABLE = (OSError, EOFError, ValueError, TypeError, KeyError, IndexError, OverflowError, MemoryError,
               RecursionError, SyntaxError, NotImplementedError, RuntimeError, zipfile.BadZipFile, zlib.error,
               _LZMAError, struct.error, tokenize.TokenError)
_NPY = ".npy"
_NPY_MAGIC = b"\x93NUMPY"
#: Zip compression methods an agent may use: numpy.savez stores, numpy.savez_compressed deflates.
_METHODS = (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED)
_METHOD_NAMES = {zipfile.ZIP_BZIP2: "bzip2", zipfile.ZIP_LZMA: "LZMA", 93: "Zstandard", 95: "xz", 98: "PPMd",
                 99: "AES encryption"}
#: The zip end record (22 bytes and a comment of up to 65,535) and the zip64 locator that may precede it.
_END_SIGNATURE, _END_BYTES = b"PK\x05\x06", 22
_END_SEARCH_BYTES = _END_BYTES + 2 ** 16
_ZIP64_LOCATOR_SIGNATURE, _ZIP64_LOCATOR_BYTES = b"PK\x06\x07", 20


@contextlib.contextmanager
def _unreadable(path: Path) -> Iterator[None]:
    """Around code that parses the file's bytes: what the parsers raise becomes 'truncated or damaged'."""
    try:
        yield
    except _UNREADABLE as error:
        raise _damaged(path, error) from error


def _open_archive(path: Path) -> zipfile.ZipFile:
    with _unreadable(path):
        size = path.stat().st_size
        with open(path, "rb") as handle:
            magic = handle.read(2)
            handle.seek(max(0, size - _END_SEARCH_BYTES))
            tail = handle.read(_END_SEARCH_BYTES)
    if size > MAX_FILE_BYTES:
        raise RLAnimateError(f"The agent file {path} is {size / 2 ** 20:.0f} MB, more than any agent "
                             f"({MAX_FILE_BYTES // 2 ** 20} MB at most): choose a .npz written by "
                             f"trainer/agent/agent_export.py.")
    if not magic:
        raise _damaged(path, "the file is empty")
    if magic != b"PK":  # a bare .npy, a pickle, text: numpy would have to unpickle some of them
        raise RLAnimateError(f"{path} is not an RLAnimate agent file (not a numpy .npz archive; pickled data is "
                             f"refused): choose a .npz written by trainer/agent/agent_export.py.")
    _check_end_record(path, tail)
    with _unreadable(path):
        return zipfile.ZipFile(path)


def _check_end_record(path: Path, tail: bytes) -> None:
    """The zip's end record, found as zipfile finds it in the file's last bytes `tail`, bounds what zipfile
    will parse: the entry count and the central directory's size, before zipfile reads the directory."""
    if tail[-_END_BYTES:-_END_BYTES + 4] == _END_SIGNATURE and tail[-2:] == b"\0\0":
        at = len(tail) - _END_BYTES  # no archive comment, the usual case
    else:
        at = tail.rfind(_END_SIGNATURE)
    if at < 0 or len(tail) - at < _END_BYTES:
        raise _damaged(path, "no zip end record")
    if tail[max(0, at - _ZIP64_LOCATOR_BYTES):at].startswith(_ZIP64_LOCATOR_SIGNATURE):
        raise RLAnimateError(f"The agent file {path} is a zip64 archive, made for more entries or bytes than any "
                             f"agent has: choose a .npz written by trainer/agent/agent_export.py.")
    disk_entries, entries, directory_bytes = struct.unpack_from("<2HI", tail, at + 8)
    if max(disk_entries, entries) > MAX_ENTRIES or directory_bytes > MAX_DIRECTORY_BYTES:
        raise RLAnimateError(f"The agent file {path} declares {max(disk_entries, entries):,} entries in a "
                             f"{directory_bytes:,}-byte directory, more than any agent ({MAX_ENTRIES:,} entries "
                             f"in {MAX_DIRECTORY_BYTES:,} bytes at most): choose a .npz written by "
                             f"trainer/agent/agent_export.py.")


def _entries(path: Path, archive: zipfile.ZipFile) -> dict[str, zipfile.ZipInfo]:
    """{array name: ZipInfo} of the archive, its size, names and compression methods checked."""
    infos = archive.infolist()
    if len(infos) > MAX_ENTRIES:
        raise _not_an_agent(path)
    entries: dict[str, zipfile.ZipInfo] = {}
    for info in infos:
        if not info.filename.endswith(_NPY) or info.filename[:-len(_NPY)] in entries:
            raise _damaged(path, f"entry {info.filename!r} is not one numpy array")
        if info.compress_type not in _METHODS:
            raise RLAnimateError(f"The agent file {path} compresses {info.filename!r} with zip method "
                                 f"{info.compress_type} ({_METHOD_NAMES.get(info.compress_type, 'unknown')}); "
                                 f"agents are stored or deflated, as numpy.savez writes them: re-export it with "
                                 f"trainer/agent/agent_export.py, or re-zip it without that compression.")
        if info.file_size > MAX_ENTRY_BYTES:
            raise _damaged(path, f"entry {info.filename!r} declares {info.file_size:,} bytes, more than any "
                                 f"agent's {MAX_ENTRY_BYTES:,}")
        entries[info.filename[:-len(_NPY)]] = info
    return entries


def _npy_header(stream: IO[bytes], name: str) -> NpyHeader:
    """(shape, fortran_order, dtype) from the npy header at the start of `stream`, by numpy's own parser
    once the header's length field is checked: numpy would read as many bytes as the field claims."""
    magic = stream.read(len(_NPY_MAGIC) + 2)
    if len(magic) < len(_NPY_MAGIC) + 2 or not magic.startswith(_NPY_MAGIC):
        raise ValueError(f"{name} is not a numpy array")
    version = tuple(magic[-2:])
    readers: dict[tuple[int, ...], Callable[[IO[bytes]], NpyHeader]] = {
        (1, 0): np.lib.format.read_array_header_1_0, (2, 0): np.lib.format.read_array_header_2_0}
    read = readers.get(version)
    if read is None:
        raise ValueError(f"{name} is npy format version {version}")
    length_field = stream.read(2 if version == (1, 0) else 4)
    length = int.from_bytes(length_field, "little")
    if length > MAX_NPY_HEADER_BYTES:
        raise ValueError(f"the npy header of {name} claims {length:,} bytes, more than "
                         f"{MAX_NPY_HEADER_BYTES:,}")
    header = io.BytesIO(length_field + stream.read(length))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # numpy's note on headers written by Python 2
        parsed: NpyHeader = read(header)
        return parsed


def _read_npy(path: Path, archive: zipfile.ZipFile, info: zipfile.ZipInfo, name: str,
              check: HeaderCheck) -> npt.NDArray[Any]:
    """The array in the archive entry `info`; `check(shape, dtype)` sees the header before any data is read."""
    with _unreadable(path), archive.open(info) as stream:
        shape, fortran_order, dtype = _npy_header(stream, name)
        if dtype.hasobject:
            raise _pickled(path, name)
        if any(n < 0 for n in shape):
            raise _damaged(path, f"{name} has the shape {shape}")
        check(shape, dtype)
        size = math.prod(shape) * dtype.itemsize
        if stream.tell() + size != info.file_size:
            raise _damaged(path, f"{name} declares {size} bytes of data in an entry of {info.file_size}")
        data = stream.read(size)  # the zip CRC is checked as the entry's last byte is read
        if len(data) != size:
            raise _damaged(path, f"{name} ends early")
        return np.frombuffer(bytearray(data), dtype=dtype).reshape(shape, order="F" if fortran_order else "C")


def _damaged(path: Path, error: object) -> RLAnimateError:
    return RLAnimateError(f"The agent file {path} is truncated or damaged ({error}): export or copy it again.")


def _pickled(path: Path, name: str) -> RLAnimateError:
    return RLAnimateError(f"The agent file {path} carries a pickled Python object in {name}, which is refused "
                          f"because loading it could run code: use an agent exported by trainer/agent/agent_export.py.")


def _not_an_agent(path: Path) -> RLAnimateError:
    return RLAnimateError(f"{path} is not an RLAnimate agent file (no {METADATA_KEY} entry): choose a .npz "
                          f"written by trainer/agent/agent_export.py.")


def _read_metadata(path: Path, archive: zipfile.ZipFile, info: zipfile.ZipInfo | None) -> npt.NDArray[Any]:
    if info is None:
        raise _not_an_agent(path)

    def check(shape: Shape, dtype: np.dtype[Any]) -> None:
        if dtype.kind != "U" or shape != ():
            raise _not_an_agent(path)
        if not 0 < dtype.itemsize <= MAX_METADATA_BYTES:  # numpy's itemsize wraps negative past 2 GB
            raise RLAnimateError(f"The agent file {path} declares more metadata than any agent has "
                                 f"({MAX_METADATA_BYTES // 2 ** 20} MB at most): re-export it.")

    return _read_npy(path, archive, info, METADATA_KEY, check)


def _parse_metadata(path: Path, entry: npt.NDArray[Any]) -> dict[str, Any]:
    try:
        metadata = json.loads(str(entry))
    except (ValueError, RecursionError) as error:
        raise _damaged(path, error) from error
    if not isinstance(metadata, dict) or metadata.get("format") != FORMAT_NAME:
        raise _not_an_agent(path)
    version = metadata.get("format_version")
    if _is_int(version) and version in _RETIRED_VERSIONS:
        raise RLAnimateError(f"The agent file {path} is format version {version}, {_RETIRED_VERSIONS[version]}; "
                             f"this add-on reads version {FORMAT_VERSION}: retrain the agent with this version's "
                             f"trainer (python trainer/train.py).")
    if not _is_int(version) or version not in _READ_VERSIONS:
        raise RLAnimateError(f"The agent file {path} is format version {version!r}, but "
                             f"this add-on reads version {FORMAT_VERSION}: update the add-on, or re-export "
                             f"the agent with this version's trainer.")
    missing = [key for key in REQUIRED_METADATA + (REQUIRED_SINCE_4 if version >= 4 else ()) if key not in metadata]
    if missing:
        raise RLAnimateError(f"The agent file {path} lacks metadata {', '.join(missing)}: re-export it with "
                             f"trainer/agent/agent_export.py.")
    checked: dict[str, Any] = metadata
    return checked


def _is_int(value: object) -> TypeGuard[int]:
    return isinstance(value, int) and not isinstance(value, bool)


def _is_number(value: object) -> bool:
    """An int (of any size: the range checks that follow compare it exactly) or a finite float."""
    return _is_int(value) or isinstance(value, float) and math.isfinite(value)


def _count(n: int, noun: str) -> str:
    return f"{n:,} {noun}{'s' if n > 1 else ''}"


def _largest_number(value: object) -> float:
    """The largest magnitude among the numbers anywhere in the JSON value (NaN if one is NaN, 0 if none)."""
    largest, pending = 0.0, [value]
    while pending:
        item = pending.pop()
        if isinstance(item, dict):
            pending.extend(item.values())
        elif isinstance(item, list):
            pending.extend(item)
        elif _is_int(item) or isinstance(item, float):
            if item != item:
                return math.nan
            largest = max(largest, abs(item))
    return largest


def _describe(number: float) -> str:
    """A number as a message names it: NaN, infinite, or its value (integers of any size in short)."""
    if isinstance(number, float) and math.isnan(number):
        return "NaN"
    if number == math.inf:
        return "infinite"
    return f"{number:.3g}" if isinstance(number, float) or abs(number) < 10 ** 15 else f"about 1e{len(str(number)) - 1}"


def _check_agent_config(path: Path, config: Any, variant: Any) -> None:
    """RLAnimateError for an agent_config whose sizes, scalars or input flags the add-on cannot run."""
    if not isinstance(config, dict) \
            or any(not _is_int(config.get(k)) or not 0 < config[k] <= MAX_SIZE for k in _AGENT_SIZES) \
            or config["hidden_layers"] > MAX_HIDDEN_LAYERS \
            or any(not _is_number(config.get(k)) or not 0 < config[k] <= MAX_CONFIG_SCALAR for k in _AGENT_SCALARS):
        raise RLAnimateError(f"The agent file {path} has an invalid agent_config (widths 1-{MAX_SIZE}, "
                             f"hidden_layers 1-{MAX_HIDDEN_LAYERS}, {', '.join(_AGENT_SCALARS)} positive and "
                             f"at most {MAX_CONFIG_SCALAR:g}): re-export it with trainer/agent/agent_export.py.")
    if not all(isinstance(config.get(flag, False), bool) for flag in ("phase_input", "tempo_input")):
        raise RLAnimateError(f"The agent file {path} has an invalid agent_config phase_input or tempo_input (true or "
                             f"false): re-export it with trainer/agent/agent_export.py.")
    if config.get("tempo_input", False) and not config.get("phase_input", False):
        raise RLAnimateError(f"The agent file {path} gives tempo_input without phase_input, beside which the tempo "
                             f"sits: re-export it with trainer/agent/agent_export.py.")
    if config.get("phase_input", False) and not uses_task_state(variant):
        raise RLAnimateError(f"The agent file {path} gives phase_input to a {variant} agent, which has "
                             f"no task state to give it beside: re-export it with trainer/agent/agent_export.py.")


def _check_metadata_values(path: Path, metadata: dict[str, Any]) -> dict[str, Shape]:
    """Every metadata value the add-on uses, checked for type and range; returns the expected weight shapes."""
    config = metadata["agent_config"]
    _check_agent_config(path, config, metadata["variant"])
    if not isinstance(metadata["variant"], str):
        raise RLAnimateError(f"The agent file {path} names no agent variant: it must name one of "
                             f"{', '.join(VARIANTS)}.")
    if metadata["variant"] not in VARIANTS:
        raise RLAnimateError(f"The agent file {path} names an unknown agent variant {metadata['variant']!r:.40}: "
                             f"it must name one of {', '.join(VARIANTS)}; re-export it with "
                             "trainer/agent/agent_export.py.")
    space = _checked_space(path, metadata)
    expected = expected_weight_shapes(config, metadata["variant"], space.size)
    parameters = sum(math.prod(shape) for shape in expected.values())
    if parameters > MAX_PARAMETERS:
        raise RLAnimateError(f"The agent file {path} describes an agent of {parameters:,} parameters, more than "
                             f"the add-on runs ({MAX_PARAMETERS:,}): train a smaller agent.")
    bounds = metadata["action_bounds"]
    if not isinstance(bounds, list) or len(bounds) != spaces.ACTION_SIZE or any(
            not isinstance(pair, list) or len(pair) != 2 or not all(_is_number(b) for b in pair)
            or not -MAX_ABS_BOUND <= pair[0] < pair[1] <= MAX_ABS_BOUND for pair in bounds):
        raise RLAnimateError(f"The agent file {path} has invalid action_bounds (need {spaces.ACTION_SIZE} "
                             f"[low, high] pairs of numbers with low < high, within +-2 pi radians): "
                             f"re-export it with trainer/agent/agent_export.py.")
    frames = metadata["average_frames"]
    if not isinstance(frames, dict) or not frames or any(
            b not in space.names or not _is_number(n) or not 2 <= n <= MAX_AVERAGE_FRAMES
            for b, n in frames.items()):
        raise RLAnimateError(f"The agent file {path} has invalid average_frames (need a length of 2 to "
                             f"{MAX_AVERAGE_FRAMES:,} frames for each behaviour it was trained for, among "
                             f"{', '.join(space.names)}): re-export it.")
    if metadata["wave_rhythm"] is not None:
        largest = _largest_number(metadata["wave_rhythm"])
        if not largest <= MAX_RHYTHM_VALUE:
            raise RLAnimateError(f"The agent file {path} has a wave_rhythm value of {_describe(largest)}, beyond "
                                 f"+-{MAX_RHYTHM_VALUE:g} (exaggerations, wave frequencies and fractions of a "
                                 f"gesture are small numbers): re-export it with trainer/agent/agent_export.py.")
        problem = rhythm.invalid_field(metadata["wave_rhythm"])
        if problem:
            raise RLAnimateError(f"The agent file {path} has an invalid wave_rhythm ({problem}): re-export it with "
                                 f"trainer/agent/agent_export.py.")
    still = metadata.get("still_free_arm", [])
    if not isinstance(still, list) or any(not isinstance(b, str) or b not in space.names for b in still):
        raise RLAnimateError(f"The agent file {path} has an invalid still_free_arm (need a list of the behaviours, "
                             f"among {', '.join(space.names)}, whose free arm the gesture holds still): re-export it.")
    return {name: tuple(shape) for name, shape in expected.items()}


def _checked_space(path: Path, metadata: dict[str, Any]) -> spaces.ObjectiveSpace:
    """The ObjectiveSpace of the metadata: point and wave in version 3, else its `behaviours`, a list of
    {"name", "kind"}, 1 to MAX_BEHAVIOURS of them, in objective order (behaviours.ordered), each name once."""
    if metadata["format_version"] == 3:
        return spaces.PAPER_SPACE
    declared, problem = metadata["behaviours"], None
    if not isinstance(declared, list) or not 0 < len(declared) <= behaviours.MAX_BEHAVIOURS or any(
            not isinstance(b, dict) or not {"name", "kind"} <= set(b) <= {"name", "kind", "does"}
            or not all(isinstance(v, str) for v in b.values())
            for b in declared):
        problem = (f"need a list of 1 to {behaviours.MAX_BEHAVIOURS} behaviours, each "
                   f'{{"name": ..., "kind": "{behaviours.TARGET}" or "{behaviours.INTENSITY}"}} and, optionally, '
                   f'"does" ({", ".join(behaviours.ACTIONS)})')
    else:
        try:
            space = spaces.ObjectiveSpace(tuple(behaviours.from_dict(b) for b in declared))
        except RLAnimateError as error:
            problem = str(error)
        else:
            if space.behaviours != behaviours.ordered(space.behaviours):
                problem = "they are not in objective order (point, wave, then the others by name)"
    if problem:
        raise RLAnimateError(f"The agent file {path} declares invalid behaviours ({problem}): re-export it with "
                             f"trainer/agent/agent_export.py.")
    return space


def _read_weights(path: Path, archive: zipfile.ZipFile, entries: dict[str, zipfile.ZipInfo],
                  expected: dict[str, Shape]) -> dict[str, npt.NDArray[Any]]:
    """{name: float array} of the weight entries, checked against the expected shapes before any is read."""
    missing = sorted(set(expected) - set(entries))
    extra = sorted(set(entries) - set(expected))
    headers: dict[str, NpyHeader] = {}
    for name, info in entries.items():
        with _unreadable(path), archive.open(info) as stream:
            headers[name] = _npy_header(stream, name)
        if headers[name][2].hasobject:
            raise _pickled(path, name)
    wrong = [f"{name} {headers[name][0]} (expected {expected[name]})"
             for name in sorted(set(expected) & set(entries)) if headers[name][0] != expected[name]]
    if missing or extra or wrong:
        problems = ([f"missing {', '.join(missing)}"] if missing else []) + \
                   ([f"unexpected {', '.join(extra)}"] if extra else []) + \
                   ([f"wrong shape {'; '.join(wrong)}"] if wrong else [])
        raise RLAnimateError(f"The agent file {path} does not match its own config: {'; '.join(problems)}. "
                             f"Re-export the agent with trainer/agent/agent_export.py.")

    def check(name: str) -> HeaderCheck:
        def floats(shape: Shape, dtype: np.dtype[Any]) -> None:
            if shape != expected[name]:
                raise _damaged(path, f"{name} changed its shape")
            if dtype.kind != "f":
                raise RLAnimateError(f"The agent file {path} holds {name} as {dtype}, not floats: re-export it.")
        return floats

    weights: dict[str, npt.NDArray[Any]] = {}
    for name in sorted(expected):
        weights[name] = _read_npy(path, archive, entries[name], name, check(name))
        _check_weight_values(path, name, weights[name])
    return weights


def _check_weight_values(path: Path, name: str, array: npt.NDArray[Any]) -> None:
    """RLAnimateError naming what is wrong with the weight array `name`: NaN, infinite or huge values."""
    nan, infinite = int(np.isnan(array).sum()), int(np.isinf(array).sum())
    finite = array[np.isfinite(array)]
    largest = float(np.abs(finite).max()) if finite.size else 0.0
    if nan or infinite or largest > MAX_ABS_WEIGHT:
        found = ", ".join(([_count(nan, "NaN value")] if nan else []) +
                          ([_count(infinite, "infinite value")] if infinite else []) +
                          ([f"values as large as {largest:.3g}"] if largest > MAX_ABS_WEIGHT else []))
        raise RLAnimateError(f"The agent file {path} has {found} in {name} (a trained agent's weights are finite "
                             f"and within +-{MAX_ABS_WEIGHT:g}): its training diverged or the file was altered; "
                             f"train it again (a lower learning rate or gradient clip helps).")
