"""Task sequences for the paper's S1/S2, variation modes, always-on conjuncts,
unsatisfiable specifications and the ``tasks`` CLI subcommand."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ltl_human_motion.cli import main
from ltl_human_motion.errors import SpecError
from ltl_human_motion.ltl import (
    Atom,
    TaskSequence,
    automaton_from_hoa,
    build_specification,
    evaluate_lasso,
    hoa_from_automaton,
    letter_of,
    parse,
    synthesize_sequences,
    task_automaton,
)
from ltl_human_motion.ltl.sequences import _canonical, _LetterGraph

CELL = {"objects": ["O1", "O2"], "regions": ["R0", "R1"],
        "shorthands": {"assemble": (("R",), "leftHand(R) & rightHand(R)")},
        "final_region": "R1"}
G1, G2, A = Atom("grasp", ("O1",)), Atom("grasp", ("O2",)), Atom("assemble", ("R1",))


def _check_all(seqs, spec):
    for s in seqs:
        prefix, cycle = s.lasso(CELL)
        assert evaluate_lasso(spec.formula, prefix, cycle)
        assert s.tasks == s.prefix + s.cycle * s.repetitions


def test_letters_and_always_on_conjuncts():
    assert letter_of(A, CELL) == {"leftHand(R1)", "rightHand(R1)", "enter(R1)"}
    assert letter_of(Atom("carry", ("O1", "R0")), CELL) == {"carry(O1, R0)", "enter(R0)"}
    spec = build_specification("S1", CELL)
    labels = [label for label, _ in spec.always_on]
    assert labels == ["exclusivity (one task per step)", "final region R1"]
    excl = spec.always_on[0][1]
    # the paper's G !(a & g): g excludes both hands, the hands may go together
    assert evaluate_lasso(excl, [], [letter_of(A, CELL)])
    assert not evaluate_lasso(excl, [], [{"grasp(O1)", "leftHand(R1)"}])
    assert spec.tasks == (G1, A)
    other = build_specification("F grasp(O2)", CELL)
    assert Atom("walk", ("R1",)) in other.tasks  # adds a way into the final region


def test_s1_gives_the_paper_main_loop_grasp_then_assemble():
    spec = build_specification("S1", CELL)
    seqs = synthesize_sequences(spec, n=4, mode="all")
    assert seqs[0] == TaskSequence((), (G1, A), 1, seqs[0].letter_map)
    assert seqs[0].tasks == (G1, A)
    assert synthesize_sequences(spec, n=1, mode="all", cycles=3)[0].tasks == (G1, A) * 3
    assert len(synthesize_sequences(spec, n=1, mode="all", min_steps=7)[0].tasks) == 8
    for mode in ("all", "coverage", "random"):
        seqs = synthesize_sequences(spec, n=8, seed=2, mode=mode)
        _check_all(seqs, spec)
        assert all(s.tasks[0] == G1 for s in seqs)  # S1 starts by grasping


def test_literal_formula_3_degenerates_under_the_stated_precedence():
    literal = build_specification(
        "grasp(O1) & G(assemble(R1) -> F(grasp(O1)) & grasp(O1) -> F(assemble(R1)))", CELL)
    # accepts grasping once and then assembling forever, which S1 forbids
    word = ([letter_of(G1, CELL)], [letter_of(A, CELL)])
    assert evaluate_lasso(literal.formula, *word)
    assert not evaluate_lasso(build_specification("S1", CELL).formula, *word)


def test_s2_grasps_both_parts_in_both_orders_before_assembly():
    spec = build_specification("S2", CELL)
    for mode in ("all", "coverage", "random"):
        seqs = synthesize_sequences(spec, n=12, seed=1, mode=mode)
        _check_all(seqs, spec)
        firsts = set()
        for s in seqs:
            tasks = list(s.prefix + s.cycle * 2)
            firsts.add(tasks[0])
            last = -1  # position of the previous assembly
            for i, t in enumerate(tasks):
                if t == A:  # both parts grasped since the previous assembly
                    assert {G1, G2} <= set(tasks[last + 1:i])
                    last = i
            assert last >= 0
        assert firsts == {G1, G2}, mode
    shortest = synthesize_sequences(spec, n=2, mode="all")
    assert {s.cycle for s in shortest} == {(G1, G2, A), (G2, G1, A)}


def test_same_seed_same_output_and_seeds_vary():
    runs = [synthesize_sequences("S2", CELL, n=5, seed=s, mode="random") for s in (4, 4, 5)]
    assert runs[0] == runs[1]
    assert runs[0] != runs[2]


def test_coverage_set_covers_every_useful_transition():
    spec = build_specification("S2", CELL)
    aut = task_automaton(spec, "builtin")
    seqs = synthesize_sequences(spec, n=None, mode="coverage", backend="builtin")
    graph = _LetterGraph(aut, spec.letters, allow_empty=False)
    useful = {a.edge for q in graph.useful for a in graph.out[q]}
    covered = set()
    for s in seqs:  # replay each lasso on the automaton, collecting the edges it can use
        prefix, cycle = s.lasso(CELL)
        word = prefix + cycle * (len(aut.edges) + 2)
        states = {aut.initial}
        for letter in word:
            nxt = set()
            for q in states:
                for k, e in enumerate(aut.edges):
                    if e.src == q and e.guard.satisfied_by(letter) and e.dst in graph.useful:
                        covered.add(k)
                        nxt.add(e.dst)
            states = nxt
    assert useful <= covered


def test_canonical_lasso_rolls_prefix_and_shortens_cycle():
    assert _canonical([0], [1, 0]) == ((), (0, 1))
    assert _canonical([2, 0, 1], [0, 1, 0, 1]) == ((2,), (0, 1))


def test_unsatisfiable_spec_names_a_small_conflicting_core():
    with pytest.raises(SpecError) as info:
        synthesize_sequences("F grasp(O2) & G F assemble(R1) & G !grasp(O2)", CELL)
    text = str(info.value)
    assert "unsatisfiable" in text and "F grasp(O2) & G F assemble(R1)" in text
    assert "G !grasp(O2)" in text and "G F" not in text.split("conflict:")[1]
    with pytest.raises(SpecError, match="no sequence of task steps"):
        synthesize_sequences("G grasp(O1)", CELL)  # F enter(R1) needs another step


def test_bad_arguments_raise_value_error():
    with pytest.raises(ValueError, match="mode"):
        synthesize_sequences("S1", CELL, mode="bfs")
    with pytest.raises(ValueError, match="cycles"):
        synthesize_sequences("S1", CELL, cycles=0)


def test_free_atoms_specs_synthesize_without_a_cell():
    f = "G(p0 -> X p1) & G F p0"
    seqs = synthesize_sequences(f, n=3, mode="all", free_atoms=True)
    assert seqs[0].cycle == (Atom("p0"), Atom("p1"))
    assert all(evaluate_lasso(parse(f, free_atoms=True), *s.lasso()) for s in seqs)


@pytest.fixture()
def cell_file(tmp_path: Path) -> Path:
    path = tmp_path / "cell.yaml"
    path.write_text("objects: [O1, O2]\nregions: [R0, R1]\nstart_region: R0\n"
                    "final_region: R1\nshorthands:\n  assemble: {params: [R], body: "
                    "'leftHand(R) & rightHand(R)'}\n")
    return path


@pytest.fixture()
def paper_cell(cell_file: Path) -> str:
    """config/paper_cell.yaml (read by the scene module), else the minimal file."""
    path = Path(__file__).resolve().parents[1] / "config" / "paper_cell.yaml"
    return str(path if path.is_file() else cell_file)


def test_cli_prints_sequences_json_and_automata(capsys, paper_cell):
    cell = paper_cell
    assert main(["tasks", "S1", "--cell", cell, "-n", "2", "--seed", "1", "--mode", "all"]) == 0
    out = capsys.readouterr().out
    assert "1: grasp(O1) -> assemble(R1)\n" in out
    assert main(["tasks", "S2", "--cell", cell, "-n", "3", "--json", "--mode", "coverage"]) == 0
    data = json.loads(capsys.readouterr().out)
    # a covering set of at most n (S2's product is covered by two lassos)
    assert 1 <= len(data["sequences"]) <= 3 and "assemble(R1)" in data["sequences"][0]["tasks"]
    assert main(["tasks", "S1", "--cell", cell, "--automaton", "hoa", "--backend",
                 "builtin"]) == 0
    assert capsys.readouterr().out.startswith("HOA: v1")
    assert main(["tasks", "S1", "--cell", cell, "--automaton", "dot", "--state-based"]) == 0
    assert "doublecircle" in capsys.readouterr().out


def test_cli_summarises_a_long_exclusivity_conjunct(capsys):
    """Six tasks in the kitting cell give 15 exclusivity clauses: one summary line (the
    JSON keeps the whole formula); S1's two clauses stay printed in full."""
    cell = str(Path(__file__).resolve().parents[1] / "scenarios" / "cells" / "kitting.yaml")
    spec = ("F grasp(gear) & F grasp(bolt) & F insert(gear, kit_c) & F insert(bolt, kit_c)"
            " & F move(gear, R_cart)")
    assert main(["tasks", spec, "--cell", cell, "-n", "1"]) == 0
    header = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("# always")]
    assert header[0].startswith("# always on: exclusivity (one task per step): G !(p & q) "
                                "for 15 pairs of tasks, e.g. !(grasp(bolt) & grasp(gear))")
    assert header[1] == "# always on: final region R_line: F enter(R_line)"
    assert all(len(ln) < 200 for ln in header)
    assert main(["tasks", spec, "--cell", cell, "-n", "1", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["formula"].count("!(") == 15


@pytest.mark.parametrize(("spec", "fragment"), [
    ("grasp(O9)", "unknown object 'O9'"),
    ("G(grasp(O1)", "expected ')'"),
    ("G grasp(O1) & F grasp(O2)", "unsatisfiable"),
])
def test_cli_errors_are_one_message_without_traceback(capsys, paper_cell, spec, fragment):
    assert main(["tasks", spec, "--cell", paper_cell]) == 2
    err = capsys.readouterr().err
    assert fragment in err and "Traceback" not in err


@pytest.fixture()
def no_scene_loader(monkeypatch):
    """Hide ltl_human_motion.scene.cell so the minimal YAML reader is used."""
    import builtins
    real_import = builtins.__import__

    def no_scene(name, *args, **kwargs):
        if name == "ltl_human_motion.scene.cell":
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_scene)


def test_cli_minimal_yaml_reader_and_missing_cell(capsys, cell_file, no_scene_loader):
    assert main(["tasks", "S1", "--cell", str(cell_file), "-n", "1", "--mode", "all"]) == 0
    assert "grasp(O1) -> assemble(R1)" in capsys.readouterr().out
    assert main(["tasks", "S1", "--cell", str(cell_file) + ".missing"]) == 2
    assert "cell file not found" in capsys.readouterr().err


def test_enter_atoms_get_a_walk_step_and_no_task_steps_are_checked():
    seqs = synthesize_sequences("F enter(R0) & G F grasp(O1)", CELL, n=3, mode="all")
    assert Atom("walk", ("R0",)) in seqs[0].tasks and Atom("walk", ("R1",)) in seqs[0].tasks
    # p0 must be followed by a step without p0: only a no-task step fits, and dropping it
    # would break the specification, so the synthesizer refuses instead of lying
    with pytest.raises(SpecError, match="without a task"):
        synthesize_sequences("G(p0 -> X !p0) & G F p0", n=2, free_atoms=True)


def test_sequences_from_an_imported_hoa_automaton(tmp_path, capsys, no_scene_loader):
    spec = build_specification("S1", CELL)
    text = hoa_from_automaton(task_automaton(spec, "builtin"))
    seqs = synthesize_sequences(spec, n=3, mode="all", automaton=automaton_from_hoa(text))
    assert seqs[0].tasks == (G1, A)
    # an automaton for a weaker formula: its runs that break S1 are filtered out
    weak = automaton_from_hoa(hoa_from_automaton(task_automaton(
        build_specification("G F grasp(O1) & G F assemble(R1)", CELL), "builtin")))
    for s in synthesize_sequences(spec, n=5, mode="all", automaton=weak):
        assert evaluate_lasso(spec.formula, *s.lasso()) and s.tasks[0] == G1
    path = tmp_path / "s1.hoa"
    path.write_text(text)
    cell = tmp_path / "cell.yaml"
    cell.write_text("objects: [O1, O2]\nregions: [R0, R1]\nfinal_region: R1\nshorthands:\n"
                    "  assemble: {params: [R], body: 'leftHand(R) & rightHand(R)'}\n")
    assert main(["tasks", "S1", "--cell", str(cell), "--hoa", str(path), "-n", "1",
                 "--mode", "all"]) == 0
    assert "1: grasp(O1) -> assemble(R1)" in capsys.readouterr().out
    assert main(["tasks", "S1", "--cell", str(cell), "--hoa", str(path) + "x"]) == 2
    assert "cannot read HOA file" in capsys.readouterr().err
