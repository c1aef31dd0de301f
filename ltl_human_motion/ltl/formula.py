"""LTL formulas as frozen, hashable values: one class per operator.

``str(formula)`` prints the project syntax, which :func:`~ltl_human_motion.ltl.parser.parse`
reads back to an equal formula; :func:`to_spot` prints Spot's ASCII syntax (task atoms
quoted, e.g. ``"grasp(O1)"``) so a formula can be pasted into Spot's tools.

Binding strength, weakest first (the paper's Sec. II-A rules, which agree with Spot):
``-> <->`` (right associative), ``|``, ``xor``, ``&``, ``U R W M`` (right associative),
unary ``! X F G``.

A pass over formulas is written with the generic walks of :class:`Formula`, as with
Spot's Python API: :meth:`~Formula.map` rebuilds a node over new children (through
:meth:`~Formula.make`, which flattens ``&`` and ``|``), and :meth:`~Formula.fold`
computes a value bottom-up, once per distinct subformula.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from typing import TypeVar

__all__ = [
    "FALSE", "TRUE", "And", "Atom", "Const", "Equiv", "Finally", "Formula", "Globally",
    "Implies", "Next", "Not", "Or", "Release", "StrongRelease", "Until", "WeakUntil", "Xor",
    "atoms", "conj", "disj", "neg", "size", "to_spot", "top_level_conjuncts",
]

T = TypeVar("T")

_PLAIN_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_.]*\Z")
_RESERVED = frozenset({"U", "R", "W", "M", "X", "F", "G", "true", "false", "xor",
                       "TRUE", "FALSE"})


class Formula:
    """Base class of all formula nodes (frozen dataclasses, hashable, ordered by text).

    Hash and text are computed once per node and cached, since the translator keys
    dictionaries and sorts on them.
    """

    def children(self) -> tuple[Formula, ...]:
        """The direct subformulas."""
        return ()

    @classmethod
    def make(cls, *children: Formula) -> Formula:
        """A node of this kind over ``children`` (``And`` and ``Or`` flatten, drop
        duplicates and constants: :func:`conj`, :func:`disj`)."""
        return cls(*children)

    def map(self, fn: Callable[[Formula], Formula]) -> Formula:
        """This kind of node over ``fn`` of each child (Spot's ``formula.map``); a
        constant or an atom is returned as it is."""
        children = self.children()
        return type(self).make(*[fn(c) for c in children]) if children else self

    def fold(self, fn: Callable[[Formula, list], T], memo: dict | None = None) -> T:
        """``fn(node, [values of its children])`` bottom-up, once per distinct subformula
        (``memo`` maps each to its value and may be shared between calls). Recursive:
        parsed formulas nest at most ``limits.MAX_NESTING`` deep."""
        memo = {} if memo is None else memo

        def value(f: Formula) -> T:
            if f in memo:
                return memo[f]
            out = memo[f] = fn(f, [value(c) for c in f.children()])
            return out

        return value(self)

    def _key(self) -> tuple:
        return tuple(self.__dict__[name] for name in self.__dataclass_fields__)

    def __eq__(self, other: object) -> bool:
        if self is other:
            return True
        if type(self) is not type(other):
            return NotImplemented if not isinstance(other, Formula) else False
        return hash(self) == hash(other) and self._key() == other._key()

    def __hash__(self) -> int:
        cached = self.__dict__.get("_hash")
        if cached is None:
            cached = hash((type(self).__name__, *self._key()))
            object.__setattr__(self, "_hash", cached)
        return cached

    def __getstate__(self) -> dict:
        # drop cached values: string hashes differ between processes
        return {k: self.__dict__[k] for k in self.__dataclass_fields__}

    def __str__(self) -> str:
        cached = self.__dict__.get("_text")
        if cached is None:
            cached = _render(self, spot=False)
            object.__setattr__(self, "_text", cached)
        return cached

    def __lt__(self, other: Formula) -> bool:
        return str(self) < str(other)


@dataclass(frozen=True, eq=False)
class Const(Formula):
    """``true`` or ``false``."""

    value: bool

    def __repr__(self) -> str:
        return "TRUE" if self.value else "FALSE"


TRUE = Const(True)
FALSE = Const(False)


@dataclass(frozen=True, eq=False)
class Atom(Formula):
    """An atomic proposition: a task predicate ``grasp(O1)``, ``enter(R1)`` or a plain name.

    ``key`` (``name`` or ``name(arg1, arg2)``) is the string that stands for the atom in
    word letters and in automaton propositions.
    """

    name: str
    args: tuple[str, ...] = ()

    @cached_property
    def key(self) -> str:
        """The atom's canonical string (used in letters and automaton APs)."""
        if not self.args:
            return self.name
        return f"{self.name}({', '.join(self.args)})"

    def __repr__(self) -> str:
        return f"Atom({self.key!r})"


@dataclass(frozen=True, eq=False)
class Not(Formula):
    """``!arg``."""

    arg: Formula

    def children(self) -> tuple[Formula, ...]:
        return (self.arg,)


@dataclass(frozen=True, eq=False)
class Next(Formula):
    """``X arg``: arg holds at the next position."""

    arg: Formula

    def children(self) -> tuple[Formula, ...]:
        return (self.arg,)


@dataclass(frozen=True, eq=False)
class Finally(Formula):
    """``F arg`` = ``true U arg``."""

    arg: Formula

    def children(self) -> tuple[Formula, ...]:
        return (self.arg,)


@dataclass(frozen=True, eq=False)
class Globally(Formula):
    """``G arg`` = ``!F !arg``."""

    arg: Formula

    def children(self) -> tuple[Formula, ...]:
        return (self.arg,)


@dataclass(frozen=True, eq=False)
class And(Formula):
    """``args[0] & args[1] & ...`` (at least two operands)."""

    args: tuple[Formula, ...]

    def children(self) -> tuple[Formula, ...]:
        return self.args

    @classmethod
    def make(cls, *children: Formula) -> Formula:
        return conj(*children)


@dataclass(frozen=True, eq=False)
class Or(Formula):
    """``args[0] | args[1] | ...`` (at least two operands)."""

    args: tuple[Formula, ...]

    def children(self) -> tuple[Formula, ...]:
        return self.args

    @classmethod
    def make(cls, *children: Formula) -> Formula:
        return disj(*children)


@dataclass(frozen=True, eq=False)
class _Binary(Formula):
    left: Formula
    right: Formula

    def children(self) -> tuple[Formula, ...]:
        return (self.left, self.right)


class Implies(_Binary):
    """``left -> right``."""


class Equiv(_Binary):
    """``left <-> right``."""


class Xor(_Binary):
    """``left xor right``."""


class Until(_Binary):
    """``left U right`` (strong until)."""


class Release(_Binary):
    """``left R right`` = ``!(!left U !right)``."""


class WeakUntil(_Binary):
    """``left W right`` = ``(left U right) | G left``."""


class StrongRelease(_Binary):
    """``left M right`` = ``right U (left & right)``."""


# --------------------------------------------------------------------------- helpers

def conj(*parts: Formula) -> Formula:
    """The conjunction of ``parts``, flattened, without duplicates or ``true``."""
    out: list[Formula] = []
    seen: set[Formula] = set()      # membership in a list is quadratic in the parts
    for part in parts:
        items = part.args if isinstance(part, And) else (part,)
        for item in items:
            if item == FALSE:
                return FALSE
            if item != TRUE and item not in seen:
                seen.add(item)
                out.append(item)
    if not out:
        return TRUE
    return out[0] if len(out) == 1 else And(tuple(out))


def disj(*parts: Formula) -> Formula:
    """The disjunction of ``parts``, flattened, without duplicates or ``false``."""
    out: list[Formula] = []
    seen: set[Formula] = set()
    for part in parts:
        items = part.args if isinstance(part, Or) else (part,)
        for item in items:
            if item == TRUE:
                return TRUE
            if item != FALSE and item not in seen:
                seen.add(item)
                out.append(item)
    if not out:
        return FALSE
    return out[0] if len(out) == 1 else Or(tuple(out))


def neg(f: Formula) -> Formula:
    """``!f`` with double negations and constants removed."""
    if isinstance(f, Const):
        return Const(not f.value)
    if isinstance(f, Not):
        return f.arg
    return Not(f)


def atoms(f: Formula) -> frozenset[Atom]:
    """All atoms occurring in ``f``."""
    found: set[Atom] = set()
    stack = [f]
    while stack:
        g = stack.pop()
        if isinstance(g, Atom):
            found.add(g)
        else:
            stack.extend(g.children())
    return frozenset(found)


def size(f: Formula) -> int:
    """Number of nodes of ``f``."""
    return 1 + sum(size(c) for c in f.children())


def top_level_conjuncts(f: Formula) -> tuple[Formula, ...]:
    """The operands of a top-level ``&`` (``(f,)`` when ``f`` is no conjunction)."""
    return f.args if isinstance(f, And) else (f,)


def to_spot(f: Formula) -> str:
    """``f`` in Spot's ASCII syntax; task atoms are double-quoted (``"grasp(O1)"``)."""
    return _render(f, spot=True)


# --------------------------------------------------------------------------- printing

_BINARY_TOKENS: dict[type, tuple[str, int]] = {
    Implies: ("->", 1), Equiv: ("<->", 1), Or: ("|", 2), Xor: ("xor", 3), And: ("&", 4),
    Until: ("U", 5), Release: ("R", 5), WeakUntil: ("W", 5), StrongRelease: ("M", 5),
}
_UNARY_TOKENS: dict[type, str] = {Not: "!", Next: "X", Finally: "F", Globally: "G"}


def _atom_text(a: Atom, spot: bool) -> str:
    if a.args and not spot:
        ok = _PLAIN_NAME.match(a.name) and a.name not in _RESERVED and a.name[0] not in "FGX"
        if ok and all(_PLAIN_NAME.match(x) or _is_number(x) for x in a.args):
            return a.key
    elif not a.args and _PLAIN_NAME.match(a.name) and a.name not in _RESERVED \
            and a.name[0] not in "FGX":
        return a.name
    escaped = a.key.replace("\\", "\\\\").replace('"', '\\"')
    return f'"{escaped}"'


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _render(f: Formula, spot: bool) -> str:
    if isinstance(f, Const):
        return "true" if f.value else "false"
    if isinstance(f, Atom):
        return _atom_text(f, spot)
    kind = type(f)
    if kind in _UNARY_TOKENS:
        token = _UNARY_TOKENS[kind]
        child = f.children()[0]
        inner = _render(child, spot)
        if isinstance(child, (Const, Atom, Not, Next, Finally, Globally)):
            return f"{token}{inner}" if kind is Not else f"{token} {inner}"
        return f"{token}({inner})"
    token, prec = _BINARY_TOKENS[kind]
    parts = []
    for child in f.children():
        text = _render(child, spot)
        child_prec = _BINARY_TOKENS.get(type(child), (None, 99))[1]
        parts.append(f"({text})" if child_prec <= prec else text)
    return f" {token} ".join(parts)
