"""The cell model for task planning and the product search: preconditions, physically
consistent and cost-optimal first sequences, variations, explanations, the CLI."""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

from ltl_human_motion.cli import main
from ltl_human_motion.errors import SpecError
from ltl_human_motion.ltl import Atom, build_specification, evaluate_lasso
from ltl_human_motion.scene.cell_yaml import cell_from_yaml, load_cell
from ltl_human_motion.tasks import CellModel, Limits, plan_sequences
from ltl_human_motion.tasks.kitting import kitting_cell_yaml, kitting_spec
from ltl_human_motion.tasks.model import HELD, IN_PLACE_WALK_PENALTY
from ltl_human_motion.tasks.product import ProductSearch, product_search
from ltl_human_motion.tasks.sequences import RANDOM_COST_FACTOR

ROOT = Path(__file__).resolve().parents[1]


def _t(text: str) -> Atom:
    name, _, rest = text.partition("(")
    return Atom(name, tuple(a.strip() for a in rest.rstrip(")").split(",") if a.strip()))


def _consistent(tasks, two_handed=frozenset(), fixed=frozenset()) -> None:
    """An independent check of the physical rules: two hands, a part is grasped only when
    not held; release/move/insert/carry fetch a part not held (issue 11: a release of a
    part not in hand grasps it first)."""
    held: list[str] = []
    for t in tasks:
        part = t.args[0] if t.args else None
        width = lambda p: 2 if p in two_handed else 1  # noqa: E731
        if t.name in ("grasp", "move", "insert", "carry", "release") and part not in held:
            assert part not in fixed, f"{t}: a fixed object cannot be held"
            assert sum(map(width, held)) + width(part) <= 2, f"{t}: a third part in two hands"
            held.append(part)
        elif t.name == "grasp":
            raise AssertionError(f"{t}: the part is already in hand")
        if t.name in ("release", "move", "insert"):   # move sets the part down in R
            assert part in held, f"{t}: the part is not held"
            held.remove(part)
        if t.name == "assemble":
            held.clear()


@pytest.fixture(scope="module")
def paper_cell():
    return load_cell(ROOT / "config" / "paper_cell.yaml")


def _kitting(n: int):
    return cell_from_yaml(kitting_cell_yaml(n))


def test_model_preconditions_and_effects():
    cell = cell_from_yaml(kitting_cell_yaml(4).replace(
        "P3: {position", "P3: {two_handed: true, position"))
    m = CellModel.from_cell(cell)
    s = m.initial_state()
    fetched = m.step(s, _t("release(P0)"))                 # not held: fetched first
    assert fetched is not None and fetched[0].held == ()
    assert fetched[1] > m.step(s, _t("grasp(P0)"))[1] + m.durations["release"]
    s1, c1 = m.step(s, _t("grasp(P0)"))
    assert c1 > m.durations["grasp"] and s1.held == (0,)
    assert m.step(s1, _t("grasp(P0)")) is None            # already in hand
    s2, _ = m.step(s1, _t("grasp(P1)"))
    assert m.step(s2, _t("grasp(P2)")) is None            # a third part in two hands
    assert m.step(s2, _t("move(P2, R1)")) is None         # fetching it needs a free hand
    assert m.step(s1, _t("grasp(P3)")) is None            # two-handed: both hands
    s3, _ = m.step(s2, _t("move(P0, R1)"))              # set down in R1, hand free
    assert s3.held == (1,) and s3.location == m.region_location("R1")
    here, cost = m.step(s3, _t("walk(R1)"))              # already there: stands in R1
    assert here == s3 and cost == m.durations["walk"] + IN_PLACE_WALK_PENALTY
    assert m.step(s3, _t("grasp(kit)")) is None           # a fixed object
    assert s3.parts[0] == m.region_location("R1")
    s4, _ = m.step(s3, _t("insert(P1, kit)"))
    assert s4.held == ()
    picked, _ = m.step(s4, _t("grasp(P1)"))       # picked out of the open kit, as planned
    assert picked.held == (1,) and picked.parts[1] == HELD
    s5, _ = m.step(s4, _t("extract(P1, kit)"))
    assert s5.held == (1,)
    seat = m.step(s, _t("sit(P0)"))[0]
    again = m.step(seat, _t("sit(P0)"))                   # sitting again: stays seated
    assert again is not None and again[0].posture == seat.posture
    stand, cost = m.step(seat, _t("standUp"))
    assert cost == m.durations["standUp"]
    assert stand.posture == 0 and m.step(s, _t("standUp"))[0].posture == 0
    assert m.with_limits(Limits(hands=4)).step(s2, _t("grasp(P2)")) is not None


@pytest.mark.parametrize("n", [3, 6, 9])
def test_grasp_each_part_exactly_once_with_the_forced_releases(n):
    seqs, stats = plan_sequences(kitting_spec("grasp_each", n), _kitting(n), n=1)
    tasks = seqs[0].tasks
    grasps = [t for t in tasks if t.name == "grasp"]
    assert sorted(t.args[0] for t in grasps) == sorted(f"P{i}" for i in range(n))
    assert sum(t.name == "release" for t in tasks) == max(0, n - 2)
    _consistent(tasks)
    assert stats.optimal


def test_first_sequence_is_cost_optimal_against_uniform_cost_search():
    for family, n in (("grasp_each", 4), ("move_each", 3), ("response", 3),
                      ("precedence", 4)):
        cell = _kitting(n)
        seqs, stats = plan_sequences(kitting_spec(family, n), cell, n=1)
        spec = build_specification(kitting_spec(family, n), cell)
        # over every candidate release too: dropping the pointless ones loses nothing
        exhaustive, _, _ = product_search(spec, CellModel.from_cell(cell), weight=1.0,
                                             budget=10**6, heuristic=False, releases="all")
        best = exhaustive.lassos(1)[0].cost
        assert stats.costs[0] <= best * 1.01 + 1e-9, family
        _consistent(seqs[0].tasks, fixed={"kit"})


@pytest.mark.parametrize("family,n", [("move_each", 5), ("response", 3),
                                      ("precedence", 4), ("grasp_each", 4)])
def test_heuristic_is_admissible_on_the_states_a_search_reaches(family, n):
    """The A* heuristic (with the trip bound of moves and inserts) never exceeds the
    optimal cost still to go, found by Dijkstra from the node, on sampled nodes."""
    cell = _kitting(n)
    spec = build_specification(kitting_spec(family, n), cell)
    model = CellModel.from_cell(cell)
    search, tasks, _ = product_search(spec, model)
    exact = ProductSearch(search.aut, model, tasks, heuristic=False, budget=10**6)
    q, s, path = search.aut.initial, model.initial_state(), []
    checked = 0
    for depth in range(3 * n):
        s = search.forget(q, s)
        h = search.heuristic(q, s)
        found = exact.lassos(1, start=(tuple(path), q, s, 0.0))
        assert found, (family, depth)
        assert h <= found[0].cost + 1e-9, (family, depth, h, found[0].cost)
        checked += 1
        moves = [(i, nxt[0], q2) for i in range(len(tasks)) if (nxt := search.step(s, i))
                 for q2, _m in search.aut.successors(q, i)]
        start = (7 * depth + 3) % max(1, len(moves))           # a fixed pseudo-random walk
        live = next(((i, s2, q2) for i, s2, q2 in moves[start:] + moves[:start]
                     if exact.lassos(1, start=((*path, i), q2, s2, 0.0))), None)
        if live is None:
            break
        i, s, q = live
        path.append(i)
    assert checked >= min(4, 2 * n)


def test_pointless_releases_are_no_candidates_unless_needed():
    """A release is a candidate step only for a part nothing else sets down."""
    from ltl_human_motion.tasks.product import task_steps
    cell = _kitting(4)
    model = CellModel.from_cell(cell)
    names = lambda text, **kw: {str(t) for t in task_steps(  # noqa: E731
        build_specification(text, cell), model, **kw)[0]}
    assert not any(t.startswith("release") for t in names(kitting_spec("move_each", 4)))
    assert "release(P0)" in names(kitting_spec("move_each", 4), releases="all")
    mixed = names("F grasp(P0) & F grasp(P1) & F grasp(P2) & F move(P2, R1)")
    assert {"release(P0)", "release(P1)"} <= mixed and "release(P2)" not in mixed


def test_move_each_part_to_the_tray_carries_two_at_a_time():
    seqs, _ = plan_sequences(kitting_spec("move_each", 4), _kitting(4), n=1)
    tasks = seqs[0].tasks
    assert sorted(t.args[0] for t in tasks if t.name == "move") == ["P0", "P1", "P2", "P3"]
    trips = sum(1 for prev, t in zip((None, *tasks[:-1]), tasks)   # arrivals at the tray
                if t.name == "move" and (prev is None or prev.name not in ("move", "release")))
    assert trips == 2                    # two parts per walk to the tray
    _consistent(tasks)


def test_paper_specs_give_the_main_loops(paper_cell):
    s1, _ = plan_sequences("S1", paper_cell, n=1)
    assert s1[0].tasks == (_t("grasp(O1)"), _t("assemble(R1)"))
    s2, _ = plan_sequences("S2", paper_cell, n=1)
    assert set(s2[0].tasks) == {_t("grasp(O1)"), _t("grasp(O2)"), _t("assemble(R1)")}
    assert len(s2[0].tasks) == 3


@pytest.mark.parametrize("mode", ["random", "all", "coverage"])
def test_variations_are_consistent_checked_and_cheap(paper_cell, mode):
    seqs, stats = plan_sequences("S2", paper_cell, n=4, mode=mode, seed=5, cycles=2)
    assert seqs and len(stats.costs) >= len(seqs)
    spec = build_specification("S2", paper_cell)
    for s in seqs:
        assert evaluate_lasso(spec.formula, *s.lasso(paper_cell))
        _consistent(s.tasks)
    if mode == "random":
        assert all(c <= RANDOM_COST_FACTOR * stats.costs[0] + 1e-9 for c in stats.costs)
    if mode == "all":
        assert stats.costs[:len(seqs)] == sorted(stats.costs[:len(seqs)])
    again, _ = plan_sequences("S2", paper_cell, n=4, mode=mode, seed=5, cycles=2)
    assert [str(s) for s in again] == [str(s) for s in seqs]


def test_three_parts_in_hand_is_explained():
    text = ("F(grasp(P0) & X F(grasp(P1) & X F grasp(P2))) & G !release(P0) & "
            "G !release(P1) & G !release(P2)")
    with pytest.raises(SpecError) as err:
        plan_sequences(text, _kitting(3), n=1)
    msg = str(err.value)
    assert "satisfiable" in msg and "2 hands" in msg and "unsatisfiable" not in msg
    assert "G !release(P0)" in msg and "conjunct" in msg


def test_cli_tasks_uses_the_cell_model(capsys, tmp_path):
    path = tmp_path / "kit.yaml"
    path.write_text(kitting_cell_yaml(4))
    assert main(["tasks", kitting_spec("grasp_each", 4), "--cell", str(path), "-n", "1"]) == 0
    out = capsys.readouterr().out
    first = next(line for line in out.splitlines() if line.startswith("1: "))
    assert first.count("grasp(") == 4 and first.count("release(") == 2
    assert "estimated time" in out


def test_explicit_automaton_view_gives_the_same_optimum(paper_cell):
    """The product with an explicit automaton (the built-in translator's, as Spot's would
    be with backend="spot") finds lassos of the same cost as the on-the-fly tableau."""
    from ltl_human_motion.ltl import translate
    from ltl_human_motion.tasks import ExplicitView, ProductSearch
    from ltl_human_motion.tasks.product import task_steps
    for name in ("S1", "S2"):
        spec = build_specification(name, paper_cell)
        model = CellModel.from_cell(paper_cell)
        tasks, letters = task_steps(spec, model)
        view = ExplicitView(translate(spec.formula, backend="builtin"), letters)
        explicit = ProductSearch(view, model, tasks).lassos(1)[0]
        onthefly, _, _ = product_search(spec, model)
        assert explicit.cost == pytest.approx(onthefly.lassos(1)[0].cost)
        assert evaluate_lasso(spec.formula, [letters[i] for i in explicit.prefix],
                              [letters[i] for i in explicit.cycle])


SPOT_REFERENCE = Path(__file__).resolve().parents[2] / "shared" / "data" / "spot-reference"
if not SPOT_REFERENCE.is_dir():
    SPOT_REFERENCE = Path("/work/shared/data/spot-reference")


@pytest.mark.skipif(not (SPOT_REFERENCE / "S1_formula3.hoa").is_file(),
                    reason="shared/data/spot-reference not present")
def test_spots_own_automaton_gives_the_same_sequences(paper_cell):
    """Issue 16, must-have 5: with Spot's automaton (Spot 2.12.1's output for the paper's
    formula (3), stored as HOA; its propositions g, a renamed to the tasks) the product
    search finds a lasso of the same cost as with ours, and physically consistent: no
    grasp of the part in hand (the Spot backend used to give grasp(O1), grasp(O1), ...)."""
    from ltl_human_motion.ltl import automaton_from_hoa, parse, translate
    from ltl_human_motion.tasks import ExplicitView
    from ltl_human_motion.tasks.product import task_steps
    hoa = (SPOT_REFERENCE / "S1_formula3.hoa").read_text()
    hoa = hoa.replace('"g"', '"grasp(O1)"').replace('"a"', '"assemble(R1)"')
    spot = automaton_from_hoa(hoa)
    formula = parse("grasp(O1) & G((assemble(R1) -> F grasp(O1)) & "
                    "(grasp(O1) -> F assemble(R1)))", free_atoms=True)
    spec = build_specification("S1", paper_cell)
    model = CellModel.from_cell(paper_cell)
    tasks, _ = task_steps(spec, model)
    letters = [frozenset({str(t)}) for t in tasks]        # one task per step, as Spot's
    ours = ProductSearch(ExplicitView(translate(formula, backend="builtin"), letters),
                         model, tasks).lassos(1)[0]
    lasso = ProductSearch(ExplicitView(spot, letters), model, tasks).lassos(1)[0]
    assert lasso.cost == pytest.approx(ours.cost)
    words = [[letters[i] for i in part] for part in (lasso.prefix, lasso.cycle)]
    assert evaluate_lasso(formula, *words)
    steps = [tasks[i] for i in (*lasso.prefix, *lasso.cycle)]
    names = [str(t) for t in steps]
    assert "grasp(O1)" in names and "assemble(R1)" in names
    assert all(a != b for a, b in itertools.pairwise(names)), names


def test_kitting_cell_synthesizes_a_verified_motion_end_to_end():
    """Three parts to the kit tray in config/kitting_cell.yaml: cell-model sequence,
    planner, blending and every verification check (bench/README: all ten parts)."""
    from ltl_human_motion.planning.pipeline import synthesize
    spec = "F move(P0, R1) & F move(P1, R1) & F move(P5, R1)"
    motion = synthesize(spec, str(ROOT / "config" / "kitting_cell.yaml"), variants=1)[0]
    assert motion.verification["passed"]
    moves = [t for t in motion.sequence if t.startswith("move(")]
    assert sorted(moves) == ["move(P0, R1)", "move(P1, R1)", "move(P5, R1)"]
    assert motion.stats.sequence_time > 0.0


def test_inserts_into_the_kit_tray_verify_and_a_flush_tray_is_refused_early(monkeypatch):
    """Four parts into the kit (the response family): the parts come to rest inside the
    tray and Table I's enclose holds. A tray exactly as deep as the parts leaves no room
    (a placed part would hold enclose only to rounding, as the 10-part run showed): it is
    refused before any search, naming the axis and the clearance."""
    from ltl_human_motion.errors import PlanningError
    from ltl_human_motion.planning import steps as steps_mod
    from ltl_human_motion.planning.pipeline import synthesize
    spec = kitting_spec("response", 4)
    motion = synthesize(spec, kitting_cell_yaml(4), variants=1)[0]
    assert motion.verification["passed"]
    assert sum(t.startswith("insert(") for t in motion.sequence) == 4
    flush = kitting_cell_yaml(4).replace("position: [0.0, -1.85, 0.94], shape: box, "
                                         "size: [0.35, 0.25, 0.08]",
                                         "position: [0.0, -1.85, 0.93], shape: box, "
                                         "size: [0.35, 0.25, 0.06]")
    assert flush != kitting_cell_yaml(4)

    def no_search(*_a, **_k):
        raise AssertionError("searched")
    monkeypatch.setattr(steps_mod, "astar", no_search)      # the planner's A*
    with pytest.raises(PlanningError, match=r"container kit leaves P\d 0.000 m of room "
                       r"along z \(at least 0.002 m, FIT_CLEARANCE") as info:
        synthesize(spec, flush, variants=1)
    assert info.value.reason == "size"


def test_recurrences_over_few_parts_give_a_cycle_with_each_grasp():
    """G F over five parts: the cycle (longer than the default tails) grasps each part,
    with the releases two hands force, and is physically consistent."""
    n = 5
    text = " & ".join(f"G F grasp(P{i})" for i in range(n))
    seqs, _ = plan_sequences(text, _kitting(n), n=1)
    cycle = seqs[0].cycle
    assert sorted(t.args[0] for t in cycle if t.name == "grasp") == [f"P{i}" for i in range(n)]
    _consistent(seqs[0].tasks)


def test_recurrences_over_many_parts_are_refused_before_any_search(monkeypatch):
    from ltl_human_motion.tasks.product import ProductSearch as Search
    from ltl_human_motion.tasks.recurrence import MAX_RECURRENCES

    def no_search(*_a, **_k):
        raise AssertionError("searched")
    monkeypatch.setattr(Search, "lassos", no_search)
    n = MAX_RECURRENCES + 2
    text = " & ".join(f"G F grasp(P{i})" for i in range(n))
    with pytest.raises(SpecError, match=f"needs {n} different tasks again and again"):
        plan_sequences(text, _kitting(n), n=1)


@pytest.mark.parametrize("family", ["grasp_each", "move_each", "response"])
def test_twenty_part_kitting_is_answered_cost_optimally(family):
    """With the trip bound and ties broken deepest-first, the optimal A* (weight 1)
    answers 20-part kitting within its first budget; the sequence is consistent."""
    seqs, stats = plan_sequences(kitting_spec(family, 20), _kitting(20), n=1)
    assert stats.optimal, stats.weight
    _consistent(seqs[0].tasks, fixed={"kit"})
    done = {t.args[0] for t in seqs[0].tasks if t.name in ("grasp", "move", "insert")}
    assert done == {f"P{i}" for i in range(20)}


def test_equal_costs_prefer_fewer_steps():
    """A move fetches its part itself: no separate grasp before it at the same cost
    (summed in another order, the two costs differed in the last bits)."""
    cell = load_cell(ROOT / "config" / "demo_cell.yaml")
    seqs, stats = plan_sequences("F(move(O1, R0) & F grasp(O1))", cell, n=1)
    assert [str(t) for t in seqs[0].prefix[:2]] == ["move(O1, R0)", "grasp(O1)"]
    assert stats.optimal
