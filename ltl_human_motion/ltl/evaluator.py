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

from collections.abc import Iterable, Sequence

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
    n, total = len(prefix), len(word)

    def succ(i: int) -> int:
        return i + 1 if i + 1 < total else n

    def window(i: int) -> list[int]:
        """The positions i, i+1, ... covering every distinct suffix reachable from i."""
        out, k = [], i
        for _ in range(total):
            out.append(k)
            k = succ(k)
        return out

    memo: dict[Formula, list[bool]] = {}

    def until(a: list[bool], b: list[bool]) -> list[bool]:
        result = []
        for i in range(total):
            holds = False
            for j in window(i):
                if b[j]:
                    holds = True
                    break
                if not a[j]:
                    break
            result.append(holds)
        return result

    def ev(f: Formula) -> list[bool]:
        if f in memo:
            return memo[f]
        if isinstance(f, Const):
            r = [f.value] * total
        elif isinstance(f, Atom):
            r = [f.key in letter for letter in word]
        elif isinstance(f, Not):
            r = [not x for x in ev(f.arg)]
        elif isinstance(f, And):
            parts = [ev(g) for g in f.args]
            r = [all(p[i] for p in parts) for i in range(total)]
        elif isinstance(f, Or):
            parts = [ev(g) for g in f.args]
            r = [any(p[i] for p in parts) for i in range(total)]
        elif isinstance(f, Implies):
            a, b = ev(f.left), ev(f.right)
            r = [(not x) or y for x, y in zip(a, b)]
        elif isinstance(f, Equiv):
            a, b = ev(f.left), ev(f.right)
            r = [x == y for x, y in zip(a, b)]
        elif isinstance(f, Xor):
            a, b = ev(f.left), ev(f.right)
            r = [x != y for x, y in zip(a, b)]
        elif isinstance(f, Next):
            a = ev(f.arg)
            r = [a[succ(i)] for i in range(total)]
        elif isinstance(f, Until):
            r = until(ev(f.left), ev(f.right))
        elif isinstance(f, Finally):  # F phi = true U phi
            r = until([True] * total, ev(f.arg))
        elif isinstance(f, Globally):  # G phi = !F !phi
            r = [not x for x in until([True] * total, [not y for y in ev(f.arg)])]
        elif isinstance(f, Release):  # a R b = !(!a U !b)
            a, b = ev(f.left), ev(f.right)
            r = [not x for x in until([not y for y in a], [not y for y in b])]
        elif isinstance(f, WeakUntil):  # a W b = (a U b) | G a
            a, b = ev(f.left), ev(f.right)
            ga = [not x for x in until([True] * total, [not y for y in a])]
            r = [x or y for x, y in zip(until(a, b), ga)]
        elif isinstance(f, StrongRelease):  # a M b = b U (a & b)
            a, b = ev(f.left), ev(f.right)
            r = until(b, [x and y for x, y in zip(a, b)])
        else:
            raise TypeError(f"not a formula node: {f!r}")
        memo[f] = r
        return r

    return ev(formula)


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
    return evaluate_positions(formula, prefix_letters, cycle_letters)[0]


def propositional_letters(f: Formula, letters: Sequence[frozenset[str]]
                          ) -> tuple[int, ...] | None:
    """Indices of the letters on which the propositional ``f`` holds (None: temporal)."""

    def ev(g: Formula, letter: frozenset[str]) -> bool | None:
        if isinstance(g, Atom):
            return g.key in letter
        if isinstance(g, Const):
            return g.value
        if isinstance(g, Not):
            v = ev(g.arg, letter)
            return None if v is None else not v
        if isinstance(g, (And, Or)):
            vals = [ev(a, letter) for a in g.args]
            if any(v is None for v in vals):
                return None
            return all(vals) if isinstance(g, And) else any(vals)
        return None

    out = []
    for i, letter in enumerate(letters):
        v = ev(f, letter)
        if v is None:
            return None
        if v:
            out.append(i)
    return tuple(out)
