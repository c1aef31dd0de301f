"""Cell studies: many verified variants of a task in one or two cell layouts, scored for
ergonomics, cycle time and safety against the robot, with a report (JSON, PNG, HTML)."""

from ltl_human_motion.study.runner import StudyConfig, run_study

__all__ = ["StudyConfig", "run_study"]
