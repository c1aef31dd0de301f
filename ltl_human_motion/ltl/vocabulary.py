"""The task vocabulary of Table I and the cell names a specification may use.

A cell is anything with the attributes of :class:`CellVocabulary` (the scene module's
``Cell`` is one), a plain ``dict`` with the same keys, or a YAML file read by
:func:`load_vocabulary`. Only names are used here; the geometry stays in ``scene/``,
which this layer does not import.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

from ltl_human_motion.errors import CellError
from ltl_human_motion.vocabulary import INPUT_ARGUMENTS, TASK_ARGUMENTS

__all__ = [
    "TASK_SIGNATURES", "CellVocabulary", "Vocabulary", "load_vocabulary", "vocabulary_from",
]

#: Deprecated name of :data:`ltl_human_motion.vocabulary.TASK_ARGUMENTS` (the same dict).
TASK_SIGNATURES = TASK_ARGUMENTS


@runtime_checkable
class CellVocabulary(Protocol):
    """What the LTL layer needs from a cell: names only."""

    objects: Mapping[str, Any]
    regions: Mapping[str, Any]
    shorthands: Mapping[str, tuple[tuple[str, ...], str]]
    final_region: Any  # a region name, or an object with ``.name``, or None


@dataclass(frozen=True)
class Vocabulary:
    """Names a specification may use.

    ``objects``/``regions`` of None mean "not checked" (no cell given).
    ``shorthands`` maps a name to ``(params, body_text)``. ``inputs`` maps the cell's own
    Boolean input propositions to their ``std_msgs/Bool`` topics (the built-in inputs
    of :data:`~ltl_human_motion.vocabulary.INPUT_ARGUMENTS` need no declaration).
    """

    objects: frozenset[str] | None = None
    regions: frozenset[str] | None = None
    shorthands: Mapping[str, tuple[tuple[str, ...], str]] = field(default_factory=dict)
    final_region: str | None = None
    source: str = "<cell>"
    inputs: Mapping[str, str] = field(default_factory=dict)


def _names(value: Any, key: str, source: str) -> frozenset[str] | None:
    if value is None:
        return None
    if isinstance(value, Mapping):
        return frozenset(str(k) for k in value)
    if isinstance(value, (list, tuple, set, frozenset)):
        out = []
        for item in value:
            if isinstance(item, Mapping) and "name" in item:
                out.append(str(item["name"]))
            elif isinstance(item, str):
                out.append(item)
            else:
                raise CellError(f"{source}: '{key}' must list names, got {item!r}")
        return frozenset(out)
    raise CellError(f"{source}: '{key}' must be a mapping or a list of names, "
                    f"got {type(value).__name__}")


def _shorthands(value: Any, source: str) -> dict[str, tuple[tuple[str, ...], str]]:
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise CellError(f"{source}: 'shorthands' must be a mapping name -> definition")
    out: dict[str, tuple[tuple[str, ...], str]] = {}
    for name, spec in value.items():
        if isinstance(spec, (tuple, list)) and len(spec) == 2 and isinstance(spec[1], str):
            params, body = tuple(str(p) for p in spec[0]), spec[1]
        elif isinstance(spec, Mapping) and "body" in spec:
            params, body = tuple(str(p) for p in spec.get("params", ())), str(spec["body"])
        elif isinstance(spec, str):
            params, body = (), spec
        else:
            raise CellError(f"{source}: shorthand '{name}' must be (params, body) or "
                            f"{{params: [...], body: '...'}}, got {spec!r}")
        name = str(name)
        if "(" in name:  # "assemble(R)" as the key
            head, _, rest = name.partition("(")
            params = tuple(p.strip() for p in rest.rstrip(")").split(",") if p.strip())
            name = head.strip()
        out[name] = (params, body)
    return out


def _inputs(value: Any, source: str, shorthands: Mapping[str, Any]) -> dict[str, str]:
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise CellError(f"{source}: 'inputs' must be a mapping name -> std_msgs/Bool topic, "
                        f"e.g. {{door_open: /cell/door_open}}")
    out: dict[str, str] = {}
    for name, topic in value.items():
        name = str(name)
        if name in TASK_ARGUMENTS or name in INPUT_ARGUMENTS or name in shorthands:
            raise CellError(f"{source}: input '{name}' is already a task, a built-in input "
                            "or a shorthand; choose another name")
        if not isinstance(topic, str) or not topic.startswith("/"):
            raise CellError(f"{source}: input '{name}' needs an absolute topic name such as "
                            f"/cell/{name}, got {topic!r}")
        out[name] = topic
    return out


def vocabulary_from(cell: Any) -> Vocabulary:
    """A :class:`Vocabulary` from a cell object, a dict, a YAML path, or None.

    Raises
    ------
    CellError
        If the cell lacks the names or they have the wrong type.
    """
    if cell is None:
        return Vocabulary()
    if isinstance(cell, Vocabulary):
        return cell
    if isinstance(cell, (str, Path)):
        return load_vocabulary(cell)
    if isinstance(cell, Mapping):
        source = str(cell.get("source", "<cell>"))
        get = cell.get
    else:
        source = str(getattr(cell, "source", "<cell>"))

        def get(key: str, default: Any = None) -> Any:
            return getattr(cell, key, default)
    objects = _names(get("objects"), "objects", source) or frozenset()
    regions = _names(get("regions"), "regions", source) or frozenset()
    final = get("final_region")
    if final is not None and not isinstance(final, str):
        final = getattr(final, "name", final)  # the scene's Region object
    if final is not None and str(final) not in regions:
        raise CellError(f"{source}: final_region '{final}' is not one of the regions "
                        f"{sorted(regions)}")
    shorthands = _shorthands(get("shorthands"), source)
    return Vocabulary(objects=objects, regions=regions, shorthands=shorthands,
                      final_region=None if final is None else str(final), source=source,
                      inputs=_inputs(get("inputs"), source, shorthands))


def load_vocabulary(path: str | Path) -> Vocabulary:
    """Read the names of a cell YAML file: the keys ``objects``, ``regions``,
    ``shorthands``, ``inputs`` and ``final_region`` (the geometry is the scene module's to read).

    Raises
    ------
    CellError
        If the file is missing, too large or deep for
        :func:`~ltl_human_motion.yaml_limits.load_yaml_limited`, or malformed.
    """
    from ltl_human_motion.yaml_limits import (
        TextFileError,
        YamlLimitError,
        load_yaml_limited,
        read_text_file,
    )

    path = Path(path)
    if not path.exists():
        raise CellError(f"cell file not found: {path}")
    try:
        text = read_text_file(path, "cell file")
    except TextFileError as exc:
        raise CellError(str(exc)) from None
    try:
        data = load_yaml_limited(text)
    except YamlLimitError as exc:
        raise CellError(f"{path}: cannot read cell description: {exc}") from None
    if not isinstance(data, Mapping):
        raise CellError(f"{path}: a cell description must be a YAML mapping")
    data = dict(data)
    data["source"] = str(path)
    return vocabulary_from(data)
