"""What a settings field takes on the command line beyond its type (trainer/scripts/cli.py makes each script's
command line from its settings dataclass with tyro)."""
import dataclasses
from collections.abc import Iterable
from typing import Any, Literal

import tyro

from rlanimate_addon.core.errors import RLAnimateError


def some_of(names: Iterable[str]) -> Any:
    """An `Annotated[tuple[str, ...], some_of(NAMES)]` marker: the field takes any of `names` on the command line,
    which --help lists and which refuses any other name."""
    literal: Any = Literal  # made at run time: Literal["a", "b"] from the names
    names_tuple: Any = tuple
    field_type = names_tuple[literal[tuple(names)], ...]  # tuple[Literal["a", "b"], ...]
    return tyro.conf.arg(constructor_factory=lambda: field_type)


def one_of(names: Iterable[str]) -> Any:
    """An `Annotated[str | None, one_of(NAMES)]` marker: the field takes one of `names` on the command line, which
    --help lists and which refuses any other name; None (its default) when not given."""
    literal: Any = Literal  # made at run time: Literal["a", "b"] from the names
    field_type = literal[tuple(names)] | None
    return tyro.conf.arg(constructor_factory=lambda: field_type, help_behavior_hint="(default: None)")


def require_values(settings: Any, *names: str) -> None:
    """RLAnimateError naming each tuple field of `names` that `settings` (a settings dataclass) holds empty, as the
    option it is on the command line, with its default as an example."""
    defaults: dict[str, Any] = {field.name: field.default for field in dataclasses.fields(settings)}
    empty = [f"--{name.replace('_', '-')} given no value: give one or more, such as "
             f"{' '.join(map(str, defaults[name]))}" for name in names if not getattr(settings, name)]
    if empty:
        raise RLAnimateError("; ".join(empty) + ".")
