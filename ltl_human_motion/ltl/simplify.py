"""Negation normal form and language-preserving rewrite rules.

:func:`nnf` pushes negations down to atoms and removes ``->``, ``<->`` and ``xor``; the
result uses only atoms, negated atoms, ``& | X F G U R W M`` and constants.
:func:`simplify` then applies rules such as ``F F a = F a``, ``G(a & b) = G a & G b``,
``true U a = F a``, ``a & !a = false``, ``a U (b | G a) = a W b``,
``a R (a | b) = b W a``; each rule is an LTL equivalence, and the
property tests check the translator (which runs both) against the evaluator.

Both passes rebuild nodes with :meth:`~ltl_human_motion.ltl.formula.Formula.make`:
:func:`nnf` makes each node's dual under a negation (:data:`_DUAL`), :func:`simplify`
simplifies a node's operands (:meth:`~ltl_human_motion.ltl.formula.Formula.map`), then
applies the rules of its kind (:data:`_RULES`).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache

from ltl_human_motion.ltl.formula import (
    FALSE,
    TRUE,
    And,
    Atom,
    Const,
    Equiv,
    Finally,
    Formula,
    Globally,
    Implies,
    Next,
    Not,
    Or,
    Release,
    StrongRelease,
    Until,
    WeakUntil,
    Xor,
    conj,
    disj,
)

__all__ = ["nnf", "simplify"]


#: The kind of ``!(a op b)`` pushed inside: ``!(a U b) = !a R !b``, ``!X a = X !a``, ...
_DUAL: dict[type, type] = {
    And: Or, Or: And, Next: Next, Finally: Globally, Globally: Finally,
    Until: Release, Release: Until, WeakUntil: StrongRelease, StrongRelease: WeakUntil,
}


@lru_cache(maxsize=4096)
def nnf(f: Formula, negate: bool = False) -> Formula:
    """Negation normal form of ``f`` (of ``!f`` if ``negate``)."""
    if isinstance(f, Const):
        return Const(f.value != negate)
    if isinstance(f, Atom):
        return Not(f) if negate else f
    if isinstance(f, Not):
        return nnf(f.arg, not negate)
    if isinstance(f, Implies):
        return nnf(Or((Not(f.left), f.right)), negate)
    if isinstance(f, Equiv):
        a, b = f.left, f.right
        if negate:
            return disj(conj(nnf(a), nnf(b, True)), conj(nnf(a, True), nnf(b)))
        return disj(conj(nnf(a), nnf(b)), conj(nnf(a, True), nnf(b, True)))
    if isinstance(f, Xor):
        return nnf(Equiv(f.left, f.right), not negate)
    kind = _DUAL.get(type(f))
    if kind is None:
        raise TypeError(f"not a formula node: {f!r}")
    return (kind if negate else type(f)).make(*[nnf(g, negate) for g in f.children()])


#: ``(a W b) & F b = a U b``, ``(a R b) & F a = a M b``: for an operand's kind, the
#: conjunct it absorbs and the kind it becomes.
_AND_MERGES: dict[type, tuple[Callable[[Formula], Formula], type]] = {
    WeakUntil: (lambda g: Finally(g.right), Until),
    Release: (lambda g: Finally(g.left), StrongRelease),
}
#: ``(a U b) | G a = a W b``, ``(a M b) | G b = a R b``: the same for disjunctions.
_OR_MERGES: dict[type, tuple[Callable[[Formula], Formula], type]] = {
    Until: (lambda g: Globally(g.left), WeakUntil),
    StrongRelease: (lambda g: Globally(g.right), Release),
}


def _merge_weak(f: And | Or) -> Formula | None:
    """``f`` with the first operand that absorbs another (:data:`_AND_MERGES`,
    :data:`_OR_MERGES`) merged with it; None if no rule applies."""
    merges = _AND_MERGES if isinstance(f, And) else _OR_MERGES
    items = set(f.args)
    for g in f.args:
        merge = merges.get(type(g))
        if merge is None or (used := merge[0](g)) not in items:
            continue
        rest = [h for h in f.args if h is not g and h != used]
        return type(f).make(merge[1](g.left, g.right), *rest)
    return None


def _complement(f: Formula) -> Formula | None:
    if isinstance(f, Atom):
        return Not(f)
    if isinstance(f, Not):
        return f.arg
    return None


def _operands(f: Formula, kind: type) -> tuple[Formula, ...]:
    return f.args if isinstance(f, kind) else (f,)


def _has_operand(f: Formula, g: Formula, kind: type) -> bool:
    """True if ``g`` is ``f`` or one of the operands of ``f`` (a ``kind`` node)."""
    return g in _operands(f, kind)


def _without(f: Formula, g: Formula, kind: type) -> Formula:
    """``f`` (an ``And``/``Or`` node or a single operand) without the operand ``g``."""
    return kind.make(*(h for h in _operands(f, kind) if h != g))


def _drop_disjuncts(a: Formula, b: Formula) -> Formula | None:
    """``a`` without the disjuncts that are also disjuncts of ``b``; None if there are none
    or if nothing would remain. In ``a U b`` and ``a W b`` such a disjunct only matters
    where ``b`` holds already."""
    common = set(_operands(a, Or)) & set(_operands(b, Or))
    if not common or not isinstance(a, Or) or common >= set(a.args):
        return None
    return disj(*(g for g in a.args if g not in common))


def _drop_conjuncts(a: Formula, b: Formula) -> Formula | None:
    """The dual of :func:`_drop_disjuncts` for ``a R b`` and ``a M b``: conjuncts of ``a``
    that are conjuncts of ``b`` hold wherever ``a & b`` is needed."""
    common = set(_operands(a, And)) & set(_operands(b, And))
    if not common or not isinstance(a, And) or common >= set(a.args):
        return None
    return conj(*(g for g in a.args if g not in common))


@lru_cache(maxsize=4096)
def simplify(f: Formula) -> Formula:
    """A simpler formula in NNF with the same models (input need not be in NNF)."""
    return _simp(nnf(f))


@lru_cache(maxsize=8192)
def _simp(f: Formula) -> Formula:
    if isinstance(f, (Const, Atom, Not)):
        return f
    rule = _RULES.get(type(f))
    if rule is None:
        raise TypeError(f"not an NNF formula node: {f!r}")
    g = f.map(_simp)
    # an And or Or whose simplified operands merged into one (or a constant): that one
    # is simplified already, and the rules of f's kind are not its rules
    return rule(g) if type(g) is type(f) else g


def _junction(f: And | Or) -> Formula:
    """``a & !a = false``, the merges of :func:`_merge_weak`, ``X a & X b = X(a & b)``."""
    is_and = isinstance(f, And)
    items = set(f.args)
    for g in f.args:
        c = _complement(g)
        if c is not None and c in items:
            return FALSE if is_and else TRUE
    merged = _merge_weak(f)
    if merged is not None:
        return _simp(merged)
    nexts = [g for g in f.args if isinstance(g, Next)]
    if is_and and len(nexts) > 1:  # not for "|", where X a | X b gives two smaller
        # successor states instead of one
        rest = [g for g in f.args if not isinstance(g, Next)]
        return _simp(conj(Next(conj(*(g.arg for g in nexts))), *rest))
    return f


def _next(f: Next) -> Formula:
    return f.arg if isinstance(f.arg, Const) else f


def _finally(f: Finally) -> Formula:
    a = f.arg
    if isinstance(a, (Const, Finally)):
        return a
    if isinstance(a, Until):  # F(a U b) = F b
        return _simp(Finally(a.right))
    if isinstance(a, StrongRelease):  # F(a M b) = F(a & b)
        return _simp(Finally(conj(a.left, a.right)))
    if isinstance(a, Or):  # F(a | b) = F a | F b
        return disj(*[_simp(Finally(g)) for g in a.args])
    if isinstance(a, Globally) and isinstance(a.arg, Finally):  # F G F a = G F a
        return a
    return f


def _globally(f: Globally) -> Formula:
    a = f.arg
    if isinstance(a, (Const, Globally)):
        return a
    if isinstance(a, Release):  # G(a R b) = G b
        return _simp(Globally(a.right))
    if isinstance(a, WeakUntil):  # G(a W b) = G(a | b)
        return _simp(Globally(disj(a.left, a.right)))
    if isinstance(a, And):  # G(a & b) = G a & G b
        return conj(*[_simp(Globally(g)) for g in a.args])
    if isinstance(a, Finally) and isinstance(a.arg, Globally):  # G F G a = F G a
        return a
    return f


def _trimmed(f: Until | Release | WeakUntil | StrongRelease) -> Formula | None:
    """``(c | a) U (c | b) = a U (c | b)``, the same for ``W``, and ``(c & a) R (c & b) =
    a R (c & b)``, the same for ``M``; None if ``a`` keeps every operand."""
    drop = _drop_disjuncts if isinstance(f, (Until, WeakUntil)) else _drop_conjuncts
    trimmed = drop(f.left, f.right)
    return None if trimmed is None else _simp(type(f)(trimmed, f.right))


def _until(f: Until) -> Formula:
    if (trimmed := _trimmed(f)) is not None:
        return trimmed
    a, b = f.left, f.right
    if b == TRUE or b == FALSE or a == FALSE or a == b:
        return b
    if a == TRUE:
        return _simp(Finally(b))
    if _has_operand(b, Globally(a), Or):  # a U (b | G a) = a W b
        return _simp(WeakUntil(a, _without(b, Globally(a), Or)))
    if _has_operand(b, a, And):  # a U (a & b) = b M a
        return _simp(StrongRelease(_without(b, a, And), a))
    return f


def _release(f: Release) -> Formula:
    if (trimmed := _trimmed(f)) is not None:
        return trimmed
    a, b = f.left, f.right
    if b == TRUE or b == FALSE or a == TRUE or a == b:
        return b
    if a == FALSE:
        return _simp(Globally(b))
    if _has_operand(b, Finally(a), And):  # a R (b & F a) = a M b
        return _simp(StrongRelease(a, _without(b, Finally(a), And)))
    if _has_operand(b, a, Or):  # a R (a | b) = b W a
        return _simp(WeakUntil(_without(b, a, Or), a))
    return f


def _weak_until(f: WeakUntil) -> Formula:
    if (trimmed := _trimmed(f)) is not None:
        return trimmed
    a, b = f.left, f.right
    if b == TRUE or a == b or a == FALSE:
        return b
    if a == TRUE:
        return TRUE
    if b == FALSE:
        return _simp(Globally(a))
    return f


def _strong_release(f: StrongRelease) -> Formula:
    if (trimmed := _trimmed(f)) is not None:
        return trimmed
    a, b = f.left, f.right
    if b == FALSE or a == b or a == TRUE:
        return b
    if a == FALSE:
        return FALSE
    if b == TRUE:
        return _simp(Finally(a))
    return f


#: The rules of each NNF kind, applied to a node whose operands are simplified.
_RULES: dict[type, Callable[[Formula], Formula]] = {
    And: _junction, Or: _junction, Next: _next, Finally: _finally, Globally: _globally,
    Until: _until, Release: _release, WeakUntil: _weak_until, StrongRelease: _strong_release,
}
