"""YAML read with named limits: size, nesting, alias expansion; values shown shortened.

PyYAML's ``safe_load`` shares aliased nodes, so a "billion laughs" document of 2 KB loads
quickly, but any code that walks or prints the value expands it (issue 17: 10^10 leaves
in ``description`` and an error message that printed it until MemoryError). Deep
nesting makes PyYAML raise RecursionError. :func:`load_yaml_limited` composes the node
graph first, refuses it beyond the limits below, then constructs the value.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path
from typing import Any

__all__ = ["MAX_YAML_BYTES", "MAX_YAML_CHARS", "MAX_YAML_DEPTH", "MAX_YAML_EXPANDED_NODES",
           "TextFileError", "YamlLimitError", "load_yaml_limited", "read_text_file", "short_repr"]

#: Characters of one YAML document (a detailed cell is ~100 kB; 10,000 tiny obstacles
#: were 1.4 MB).
MAX_YAML_CHARS = 5_000_000
#: Bytes read from a YAML file: MAX_YAML_CHARS characters of up to 4 UTF-8 bytes each.
MAX_YAML_BYTES = 4 * MAX_YAML_CHARS
#: Nesting depth of mappings and sequences (a cell nests 4-5 deep).
MAX_YAML_DEPTH = 64
#: Nodes of the document with every alias expanded (a cell has a few thousand).
MAX_YAML_EXPANDED_NODES = 1_000_000
#: Characters of a value shown in an error message.
SHORT_REPR_CHARS = 80


class YamlLimitError(ValueError):
    """A YAML document beyond a named limit (or not YAML); the message says which."""


class TextFileError(ValueError):
    """A text file that cannot be read: missing, not a regular file, too big or not UTF-8;
    the message names the file and the cause."""


_FILE_KINDS = ((stat.S_ISFIFO, "a FIFO"), (stat.S_ISCHR, "a character device"),
               (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"),
               (stat.S_ISDIR, "a folder"))


def read_text_file(path: str | os.PathLike[str], what: str,
                   max_bytes: int = MAX_YAML_BYTES) -> str:
    """The UTF-8 text of the regular file ``path`` (symlinks followed), at most ``max_bytes``.

    A FIFO, device, socket or folder is refused without reading (issue 34: a FIFO blocked
    forever, ``/dev/zero`` was read until memory ran out). The open does not block on a
    FIFO with no writer. ``what`` names the file in messages, e.g. ``"cell file"``.

    Raises
    ------
    TextFileError
        e.g. "cell file c.yaml is not a regular file (a FIFO)".
    """
    path = Path(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        raise TextFileError(f"{path}: cannot read {what}: {exc.strerror or exc}") from None
    mode = os.fstat(fd).st_mode
    if not stat.S_ISREG(mode):
        os.close(fd)
        kind = next((name for test, name in _FILE_KINDS if test(mode)), "a special file")
        raise TextFileError(f"{what} {path} is not a regular file ({kind})")
    with os.fdopen(fd, "rb") as fh:
        try:
            data = fh.read(max_bytes + 1)
        except OSError as exc:
            raise TextFileError(f"{path}: cannot read {what}: {exc.strerror or exc}") from None
    if len(data) > max_bytes:
        raise TextFileError(f"{what} {path} has more than {max_bytes:,} bytes; at most "
                            f"{max_bytes:,} are read (MAX_YAML_BYTES)")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise TextFileError(f"{path}: not UTF-8 text (byte 0x{exc.object[exc.start]:02x} at "
                            f"offset {exc.start}); save the {what} as UTF-8") from None


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
