"""Messages whose numbers disagreed with themselves (issue 35, item 4): each now says what
its number is and against which limit."""

from __future__ import annotations

from ltl_human_motion.cli.coexist import _breaches
from ltl_human_motion.cli.demo import _comparison_words, _status
from ltl_human_motion.cli.library import _print_quality
from ltl_human_motion.planning.steps import _approach


def test_a_walk_that_reached_the_goal_area_does_not_read_as_success() -> None:
    assert "0.00 m" not in _approach(0.0)
    assert "reached the goal's floor area but found no place there to stop" in _approach(0.0)
    assert _approach(0.734) == "it came no nearer than 0.73 m to the goal's floor area"


def _run(intervals: list[dict]) -> dict:
    return {"protective_distance": 0.55, "violation_intervals": intervals,
            "violation_time": sum(v["end"] - v["start"] for v in intervals)}


def test_coexistence_breaches_say_when_how_close_and_what_the_robot_did() -> None:
    lines = _breaches(_run([
        {"start": 3.2, "end": 11.06, "min_separation": 0.31, "max_slider": 0.01,
         "slowed_to_min": True},
        {"start": 20.0, "end": 20.5, "min_separation": 0.5, "max_slider": 0.4,
         "slowed_to_min": False}]))
    assert lines[0] == ("the worker was closer than S_p = 0.55 m 2 time(s), 8.4 s in all:")
    assert "t = 3.2-11.1 s: down to 0.31 m from the arm; the robot stood still" in lines[1]
    assert "1% minimum, which stands for stop" in lines[1]
    assert "the robot was not stopped: it moved at up to 40% of its programmed speed" \
        in lines[2]
    assert _breaches(_run([])) == ["the worker never came closer than S_p = 0.55 m"]


def test_demo_status_is_not_a_plain_ok_with_a_warning() -> None:
    assert _status({"ok": True}) == "ok"
    assert _status({"ok": True, "warning": "missed 72 deadlines"}) == "ok but"
    assert _status({"ok": False, "warning": "x"}) == "FAILED"


def test_the_demos_study_line_names_what_differs_between_the_layouts() -> None:
    """It read "1 figure(s) differ", which sounded like a failed picture comparison."""
    words = _comparison_words({"min_separation": {"diff": 0.109, "ci95": [0.069, 0.1496],
                                                  "significant": True}})
    assert words == ("; B - A: minimum human-robot separation +0.109 m "
                     "(95% CI +0.069 .. +0.15)")
    assert _comparison_words({}) == "; A and B alike"


def test_library_quality_names_each_limit(capsys) -> None:
    _print_quality("gait", {"passed": 1028, "count": 1028, "thresholds": {"foot_skate": 0.5},
                            "worst": {"bone_length": 1e-6, "floor": 0.017,
                                      "foot_skate": 0.42, "joint_speed": 4.77}})
    out = capsys.readouterr().out
    assert "1028/1028 primitives within the per-primitive limits" in out
    assert "foot skate 0.42 m/s (0.50: a primitive alone" in out
    assert "skate held to 0.03 m/s" in out
