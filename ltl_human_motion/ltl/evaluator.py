"""An independent checker: LTL semantics of Sec. II-A on lasso words ``u v^omega``.

Written directly from the definitions, without automata, so it can check the
translators and every task sequence the project emits. A lasso with ``n`` prefix letters
and ``m >= 1`` cycle letters has ``n + m`` distinct suffixes: position ``i`` stands for
the suffix ``sigma_i``, and the successor of the last position is ``n``.

For ``phi1 U phi2`` at position ``i`` the definition asks for some ``j >= i`` with
``sigma_j |= phi2`` and ``sigma_k |= phi1`` for all ``i <= k < j``. Positions repeat with
period ``m`` after the prefix, so the smallest such ``j`` (if any) lies among the first
``n + m`` positions visited from ``i``; the evaluator walks exactly those. The derived
operators are evaluated through the equalities of Sec. II-A (``F``, ``G``, ``R``, ``W``,
``M`` as ``U`` and negation).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence

from ltl_human_motion.kernel.cache import BoundedCache
from ltl_human_motion.ltl.formula import (
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
)

__all__ = ["evaluate_lasso", "evaluate_positions", "propositional_letters"]

Letter = frozenset[str]


def _letters(seq: Iterable[Iterable[str]]) -> list[frozenset[str]]:
    out = []
    for x in seq:
        if isinstance(x, str):
            raise ValueError(f"a letter must be a set of atom keys, got the string {x!r} "
                             "(write {'" + x + "'})")
        out.append(frozenset(x))
    return out


class _Lasso:
    """The positions of a lasso word ``prefix . cycle^omega``: one per distinct suffix
    (``n`` prefix letters, then the cycle's; the successor of the last is ``n``). A
    truth value over the word is a list of bool, one per position."""

    def __init__(self, word: list[frozenset[str]], n: int) -> None:
        self.total = total = len(word)
        self.succ = [i + 1 if i + 1 < total else n for i in range(total)]
        self.always = [True] * total
        self._windows: list[list[int]] = []

    def windows(self) -> list[list[int]]:
        """For each position ``i``: ``i`` and the positions after it, up to every distinct
        suffix reachable from ``i``."""
        if not self._windows:
            for i in range(self.total):
                out, k = [], i
                for _ in range(self.total):
                    out.append(k)
                    k = self.succ[k]
                self._windows.append(out)
        return self._windows

    def until(self, a: list[bool], b: list[bool]) -> list[bool]:
        result = []
        for window in self.windows():
            holds = False
            for j in window:
                if b[j]:
                    holds = True
                    break
                if not a[j]:
                    break
            result.append(holds)
        return result

    def next(self, a: list[bool]) -> list[bool]:
        return [a[j] for j in self.succ]

    def eventually(self, a: list[bool]) -> list[bool]:
        return self.until(self.always, a)

    def globally(self, a: list[bool]) -> list[bool]:
        return _no(self.eventually(_no(a)))


def _no(a: list[bool]) -> list[bool]:
    return [not x for x in a]


#: Each operator's truth over the positions, from its operands'; the derived operators
#: through the equalities of Sec. II-A: ``F a = true U a``, ``G a = !F !a``,
#: ``a R b = !(!a U !b)``, ``a W b = (a U b) | G a``, ``a M b = b U (a & b)``.
_OPERATORS: dict[type, Callable[..., list[bool]]] = {
    Not: lambda _w, a: _no(a),
    And: lambda _w, *parts: [all(column) for column in zip(*parts)],
    Or: lambda _w, *parts: [any(column) for column in zip(*parts)],
    Implies: lambda _w, a, b: [(not x) or y for x, y in zip(a, b)],
    Equiv: lambda _w, a, b: [x == y for x, y in zip(a, b)],
    Xor: lambda _w, a, b: [x != y for x, y in zip(a, b)],
    Next: _Lasso.next,
    Until: _Lasso.until,
    Finally: _Lasso.eventually,
    Globally: _Lasso.globally,
    Release: lambda w, a, b: _no(w.until(_no(a), _no(b))),
    WeakUntil: lambda w, a, b: [x or y for x, y in zip(w.until(a, b), w.globally(a))],
    StrongRelease: lambda w, a, b: w.until(b, [x and y for x, y in zip(a, b)]),
}


def evaluate_positions(formula: Formula, prefix: Sequence[Iterable[str]],
                       cycle: Sequence[Iterable[str]]) -> list[bool]:
    """Truth of ``formula`` at every distinct suffix of ``prefix . cycle^omega``.

    Parameters
    ----------
    formula : Formula
    prefix, cycle : sequences of letters
        A letter is a set of atom keys (``"grasp(O1)"``); ``cycle`` must not be empty.

    Returns
    -------
    list of bool, length ``len(prefix) + len(cycle)``
    """
    word = _letters(prefix) + _letters(cycle)
    if not cycle:
        raise ValueError("a lasso needs at least one cycle letter, got an empty cycle")
    lasso = _Lasso(word, len(prefix))

    def value(f: Formula, children: list[list[bool]]) -> list[bool]:
        if isinstance(f, Const):
            return [f.value] * lasso.total
        if isinstance(f, Atom):
            return [f.key in letter for letter in word]
        op = _OPERATORS.get(type(f))
        if op is None:
            raise TypeError(f"not a formula node: {f!r}")
        return op(lasso, *children)

    return formula.fold(value)


def evaluate_lasso(formula: Formula, prefix_letters: Sequence[Iterable[str]],
                   cycle_letters: Sequence[Iterable[str]]) -> bool:
    """True iff ``prefix . cycle^omega |= formula`` (Sec. II-A semantics).

    Parameters
    ----------
    formula : Formula
    prefix_letters : sequence of letters
        Letters before the loop (may be empty).
    cycle_letters : sequence of letters
        The repeated part; must not be empty.

    Raises
    ------
    ValueError
        If ``cycle_letters`` is empty.
    """
    prefix, cycle = tuple(_letters(prefix_letters)), tuple(_letters(cycle_letters))
    return _LASSO_TRUTHS.get_or_build(
        (prefix, cycle), lambda: evaluate_positions(formula, prefix, cycle)[0], owner=formula)


#: Truth of a formula (by identity: a specification parsed once) on a lasso word: the
#: product search of every batch item checks the same few task words again.
_LASSO_TRUTHS: BoundedCache[bool] = BoundedCache(4096)


def propositional_letters(f: Formula, letters: Sequence[frozenset[str]]
                          ) -> tuple[int, ...] | None:
    """Indices of the letters on which the propositional ``f`` holds (None: temporal)."""
    if not letters:
        return ()
    every = frozenset(range(len(letters)))

    def holds(g: Formula, children: list[frozenset[int] | None]) -> frozenset[int] | None:
        if isinstance(g, Atom):
            return frozenset(i for i, letter in enumerate(letters) if g.key in letter)
        if isinstance(g, Const):
            return every if g.value else frozenset()
        if None in children:
            return None
        if isinstance(g, Not):
            return every - children[0]
        if isinstance(g, And):
            return frozenset.intersection(*children)
        if isinstance(g, Or):
            return frozenset.union(*children)
        return None

    found = f.fold(holds)
    return None if found is None else tuple(sorted(found))
