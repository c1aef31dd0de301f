"""Specifications with the always-on conjuncts of Sec. II-B, task letters and unsat cores.

A :class:`Specification` is the user's formula plus, added automatically
(docs/ARCHITECTURE.md):

* **exclusivity** ``G(!(p & q) & ...)`` for every pair of task atoms that no single task
  step contains together (one task, or one shorthand expansion such as
  ``assemble(R1) = leftHand(R1) & rightHand(R1)``, per step). For S1 this is the
  paper's ``G(!(a & g))``.
* **final region** ``F enter(R_final)`` when the cell names a final region.

"Start in R0" and "no collision" concern the motion and are verified on it later.

The candidate task steps of a specification are the tasks and shorthand instances its
text mentions, plus ``walk(R)`` for each region R in an ``enter(R)`` atom and for the
final region, when no mentioned task enters R.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

from ltl_human_motion.errors import SpecError
from ltl_human_motion.kernel.cache import BoundedCache
from ltl_human_motion.ltl.formula import (
    And,
    Atom,
    Finally,
    Formula,
    Globally,
    Not,
    atoms,
    conj,
    top_level_conjuncts,
)
from ltl_human_motion.ltl.parser import parse_spec
from ltl_human_motion.ltl.vocabulary import Vocabulary, vocabulary_from
from ltl_human_motion.vocabulary import ENTERING_TASKS, REGION_ATOM

__all__ = [
    "PAPER_SPECS", "Specification", "Task", "build_specification", "letter_of",
    "resolve_spec_text",
]

#: A task step: a Table I task or a shorthand instance, printed as ``grasp(O1)``.
Task = Atom

#: The paper's specifications (Sec. IV) in the project syntax.
#:
#: S1 is formula (3), ``g & G(a -> F(g) & g -> F(a))``. Read with the precedence the paper
#: states (and Spot's: ``&`` binds tighter than ``->``, which is right associative), its
#: body is ``a -> ((F g & g) -> F a)``, which exclusivity (``G !(a & g)``) makes true at
#: every step, so the literal reading only asks for a first grasp. The automaton of
#: Fig. 1 (main loop grasp/assemble) and Spot's reference automaton are those of
#: ``g & G((a -> F g) & (g -> F a))``, the reading shipped here.
#:
#: S2 ("repeatedly grasp two parts O1 and O2 followed by assembling them") says: before
#: the first assembly and between two assemblies both parts are grasped, in either order,
#: and assembly happens again and again.
PAPER_SPECS: dict[str, str] = {
    "S1": "grasp(O1) & G((assemble(R1) -> F grasp(O1)) & (grasp(O1) -> F assemble(R1)))",
    "S2": "(!assemble(R1) U grasp(O1)) & (!assemble(R1) U grasp(O2)) & "
          "G(assemble(R1) -> X((!assemble(R1) U grasp(O1)) & (!assemble(R1) U grasp(O2))))"
          " & G F assemble(R1)",
}

#: Formula (3) exactly as printed in the paper (for comparison; see PAPER_SPECS).
PAPER_FORMULA_3_LITERAL = "grasp(O1) & G(assemble(R1) -> F(grasp(O1)) & grasp(O1) -> " \
                          "F(assemble(R1)))"


def resolve_spec_text(text: str) -> str:
    """The specification text for ``text``: a name of :data:`PAPER_SPECS` or the text."""
    return PAPER_SPECS.get(text.strip(), text)


def _vocabulary_key(vocab: Vocabulary) -> tuple:
    """Everything of ``vocab`` a parse reads, as a hashable value."""
    return (vocab.objects, vocab.regions, tuple(sorted(vocab.shorthands.items())),
            vocab.final_region, vocab.source, tuple(sorted(vocab.inputs.items())))


#: Parsed specifications and shorthand expansions by text and vocabulary (a batch parses
#: the same few specifications in cells whose parts were moved, not renamed).
_SPECIFICATIONS: BoundedCache[Specification] = BoundedCache(64)
_SHORTHAND_ATOMS: BoundedCache[tuple] = BoundedCache(256)


def _shorthand_atoms(task: Atom, vocab: Vocabulary) -> tuple[Atom, ...] | None:
    """Atoms of a shorthand's expansion if it is a conjunction of atoms, else None."""
    def build() -> tuple:
        parts = top_level_conjuncts(parse_spec(task.key, vocab, free_atoms=True).formula)
        return (tuple(parts) if all(isinstance(p, Atom) for p in parts) else None,)

    return _SHORTHAND_ATOMS.get_or_build((task.key, _vocabulary_key(vocab)), build)[0]


def letter_of(task: Atom, cell: object = None) -> frozenset[str]:
    """The word letter of one task step.

    The task's own atom (a shorthand contributes the atoms of its expansion) plus
    ``enter(R)`` for every region R the step puts the body into.

    Raises
    ------
    SpecError
        If a shorthand's body is not a conjunction of tasks (it cannot be one step).
    """
    vocab = vocabulary_from(cell)
    if task.name in vocab.shorthands:
        parts = _shorthand_atoms(task, vocab)
        if parts is None:
            raise SpecError(f"shorthand {task.key} is not a conjunction of tasks, so it "
                            "cannot be a single task step")
        return frozenset().union(*(letter_of(p, vocab) for p in parts))
    letter = {task.key}
    if task.name in ENTERING_TASKS and len(task.args) > ENTERING_TASKS[task.name]:
        letter.add(Atom(REGION_ATOM, (task.args[ENTERING_TASKS[task.name]],)).key)
    return frozenset(letter)


@dataclass(frozen=True)
class Specification:
    """A parsed specification with its always-on conjuncts and candidate task steps.

    Attributes
    ----------
    text : str
    user_formula : Formula
        The formula as written (shorthands expanded).
    always_on : tuple of (str, Formula)
        Labelled conjuncts added automatically.
    tasks : tuple of Task
        Candidate task steps.
    vocabulary : Vocabulary
    inputs : tuple of Atom
        Input propositions of a reactive specification (docs/reactive.md), else empty.
    """

    text: str
    user_formula: Formula
    always_on: tuple[tuple[str, Formula], ...]
    tasks: tuple[Atom, ...]
    vocabulary: Vocabulary = field(repr=False)
    inputs: tuple[Atom, ...] = ()

    @cached_property
    def formula(self) -> Formula:
        """The full formula: user formula and always-on conjuncts."""
        return conj(self.user_formula, *(f for _, f in self.always_on))

    @cached_property
    def letters(self) -> tuple[frozenset[str], ...]:
        """The letter of each candidate task (same order as :attr:`tasks`)."""
        return tuple(letter_of(t, self.vocabulary) for t in self.tasks)

    def labelled_conjuncts(self) -> list[tuple[str, Formula]]:
        """Top-level conjuncts of the user formula and the always-on ones, labelled."""
        user = [(f"conjunct {i + 1} of the specification: {c}", c)
                for i, c in enumerate(top_level_conjuncts(self.user_formula))]
        return user + [(f"{label}: {f}", f) for label, f in self.always_on]


def _exclusivity(task_atoms: list[str], letters: list[frozenset[str]]) -> Formula | None:
    clauses = []
    for i, p in enumerate(task_atoms):
        for q in task_atoms[i + 1:]:
            if not any(p in letter and q in letter for letter in letters):
                clauses.append(Not(And((_atom_from_key(p), _atom_from_key(q)))))
    return Globally(conj(*clauses)) if clauses else None


def _atom_from_key(key: str) -> Atom:
    if key.endswith(")") and "(" in key:
        name, _, rest = key.partition("(")
        return Atom(name, tuple(a.strip() for a in rest[:-1].split(",") if a.strip()))
    return Atom(key)


def build_specification(text: str, cell: object = None, *, free_atoms: bool = False,
                        reactive: bool = False) -> Specification:
    """Parse ``text`` (or a name of :data:`PAPER_SPECS`) and add the always-on conjuncts.

    Parameters
    ----------
    text : str
    cell : CellVocabulary, dict, path or None
    free_atoms : bool
        Accept plain propositions such as ``p0`` (then also candidate task steps).
    reactive : bool
        Accept input propositions (robot events, :attr:`Specification.inputs`).

    Raises
    ------
    SpecError
        For malformed or ill-typed specifications.
    """
    vocab = vocabulary_from(cell)
    text = resolve_spec_text(text)
    return _SPECIFICATIONS.get_or_build(
        (text, bool(free_atoms), bool(reactive), _vocabulary_key(vocab)),
        lambda: _specification(text, vocab, free_atoms, reactive))


def _specification(text: str, vocab: Vocabulary, free_atoms: bool, reactive: bool
                   ) -> Specification:
    """:func:`build_specification` of the resolved ``text`` in ``vocab`` (not cached)."""
    parsed = parse_spec(text, vocab, free_atoms=free_atoms, reactive=reactive)
    tasks: list[Atom] = []
    for task in parsed.tasks:
        if task.name in vocab.shorthands and _shorthand_atoms(task, vocab) is None:
            inner = [a for a in atoms(parse_spec(task.key, vocab, free_atoms=True).formula)
                     if a.name != REGION_ATOM]
            tasks.extend(sorted(inner, key=str))
        else:
            tasks.append(task)
    if free_atoms:
        tasks.extend(sorted((a for a in atoms(parsed.formula) if a.name != REGION_ATOM
                             and a not in tasks and not a.args
                             and a not in parsed.inputs), key=str))
    tasks = list(dict.fromkeys(tasks))
    letters = [letter_of(t, vocab) for t in tasks]
    always_on: list[tuple[str, Formula]] = []
    final = vocab.final_region
    regions = sorted(a.args[0] for a in atoms(parsed.formula)
                     if a.name == REGION_ATOM and a.args)
    for region in dict.fromkeys([*regions, *([final] if final is not None else [])]):
        # a way into every region the specification (or the cell) asks to enter
        if not any(Atom(REGION_ATOM, (region,)).key in letter for letter in letters):
            walk = Atom("walk", (region,))
            tasks.append(walk)
            letters.append(letter_of(walk, vocab))
    task_atoms = sorted({a for letter in letters for a in letter
                         if not a.startswith(REGION_ATOM + "(")})
    excl = _exclusivity(task_atoms, letters)
    if excl is not None:
        always_on.append(("exclusivity (one task per step)", excl))
    if final is not None:
        always_on.append((f"final region {final}", Finally(Atom(REGION_ATOM, (final,)))))
    return Specification(text=text, user_formula=parsed.formula, always_on=tuple(always_on),
                         tasks=tuple(tasks), vocabulary=vocab, inputs=parsed.inputs)
