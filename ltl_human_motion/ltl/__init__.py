"""LTL task specifications: formulas, parser, translators, automata, lasso checker and
task sequences (core, no ROS).

Typical use::

    from ltl_human_motion.ltl import synthesize_sequences
    seqs = synthesize_sequences("S1", cell, n=5, seed=1)
"""

from ltl_human_motion.ltl.automaton import Automaton, Cube, Edge, degeneralize
from ltl_human_motion.ltl.dot import dot_from_automaton
from ltl_human_motion.ltl.evaluator import evaluate_lasso, evaluate_positions
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
    atoms,
    to_spot,
)
from ltl_human_motion.ltl.hoa import HoaError, automaton_from_hoa, hoa_from_automaton
from ltl_human_motion.ltl.parser import ParsedSpec, parse, parse_spec
from ltl_human_motion.ltl.sequences import (
    MODES,
    TaskSequence,
    synthesize_sequences,
    task_automaton,
    unsat_core,
)
from ltl_human_motion.ltl.simplify import nnf, simplify
from ltl_human_motion.ltl.spec import (
    PAPER_SPECS,
    Specification,
    Task,
    build_specification,
    letter_of,
)
from ltl_human_motion.ltl.translate import BACKENDS, translate
from ltl_human_motion.ltl.translate_spot import spot_available
from ltl_human_motion.ltl.vocabulary import (
    TASK_SIGNATURES,
    CellVocabulary,
    Vocabulary,
    load_vocabulary,
    vocabulary_from,
)

__all__ = [
    "BACKENDS", "FALSE", "MODES", "PAPER_SPECS", "TASK_SIGNATURES", "TRUE", "And", "Atom",
    "Automaton", "CellVocabulary", "Const", "Cube", "Edge", "Equiv", "Finally", "Formula",
    "Globally", "HoaError", "Implies", "Next", "Not", "Or", "ParsedSpec", "Release",
    "Specification", "StrongRelease", "Task", "TaskSequence", "Until", "Vocabulary",
    "WeakUntil", "Xor", "atoms", "automaton_from_hoa", "build_specification", "degeneralize",
    "dot_from_automaton", "evaluate_lasso", "evaluate_positions", "hoa_from_automaton",
    "letter_of", "load_vocabulary", "nnf", "parse", "parse_spec", "simplify",
    "spot_available", "synthesize_sequences", "task_automaton", "to_spot", "translate",
    "unsat_core", "vocabulary_from",
]
