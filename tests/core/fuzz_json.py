"""Changing one value of a JSON document, as the agent-file and VRM fuzzes do (tests/core/agent_fuzz.py,
tests/core/vrm_fuzz.py)."""


def set_or_remove(document, path, rng, values):
    """The document with the value at `path` (keys and indices) replaced by one of `values`, or, one time in
    seven, removed (an absent key stays absent); the path () replaces the whole document."""
    if not path:
        return values[int(rng.integers(len(values)))]
    parent = document
    for key in path[:-1]:
        parent = parent[key]
    if rng.random() < 0.15:
        parent.pop(path[-1]) if isinstance(parent, list) else parent.pop(path[-1], None)
    else:
        parent[path[-1]] = values[int(rng.integers(len(values)))]
    return document
