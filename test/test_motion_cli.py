"""``ltl-human-motion library`` (builds the library, writes the report and the plot) and
``ltl-human-motion synthesize``."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ltl_human_motion.cli import build_parser, main


def test_library_command_writes_report_and_plot(tmp_path: Path, capsys) -> None:
    report, plot = tmp_path / "report.json", tmp_path / "graph.png"
    rc = main(["library", "--cache-dir", str(tmp_path / "cache"), "--report", str(report),
               "--plot", str(plot)])
    assert rc == 0
    out = capsys.readouterr().out
    assert "gait primitives" in out and "quality gait" in out
    data = json.loads(report.read_text())
    assert data["quality"]["ok"] is True
    s = data["summary"]
    assert s["primitives"] == s["walk"] + s["carry"] and s["edges"] > s["primitives"]
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # second run: from the cache, JSON summary on stdout
    rc = main(["library", "--cache-dir", str(tmp_path / "cache"), "--json"])
    assert rc == 0
    assert json.loads(capsys.readouterr().out)["key"] == s["key"]


def test_library_command_reports_user_errors(tmp_path: Path, capsys) -> None:
    rc = main(["library", "--cache-dir", str(tmp_path), "--source", str(tmp_path / "none")])
    assert rc == 2
    assert "does not exist" in capsys.readouterr().err
    rc = main(["library", "--cache-dir", str(tmp_path), "--stature", "2.5"])
    assert rc == 2
    assert "stature must be between" in capsys.readouterr().err
    bad = tmp_path / "broken"
    bad.mkdir()
    (bad / "walk.bvh").write_text("HIERARCHY\nROOT Hips\n{\n")
    rc = main(["library", "--cache-dir", str(tmp_path), "--source", str(bad), "--no-cache"])
    assert rc == 2
    err = capsys.readouterr().err
    assert "walk.bvh" in err and "MOTION" in err


def test_library_parser_has_options() -> None:
    args = build_parser().parse_args(["library", "--stature", "1.6", "--delta", "0.3"])
    assert args.stature == 1.6 and args.delta == 0.3
    with pytest.raises(SystemExit):
        build_parser().parse_args(["library", "--stature", "tall"])


def test_synthesize_command_verifies_with_the_biomechanical_checks_unless_told(
        tmp_path: Path, capsys) -> None:
    rc = main(["synthesize", "--cell", "paper_cell", "--spec", "S1", "--out",
               str(tmp_path / "on")])
    assert rc == 0
    out = capsys.readouterr().out
    assert "verified: yes" in out
    checks = json.loads(out[out.index("{"):])["motions"][0]["verification"]
    assert checks["foot_skate"] and checks["joint_speed"] and checks["self_penetration"]
    assert (tmp_path / "on" / "motion_000.npz").is_file()
    rc = main(["synthesize", "--cell", "paper_cell", "--spec", "S1", "--out",
               str(tmp_path / "off"), "--no-biomechanics"])
    out = capsys.readouterr().out
    checks = json.loads(out[out.index("{"):])["motions"][0]["verification"]
    assert rc == 0 and checks["collision"] and "foot_skate" not in checks


def test_synthesize_command_says_when_the_motion_was_made_in_another_order(
        tmp_path: Path, capsys) -> None:
    """A 1.95 m worker in the bins cell: the first order's motion slides a foot 0.16 m/s
    (foot_skate); the next order's verifies, and the command says so."""
    cell = Path(__file__).resolve().parents[1] / "scenarios" / "cells" / "bins.yaml"
    spec = ("F((grasp(O1)) & F (assemble(R2))) & F (extract(O2, bin_b)) & "
            "G(((grasp(O1)) & !(assemble(R2)) & F (assemble(R2))) -> "
            "(!(extract(O2, bin_b)) U (assemble(R2))))")
    rc = main(["synthesize", "--cell", str(cell), "--spec", spec, "--stature", "1.95",
               "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert rc == 0 and "verified: yes" in out
    assert "(made in another order of the tasks: 1 failed before it, the first: " \
           "verification failed (foot_skate)" in out
    stats = json.loads(out[out.index("{"):])["motions"][0]["stats"]
    assert stats["orders_failed"] == 1 and stats["first_failure"].startswith(
        "verification failed (foot_skate): foot_skate: left foot slides")
