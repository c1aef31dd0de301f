"""Negation normal form and language-preserving rewrite rules.

:func:`nnf` pushes negations down to atoms and removes ``->``, ``<->`` and ``xor``; the
result uses only atoms, negated atoms, ``& | X F G U R W M`` and constants.
:func:`simplify` then applies rules such as ``F F a = F a``, ``G(a & b) = G a & G b``,
``true U a = F a``, ``a & !a = false``, ``a U (b | G a) = a W b``,
``a R (a | b) = b W a``; each rule is an LTL equivalence, and the
property tests check the translator (which runs both) against the evaluator.
"""

from __future__ import annotations

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


@lru_cache(maxsize=4096)
def nnf(f: Formula, negate: bool = False) -> Formula:
    """Negation normal form of ``f`` (of ``!f`` if ``negate``)."""
    if isinstance(f, Const):
        return Const(f.value != negate)
    if isinstance(f, Atom):
        return Not(f) if negate else f
    if isinstance(f, Not):
        return nnf(f.arg, not negate)
    if isinstance(f, And):
        parts = [nnf(g, negate) for g in f.args]
        return disj(*parts) if negate else conj(*parts)
    if isinstance(f, Or):
        parts = [nnf(g, negate) for g in f.args]
        return conj(*parts) if negate else disj(*parts)
    if isinstance(f, Implies):
        return nnf(Or((Not(f.left), f.right)), negate)
    if isinstance(f, Equiv):
        a, b = f.left, f.right
        if negate:
            return disj(conj(nnf(a), nnf(b, True)), conj(nnf(a, True), nnf(b)))
        return disj(conj(nnf(a), nnf(b)), conj(nnf(a, True), nnf(b, True)))
    if isinstance(f, Xor):
        return nnf(Equiv(f.left, f.right), not negate)
    if isinstance(f, Next):
        return Next(nnf(f.arg, negate))
    if isinstance(f, Finally):
        return Globally(nnf(f.arg, True)) if negate else Finally(nnf(f.arg))
    if isinstance(f, Globally):
        return Finally(nnf(f.arg, True)) if negate else Globally(nnf(f.arg))
    a, b = nnf(f.left, negate), nnf(f.right, negate)
    if isinstance(f, Until):
        return Release(a, b) if negate else Until(a, b)
    if isinstance(f, Release):
        return Until(a, b) if negate else Release(a, b)
    if isinstance(f, WeakUntil):
        return StrongRelease(a, b) if negate else WeakUntil(a, b)
    if isinstance(f, StrongRelease):
        return WeakUntil(a, b) if negate else StrongRelease(a, b)
    raise TypeError(f"not a formula node: {f!r}")


def _merge_weak(args: tuple[Formula, ...], items: set[Formula],
                is_and: bool) -> Formula | None:
    """``(a U b) | G a = a W b``, ``(a M b) | G b = a R b``, ``(a W b) & F b = a U b``,
    ``(a R b) & F a = a M b``; None if no rule applies."""
    for g in args:
        if is_and:
            if isinstance(g, WeakUntil) and Finally(g.right) in items:
                new, used = Until(g.left, g.right), Finally(g.right)
            elif isinstance(g, Release) and Finally(g.left) in items:
                new, used = StrongRelease(g.left, g.right), Finally(g.left)
            else:
                continue
        else:
            if isinstance(g, Until) and Globally(g.left) in items:
                new, used = WeakUntil(g.left, g.right), Globally(g.left)
            elif isinstance(g, StrongRelease) and Globally(g.right) in items:
                new, used = Release(g.left, g.right), Globally(g.right)
            else:
                continue
        rest = [h for h in args if h is not g and h != used]
        return conj(new, *rest) if is_and else disj(new, *rest)
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
    rest = [h for h in _operands(f, kind) if h != g]
    return conj(*rest) if kind is And else disj(*rest)


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
    if isinstance(f, (And, Or)):
        is_and = isinstance(f, And)
        parts = [_simp(g) for g in f.args]
        out = conj(*parts) if is_and else disj(*parts)
        if isinstance(out, (And, Or)):
            items = set(out.args)
            for g in out.args:
                c = _complement(g)
                if c is not None and c in items:
                    return FALSE if is_and else TRUE
            merged = _merge_weak(out.args, items, is_and)
            if merged is not None:
                return _simp(merged)
            nexts = [g for g in out.args if isinstance(g, Next)]
            if is_and and len(nexts) > 1:  # X a & X b = X(a & b); not for "|", where
                # X a | X b gives two smaller successor states instead of one
                rest = [g for g in out.args if not isinstance(g, Next)]
                return _simp(conj(Next(conj(*(g.arg for g in nexts))), *rest))
        return out
    if isinstance(f, Next):
        a = _simp(f.arg)
        return a if isinstance(a, Const) else Next(a)
    if isinstance(f, Finally):
        a = _simp(f.arg)
        if isinstance(a, Const) or isinstance(a, Finally):
            return a
        if isinstance(a, Until):  # F(a U b) = F b
            return _simp(Finally(a.right))
        if isinstance(a, StrongRelease):  # F(a M b) = F(a & b)
            return _simp(Finally(conj(a.left, a.right)))
        if isinstance(a, Or):  # F(a | b) = F a | F b
            return disj(*[_simp(Finally(g)) for g in a.args])
        if isinstance(a, Globally) and isinstance(a.arg, Finally):  # F G F a = G F a
            return a
        return Finally(a)
    if isinstance(f, Globally):
        a = _simp(f.arg)
        if isinstance(a, Const) or isinstance(a, Globally):
            return a
        if isinstance(a, Release):  # G(a R b) = G b
            return _simp(Globally(a.right))
        if isinstance(a, WeakUntil):  # G(a W b) = G(a | b)
            return _simp(Globally(disj(a.left, a.right)))
        if isinstance(a, And):  # G(a & b) = G a & G b
            return conj(*[_simp(Globally(g)) for g in a.args])
        if isinstance(a, Finally) and isinstance(a.arg, Globally):  # G F G a = F G a
            return a
        return Globally(a)
    a, b = _simp(f.left), _simp(f.right)
    if isinstance(f, (Until, WeakUntil)):
        trimmed = _drop_disjuncts(a, b)
        if trimmed is not None:  # (c | a) U (c | b) = a U (c | b), the same for W
            return _simp(type(f)(trimmed, b))
    if isinstance(f, (Release, StrongRelease)):
        trimmed = _drop_conjuncts(a, b)
        if trimmed is not None:  # (c & a) R (c & b) = a R (c & b), the same for M
            return _simp(type(f)(trimmed, b))
    if isinstance(f, Until):
        if b == TRUE or b == FALSE or a == FALSE or a == b:
            return b
        if a == TRUE:
            return _simp(Finally(b))
        if _has_operand(b, Globally(a), Or):  # a U (b | G a) = a W b
            return _simp(WeakUntil(a, _without(b, Globally(a), Or)))
        if _has_operand(b, a, And):  # a U (a & b) = b M a
            return _simp(StrongRelease(_without(b, a, And), a))
        return Until(a, b)
    if isinstance(f, Release):
        if b == TRUE or b == FALSE or a == TRUE or a == b:
            return b
        if a == FALSE:
            return _simp(Globally(b))
        if _has_operand(b, Finally(a), And):  # a R (b & F a) = a M b
            return _simp(StrongRelease(a, _without(b, Finally(a), And)))
        if _has_operand(b, a, Or):  # a R (a | b) = b W a
            return _simp(WeakUntil(_without(b, a, Or), a))
        return Release(a, b)
    if isinstance(f, WeakUntil):
        if b == TRUE or a == b or a == FALSE:
            return b
        if a == TRUE:
            return TRUE
        if b == FALSE:
            return _simp(Globally(a))
        return WeakUntil(a, b)
    if isinstance(f, StrongRelease):
        if b == FALSE or a == b or a == TRUE:
            return b
        if a == FALSE:
            return FALSE
        if b == TRUE:
            return _simp(Finally(a))
        return StrongRelease(a, b)
    raise TypeError(f"not an NNF formula node: {f!r}")
