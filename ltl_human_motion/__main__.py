"""``python -m ltl_human_motion`` runs the CLI."""

import sys

from ltl_human_motion.cli import interrupts

interrupts.install()            # before the imports below: a Ctrl-C during them counts

from ltl_human_motion.cli import main  # noqa: E402

sys.exit(main())
