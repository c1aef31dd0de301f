"""The synthesis service with the real pipeline (``planning.synthesize``) over real DDS.

A module of its own: the scripted server of test_ros_synthesis.py must be gone, or two
servers would answer on ``/synthesize_motion``.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from ltl_human_motion.srv import SynthesizeMotion
from ros_fakes import SYNTHESIS_ONLY_BRINGUP

from ltl_human_motion.ros.bringup import Bringup
from ltl_human_motion.ros.client import ClientSession
from ltl_human_motion.ros.launch_support.bringup_config import load_bringup_config

pytestmark = [pytest.mark.ros, pytest.mark.slow]

SERVICE = "/synthesize_motion"
BAD_SPEC = "grasp(O1) & (F assemble(R1)"       # unbalanced: error at line 1, column 28


@pytest.fixture(scope="module")
def real_server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ClientSession]:
    path = tmp_path_factory.mktemp("config") / "synthesis_only.yaml"
    path.write_text(SYNTHESIS_ONLY_BRINGUP)
    bringup = Bringup(load_bringup_config(path), overrides={"store_dir": ""}).start()
    with ClientSession("test_pipeline_client") as session:
        yield session
    bringup.shutdown()


def call(session: ClientSession, spec: str, timeout: float) -> SynthesizeMotion.Response:
    return session.call(SynthesizeMotion, SERVICE,
                        SynthesizeMotion.Request(spec=spec, cell="paper_cell", seed=0),
                        timeout=timeout)


def test_pipeline_s2_over_the_service(real_server: ClientSession) -> None:
    reply = call(real_server, "S2", timeout=600.0)
    assert reply.success, reply.error_message
    tasks = reply.task_sequences[0]
    for task in ("grasp(O1)", "grasp(O2)", "assemble(R1)"):
        assert task in tasks
    assert reply.durations[0] > 1.0 and reply.stats[0].total_time > 0
    assert reply.stats[0].real_time_factor > 1.0


def test_pipeline_bad_spec_over_the_service(real_server: ClientSession) -> None:
    reply = call(real_server, BAD_SPEC, timeout=120.0)
    assert not reply.success and (reply.error_line, reply.error_column) == (1, 28)
    assert "column 28" in reply.error_message
