"""``python -m ltl_human_motion`` runs the CLI."""

import sys

from ltl_human_motion.cli import main

sys.exit(main())
