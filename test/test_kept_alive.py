"""kernel.kept_alive: a process holding an object that must not be destroyed ends with
its exit status and its output flushed, past the interpreter's teardown."""

from __future__ import annotations

import subprocess
import sys
import textwrap

SCRIPT = textwrap.dedent("""
    import logging, sys
    from ltl_human_motion.kernel.kept_alive import end_if_kept, keep_alive_forever
    logging.basicConfig(stream=sys.stderr, level=logging.INFO)
    end_if_kept(5)                                 # nothing kept: returns
    print("still running", end="")                 # buffered, not flushed yet
    logging.getLogger("t").warning("kept")
    keep_alive_forever(object())
    end_if_kept(3)
    print("never printed")
""")


def test_ends_with_the_code_and_flushed_output_once_an_object_is_kept() -> None:
    proc = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 3, proc.stderr
    assert proc.stdout == "still running"
    assert "kept" in proc.stderr and "Traceback" not in proc.stderr
