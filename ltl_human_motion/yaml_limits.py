"""YAML read with named limits: size, nesting, alias expansion; values shown shortened.

PyYAML's ``safe_load`` shares aliased nodes, so a "billion laughs" document of 2 KB loads
quickly, but any code that walks or prints the value expands it (issue 17: 10^10 leaves
in ``description`` and an error message that printed it until MemoryError). Deep
nesting makes PyYAML raise RecursionError. :func:`load_yaml_limited` composes the node
graph first, refuses it beyond the limits below, then constructs the value.
"""

from __future__ import annotations

from typing import Any

__all__ = ["MAX_YAML_CHARS", "MAX_YAML_DEPTH", "MAX_YAML_EXPANDED_NODES", "YamlLimitError",
           "load_yaml_limited", "short_repr"]

#: Characters of one YAML document (a detailed cell is ~100 kB; 10,000 tiny obstacles
#: were 1.4 MB).
MAX_YAML_CHARS = 5_000_000
#: Nesting depth of mappings and sequences (a cell nests 4-5 deep).
MAX_YAML_DEPTH = 64
#: Nodes of the document with every alias expanded (a cell has a few thousand).
MAX_YAML_EXPANDED_NODES = 1_000_000
#: Characters of a value shown in an error message.
SHORT_REPR_CHARS = 80


class YamlLimitError(ValueError):
    """A YAML document beyond a named limit (or not YAML); the message says which."""


def short_repr(value: Any, limit: int = SHORT_REPR_CHARS) -> str:
    """``repr(value)`` cut to ``limit`` characters, without expanding big containers."""
    if isinstance(value, dict | list | tuple | set) and len(value) > limit:
        return f"<{type(value).__name__} of {len(value)} items>"
    try:
        text = reprlib_repr(value)
    except RecursionError:
        return f"<deeply nested {type(value).__name__}>"
    return text if len(text) <= limit else text[:limit - 3] + "..."


def reprlib_repr(value: Any) -> str:
    """A bounded repr (reprlib: at most a few items per level, a few levels)."""
    import reprlib

    r = reprlib.Repr()
    r.maxstring = r.maxother = SHORT_REPR_CHARS
    r.maxlevel = 3
    return r.repr(value)


def _expanded_size(root: Any) -> int:
    """Nodes of the graph under ``root`` with aliases expanded (memoized, no recursion);
    raises YamlLimitError when deeper than MAX_YAML_DEPTH or larger than the limit."""
    import yaml

    sizes: dict[int, int] = {}
    stack: list[tuple[Any, int, bool]] = [(root, 1, False)]
    while stack:
        node, depth, done = stack.pop()
        if id(node) in sizes:
            continue
        if depth > MAX_YAML_DEPTH:
            raise YamlLimitError(f"nests deeper than {MAX_YAML_DEPTH} levels "
                                 "(MAX_YAML_DEPTH)")
        if isinstance(node, yaml.SequenceNode):
            children = list(node.value)
        elif isinstance(node, yaml.MappingNode):
            children = [n for pair in node.value for n in pair]
        else:
            sizes[id(node)] = 1
            continue
        if done:
            total = 1 + sum(sizes[id(c)] for c in children)
            if total > MAX_YAML_EXPANDED_NODES:
                raise YamlLimitError(f"expands to more than {MAX_YAML_EXPANDED_NODES:,} "
                                     "nodes through aliases (MAX_YAML_EXPANDED_NODES)")
            sizes[id(node)] = total
        else:
            stack.append((node, depth, True))
            stack.extend((c, depth + 1, False) for c in children if id(c) not in sizes)
    return sizes[id(root)]


def _check_depth_cheaply(text: str) -> None:
    """Refuse flow nesting (``[``/``{``) or block indentation beyond MAX_YAML_DEPTH, by
    a scan of the characters (brackets inside quoted strings count too: conservative)."""
    import re

    import numpy as np

    brackets = re.sub(r"[^\[\]{}]", "", text).encode("ascii")
    if brackets:
        steps = np.frombuffer(brackets, dtype=np.uint8)
        depth = np.cumsum(np.where((steps == ord("[")) | (steps == ord("{")), 1, -1))
        if depth.max() > MAX_YAML_DEPTH:
            raise YamlLimitError(f"nests deeper than {MAX_YAML_DEPTH} levels "
                                 "(MAX_YAML_DEPTH)")
    indents = re.findall(r"^[ -]*", text, flags=re.MULTILINE)
    if indents and max(map(len, indents)) > _MAX_INDENT:
        raise YamlLimitError(f"indents deeper than {_MAX_INDENT} columns; nesting is "
                             f"limited to {MAX_YAML_DEPTH} levels (MAX_YAML_DEPTH)")


#: Block-style nesting shows as indentation (2-8 columns per level).
_MAX_INDENT = 8 * MAX_YAML_DEPTH


def load_yaml_limited(text: str) -> Any:
    """``yaml.safe_load(text)`` within the named limits (YamlLimitError otherwise, and
    for malformed YAML)."""
    import yaml

    if len(text) > MAX_YAML_CHARS:
        raise YamlLimitError(f"has {len(text):,} characters; at most {MAX_YAML_CHARS:,} "
                             "are allowed (MAX_YAML_CHARS)")
    _check_depth_cheaply(text)
    # libyaml when built with it (10x faster on big cells); it recurses in C, so the
    # depth is bounded by the scan above before it sees the text.
    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    try:
        node = yaml.compose(text, Loader=loader)
    except RecursionError:
        raise YamlLimitError(f"nests deeper than {MAX_YAML_DEPTH} levels "
                             "(MAX_YAML_DEPTH)") from None
    except yaml.YAMLError as exc:
        raise YamlLimitError(f"invalid YAML: {exc}") from None
    if node is None:
        return None
    _expanded_size(node)
    constructor = loader("")                      # builds the value from the checked graph
    try:
        return constructor.construct_document(node)
    except yaml.YAMLError as exc:
        raise YamlLimitError(f"invalid YAML: {exc}") from None
    finally:
        constructor.dispose()
