"""The command line's help reads the same everywhere (issue 35 item 7): every option says
what it does, in lower case without a final period, and shows its default."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from ltl_human_motion.cli import build_parser

#: Help may start with a capital only for a name: an acronym (LTL, ROS, RTDE, ...), or a
#: product (Dask, Spot, URSim).
_NAME_START = re.compile(r"^([A-Z0-9]{2,}|Dask|Spot|URSim)\b")
_FLAGS = (argparse._StoreTrueAction, argparse._StoreFalseAction, argparse._StoreConstAction,
          argparse._AppendConstAction, argparse._HelpAction, argparse._VersionAction)


def _subparsers() -> dict[str, argparse.ArgumentParser]:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def _style(text: str) -> list[str]:
    problems = []
    if text[0].isupper() and not _NAME_START.match(text):
        problems.append("starts with a capital")
    if text.rstrip().endswith("."):
        problems.append("ends with a period")
    return problems


@pytest.mark.parametrize("name", sorted(_subparsers()))
def test_every_option_has_consistent_help_with_its_default(name: str) -> None:
    sub = _subparsers()[name]
    assert sub.description and not _style(sub.description), (name, sub.description)
    problems = []
    for action in sub._actions:
        if isinstance(action, argparse._HelpAction):
            continue
        where = f"{name} {'/'.join(action.option_strings) or action.dest}"
        if not action.help:
            problems.append(f"{where}: no help")
            continue
        problems += [f"{where}: {p}" for p in _style(action.help)]
        shows_default = "default" in action.help.lower()
        if (not isinstance(action, _FLAGS) and action.option_strings and not action.required
                and action.default is not None and not shows_default):
            problems.append(f"{where}: default {action.default!r} not shown")
    assert not problems, "\n".join(problems)


def test_the_demo_says_it_runs_the_study() -> None:
    assert "study" in _subparsers()["demo"].description


def test_stature_shows_its_range_and_keeps_to_it(capsys) -> None:
    from ltl_human_motion.cli import main
    from ltl_human_motion.motion.library import MAX_LIBRARY_STATURE, MIN_LIBRARY_STATURE
    help_text = next(a.help for a in _subparsers()["synthesize"]._actions
                     if "--stature" in a.option_strings)
    assert f"{MIN_LIBRARY_STATURE} to {MAX_LIBRARY_STATURE}" in help_text
    for bad in ("2.2", "1.2", "tall"):
        with pytest.raises(SystemExit) as exc:
            main(["synthesize", "--spec", "F grasp(O1)", "--cell", "paper_cell",
                  "--stature", bad])
        assert exc.value.code == 2
        err = capsys.readouterr().err
        assert "argument --stature" in err and "Traceback" not in err


# ------------------------------------------------------------------ did you mean

@pytest.mark.parametrize("spec, hint", [
    ("F grab(O1)", "unknown task 'grab'; did you mean 'grasp'? expected one of:"),
    ("F asemble(R1)", "did you mean 'assemble'?"),
    ("F grasp(o1)", "unknown object 'o1' in task 'grasp'; did you mean 'O1'?"),
    ("F walk(r1)", "did you mean 'R1'?"),
    ("F grasp(O9)", None),                       # nothing like it: no guess
    ("F jump(R1)", None),
])
def test_unknown_task_and_object_names_get_a_suggestion(spec: str, hint: str | None,
                                                        capsys) -> None:
    from ltl_human_motion.cli import main
    assert main(["tasks", spec, "--cell", "paper_cell"]) == 2
    err = capsys.readouterr().err
    assert "unknown" in err and "expected one of" in err
    if hint is None:
        assert "did you mean" not in err
    else:
        assert hint in err


def test_cell_files_and_names_get_a_suggestion(tmp_path) -> None:
    from ltl_human_motion.errors import CellError
    from ltl_human_motion.scene.cell_yaml import cell_by_name, load_cell
    with pytest.raises(CellError, match="no cell named 'paper_cel'; did you mean 'paper_cell'"):
        cell_by_name("paper_cel")
    path = tmp_path / "c.yaml"
    path.write_text("name: x\nfrmae: zup\n")
    with pytest.raises(CellError, match="frmae: unknown key; did you mean 'frame'"):
        load_cell(path)
    text = (Path(__file__).resolve().parents[1] / "config" / "paper_cell.yaml").read_text()
    path.write_text(text.replace("start_region: R0", "start_region: r0"))
    with pytest.raises(CellError, match="unknown region 'r0'; did you mean 'R0'"):
        load_cell(path)
    path.write_text(text.replace("leftHand(R) & rightHand(R)", "leftHand(R) & rightHnd(R)"))
    with pytest.raises(CellError, match=r"unknown task 'rightHnd'.*; did you mean 'rightHand'"):
        load_cell(path)


def test_did_you_mean() -> None:
    from ltl_human_motion.errors import did_you_mean
    assert did_you_mean("grap", ["grasp", "walk"]) == "did you mean 'grasp'? "
    assert did_you_mean("WALK", ["grasp", "walk"]) == "did you mean 'walk'? "
    assert did_you_mean("walk", ["grasp", "walk"]) == ""
    assert did_you_mean("xyz", ["grasp", "walk"]) == ""
    assert did_you_mean(5, ["grasp"]) == "" and did_you_mean("a", []) == ""


def test_output_into_a_closed_pipe_ends_quietly(tmp_path):
    """`ltl-human-motion ... | head -1`: the command stops without a traceback when its
    reader goes away."""
    import os
    import subprocess
    import sys
    read, write = os.pipe()
    os.close(read)
    proc = subprocess.run([sys.executable, "-m", "ltl_human_motion", "tasks", "S2",
                           "--cell", "paper_cell", "-n", "3"], stdout=write,
                          stderr=subprocess.PIPE, text=True, timeout=120)
    os.close(write)
    assert "Traceback" not in proc.stderr
    assert proc.returncode in (0, 141)


def test_synthesize_out_given_a_file_name_says_it_takes_a_folder(tmp_path, capsys) -> None:
    """`--out motion.npz` made a folder named motion.npz; it is refused before any
    synthesis, with the folder to give instead."""
    from ltl_human_motion.cli import main
    code = main(["synthesize", "--spec", "F grasp(O1)", "--cell", "paper_cell",
                 "--out", str(tmp_path / "grasp.npz")])
    err = capsys.readouterr().err
    assert code == 2 and "give a folder" in err and str(tmp_path / "grasp") in err
    assert not (tmp_path / "grasp.npz").exists()
