"""Graphviz DOT output of an automaton (edges labelled ``guard`` and ``{marks}``)."""

from __future__ import annotations

from ltl_human_motion.ltl.automaton import Automaton

__all__ = ["dot_from_automaton"]


def _escape(text: str) -> str:
    return text.replace("\\", "\\\\").replace('"', '\\"')


def dot_from_automaton(aut: Automaton) -> str:
    """The automaton as a DOT digraph; accepting states of a state-based automaton are
    drawn with a double circle, transition marks are shown as ``{0 1}``."""
    accepting = aut.accepting_states() if aut.state_based else frozenset()
    lines = ["digraph automaton {", "  rankdir=LR;",
             f'  label="{_escape(aut.name)}\\n'
             f'{"Büchi" if aut.num_sets == 1 else f"Inf x {aut.num_sets}"}";',
             "  labelloc=t;", '  node [shape=circle, fontname="Helvetica"];',
             '  edge [fontname="Helvetica"];', "  init [shape=point, label=\"\"];",
             f"  init -> {aut.initial};"]
    for q in aut.states:
        shape = ", shape=doublecircle" if q in accepting else ""
        lines.append(f'  {q} [label="{q}"{shape}];')
    for e in aut.edges:
        label = str(e.guard)
        if e.acc and not aut.state_based:
            label += " {" + " ".join(str(m) for m in sorted(e.acc)) + "}"
        lines.append(f'  {e.src} -> {e.dst} [label="{_escape(label)}"];')
    lines.append("}")
    return "\n".join(lines) + "\n"
