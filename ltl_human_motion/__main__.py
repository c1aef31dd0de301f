"""``python -m ltl_human_motion`` runs the CLI."""

from ltl_human_motion.cli import interrupts

interrupts.install()            # before the imports below: a Ctrl-C during them counts

from ltl_human_motion.cli import run  # noqa: E402

run()
