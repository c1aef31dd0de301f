"""HOA v1 (Hanoi Omega-Automata format) output and input.

Writes any :class:`~ltl_human_motion.ltl.automaton.Automaton`; reads the generalized
Büchi subset (``Acceptance: k Inf(0)&...&Inf(k-1)``, ``t``), with state- or
transition-based marks, explicit labels and ``Alias`` definitions, which covers what
Spot's ``ltl2tgba`` writes for LTL. Labels are turned into disjunctions of cubes (one
edge per cube).
"""

from __future__ import annotations

import re
import shlex

from ltl_human_motion.errors import SpecError
from ltl_human_motion.ltl.automaton import Automaton, Cube, Edge

__all__ = ["HoaError", "automaton_from_hoa", "hoa_from_automaton"]


class HoaError(SpecError):
    """A HOA text that cannot be read (line and column point at the problem)."""


def _label(cube: Cube, aps: tuple[str, ...]) -> str:
    lits = [(aps.index(a), "") for a in cube.pos] + [(aps.index(a), "!") for a in cube.neg]
    return "&".join(f"{s}{i}" for i, s in sorted(lits)) or "t"


def _quote(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def hoa_from_automaton(aut: Automaton) -> str:
    """The automaton as HOA v1 text."""
    k = aut.num_sets
    if k == 0:
        acc_name, condition = "all", "0 t"
    elif k == 1:
        acc_name, condition = "Buchi", "1 Inf(0)"
    else:
        acc_name = f"generalized-Buchi {k}"
        condition = f"{k} " + "&".join(f"Inf({i})" for i in range(k))
    lines = ["HOA: v1"]
    if aut.name:
        lines.append(f"name: {_quote(aut.name)}")
    lines += [f"States: {aut.num_states}", f"Start: {aut.initial}",
              f"AP: {len(aut.aps)}" + "".join(f" {_quote(a)}" for a in aut.aps),
              f"acc-name: {acc_name}", f"Acceptance: {condition}",
              "properties: trans-labels explicit-labels "
              + ("state-acc" if aut.state_based else "trans-acc"),
              "--BODY--"]
    for q in aut.states:
        edges = aut.successors(q)
        marks = ""
        if aut.state_based and edges and edges[0].acc:
            marks = " {" + " ".join(str(m) for m in sorted(edges[0].acc)) + "}"
        lines.append(f"State: {q}{marks}")
        for e in edges:
            acc = ""
            if not aut.state_based and e.acc:
                acc = " {" + " ".join(str(m) for m in sorted(e.acc)) + "}"
            lines.append(f"[{_label(e.guard, aut.aps)}] {e.dst}{acc}")
    lines.append("--END--")
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------------- reading

_TOKEN = re.compile(r'\s*(?:(?P<str>"(?:[^"\\]|\\.)*")|(?P<int>\d+)|(?P<alias>@[\w.-]+)'
                    r'|(?P<ident>[A-Za-z_][\w-]*:?)|(?P<sym>--BODY--|--END--|--ABORT--|'
                    r'[\[\]{}()!&|]))', re.S)


class _Reader:
    def __init__(self, text: str) -> None:
        self.text = text
        self.toks: list[tuple[str, str, int]] = []
        pos = 0
        while True:
            while pos < len(text) and text[pos].isspace():
                pos += 1
            if pos < len(text) and text.startswith("/*", pos):
                end = text.find("*/", pos + 2)
                if end < 0:
                    raise self.error("unterminated comment", pos)
                pos = end + 2
                continue
            if pos >= len(text):
                break
            m = _TOKEN.match(text, pos)
            if not m or m.end() == pos:
                raise self.error(f"unexpected character {text[pos]!r}", pos)
            kind = m.lastgroup or "sym"
            self.toks.append((kind, m.group(kind), m.start(kind)))
            pos = m.end()
        self.toks.append(("eof", "", len(text)))
        self.i = 0

    def error(self, message: str, pos: int) -> HoaError:
        line = self.text.count("\n", 0, pos) + 1
        column = pos - (self.text.rfind("\n", 0, pos) + 1) + 1
        return HoaError(f"HOA: {message}", text=self.text, line=line, column=column)

    def peek(self) -> tuple[str, str, int]:
        return self.toks[self.i]

    def take(self, kind: str | None = None, value: str | None = None) -> tuple[str, str, int]:
        tok = self.toks[self.i]
        if (kind and tok[0] != kind) or (value and tok[1] != value):
            want = value or kind
            raise self.error(f"expected {want}, found {tok[1] or 'end of input'!r}", tok[2])
        self.i += 1
        return tok

    def integer(self) -> int:
        return int(self.take("int")[1])


def _dnf(node: tuple, aliases: dict[str, tuple]) -> list[tuple[frozenset, frozenset]]:
    """Disjunctive normal form of a parsed label as (pos, neg) index sets."""
    kind = node[0]
    if kind == "const":
        return [(frozenset(), frozenset())] if node[1] else []
    if kind == "ap":
        return [(frozenset({node[1]}), frozenset())]
    if kind == "alias":
        return _dnf(aliases[node[1]], aliases)
    if kind == "or":
        return _dnf(node[1], aliases) + _dnf(node[2], aliases)
    if kind == "and":
        out = []
        for p1, n1 in _dnf(node[1], aliases):
            for p2, n2 in _dnf(node[2], aliases):
                p, n = p1 | p2, n1 | n2
                if not p & n:
                    out.append((p, n))
        return out
    # not: push negation inward
    inner = node[1]
    if inner[0] == "const":
        return _dnf(("const", not inner[1]), aliases)
    if inner[0] == "ap":
        return [(frozenset(), frozenset({inner[1]}))]
    if inner[0] == "alias":
        return _dnf(("not", aliases[inner[1]]), aliases)
    if inner[0] == "not":
        return _dnf(inner[1], aliases)
    dual = "and" if inner[0] == "or" else "or"
    return _dnf((dual, ("not", inner[1]), ("not", inner[2])), aliases)


def _label_expr(r: _Reader, aliases: dict[str, tuple], num_aps: int) -> tuple:
    def disj() -> tuple:
        node = conj()
        while r.peek()[1] == "|":
            r.take()
            node = ("or", node, conj())
        return node

    def conj() -> tuple:
        node = atom()
        while r.peek()[1] == "&":
            r.take()
            node = ("and", node, atom())
        return node

    def atom() -> tuple:
        kind, value, pos = r.take()
        if value == "!":
            return ("not", atom())
        if value == "(":
            node = disj()
            r.take("sym", ")")
            return node
        if kind == "ident" and value in ("t", "f"):
            return ("const", value == "t")
        if kind == "int":
            if int(value) >= num_aps:
                raise r.error(f"atomic proposition {value} not declared (AP: {num_aps})", pos)
            return ("ap", int(value))
        if kind == "alias":
            if value not in aliases:
                raise r.error(f"undefined alias {value}", pos)
            return ("alias", value)
        raise r.error(f"expected a label expression, found {value or 'end of input'!r}", pos)

    return disj()


def _acceptance(r: _Reader) -> int:
    """Parse ``Acceptance:``; only conjunctions of distinct Inf(i) (or t) are supported."""
    count = r.integer()
    sets: list[int] = []
    start = r.peek()[2]
    depth = 0
    while True:
        kind, value, pos = r.peek()
        if kind == "ident" and value in ("Inf",):
            r.take()
            r.take("sym", "(")
            sets.append(r.integer())
            r.take("sym", ")")
        elif kind == "ident" and value == "t":
            r.take()
        elif value == "&":
            r.take()
        elif value == "(":
            depth += 1
            r.take()
        elif value == ")" and depth:
            depth -= 1
            r.take()
        elif (kind == "ident" and value in ("Fin", "f")) or value in ("|", "!"):
            raise r.error("only generalized Büchi acceptance (Inf(0)&...&Inf(k-1), or t) "
                          "is supported; convert with 'autfilt --gba' first", pos)
        else:
            break
    if sorted(sets) != list(range(count)):
        raise r.error(f"acceptance must use each of the {count} sets once with Inf, got "
                      f"Inf({sets})", start)
    return count


def automaton_from_hoa(text: str) -> Automaton:
    """Read one automaton from HOA v1 text.

    Raises
    ------
    HoaError
        With line and column, for malformed or unsupported input.
    """
    r = _Reader(text)
    r.take("ident", "HOA:")
    r.take("ident", "v1")
    num_states: int | None = None
    starts: list[int] = []
    aps: tuple[str, ...] | None = None
    num_sets: int | None = None
    name = ""
    state_acc_prop = False
    aliases: dict[str, tuple] = {}
    while r.peek()[1] != "--BODY--":
        kind, value, pos = r.take()
        if kind == "eof":
            raise r.error("missing --BODY--", pos)
        if kind != "ident" or not value.endswith(":"):
            raise r.error(f"expected a header item, found {value!r}", pos)
        if value == "States:":
            num_states = r.integer()
        elif value == "Start:":
            starts.append(r.integer())
            if r.peek()[1] == "&":
                raise r.error("universal initial states (alternation) are not supported", pos)
        elif value == "AP:":
            n = r.integer()
            names = [shlex.split(r.take("str")[1])[0] for _ in range(n)]
            aps = tuple(names)
        elif value == "Acceptance:":
            num_sets = _acceptance(r)
        elif value == "name:":
            name = shlex.split(r.take("str")[1])[0]
        elif value == "Alias:":
            alias = r.take("alias")[1]
            aliases[alias] = _label_expr(r, aliases, len(aps or ()))
        else:
            while r.peek()[0] != "eof" and not (r.peek()[0] == "ident" and
                                                 r.peek()[1].endswith(":")) \
                    and r.peek()[1] != "--BODY--":
                tok = r.take()
                if value == "properties:" and tok[1] == "state-acc":
                    state_acc_prop = True
    body_pos = r.take("sym", "--BODY--")[2]
    if aps is None:
        aps = ()
    if num_sets is None:
        raise r.error("missing Acceptance: header", body_pos)
    if len(starts) != 1:
        raise r.error(f"exactly one Start: state is supported, got {len(starts)}", body_pos)
    edges: list[Edge] = []
    seen_states: set[int] = set()
    state_based = True
    while r.peek()[1] != "--END--":
        kind, value, pos = r.take()
        if value != "State:":
            raise r.error(f"expected 'State:' or '--END--', found {value or 'end'!r}", pos)
        state_label = None
        if r.peek()[1] == "[":
            r.take()
            state_label = _label_expr(r, aliases, len(aps))
            r.take("sym", "]")
        q = r.integer()
        if r.peek()[0] == "str":
            r.take()
        state_marks: frozenset[int] | None = None
        if r.peek()[1] == "{":
            r.take()
            marks = []
            while r.peek()[0] == "int":
                marks.append(r.integer())
            r.take("sym", "}")
            state_marks = frozenset(marks)
        seen_states.add(q)
        while r.peek()[1] not in ("State:", "--END--"):
            label = state_label
            if r.peek()[1] == "[":
                r.take()
                label = _label_expr(r, aliases, len(aps))
                r.take("sym", "]")
            if label is None:
                raise r.error("implicit labels are not supported; expected '[label]'",
                              r.peek()[2])
            dst = r.integer()
            if r.peek()[1] == "&":
                raise r.error("universal edges (alternation) are not supported", r.peek()[2])
            marks_e: frozenset[int] = frozenset()
            if r.peek()[1] == "{":
                r.take()
                ms = []
                while r.peek()[0] == "int":
                    ms.append(r.integer())
                r.take("sym", "}")
                marks_e = frozenset(ms)
                state_based = False
            acc = (state_marks or frozenset()) | marks_e
            for pos_set, neg_set in _dnf(label, aliases):
                edges.append(Edge(q, dst, Cube(frozenset(aps[i] for i in pos_set),
                                               frozenset(aps[i] for i in neg_set)), acc))
    r.take("sym", "--END--")
    if num_states is None:
        num_states = max([starts[0], *seen_states, *(e.dst for e in edges)], default=0) + 1
    try:
        return Automaton(aps, num_states, starts[0], tuple(edges), num_sets,
                         (state_based and state_acc_prop) or state_based, name)
    except ValueError as exc:
        raise HoaError(f"HOA: {exc}", text=text) from None
