"""The synthesis node as a lifecycle node, driven by a plain rclpy client over DDS the way
commissioning tools (``ros2 lifecycle set``, nav2's lifecycle manager) drive it
(issue 38 item 5)."""

from __future__ import annotations

from functools import partial

import pytest

rclpy = pytest.importorskip("rclpy")

from lifecycle_msgs.msg import State, Transition  # noqa: E402
from lifecycle_msgs.srv import ChangeState, GetState  # noqa: E402
from ltl_human_motion.msg import MotionCatalog  # noqa: E402
from ltl_human_motion.srv import SynthesizeMotion  # noqa: E402
from rclpy.context import Context  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from ros_fakes import scripted_synthesize  # noqa: E402

from ltl_human_motion.ros.client import ClientSession, wait_until  # noqa: E402
from ltl_human_motion.ros.common import LATCHED_QOS, SpinThread  # noqa: E402
from ltl_human_motion.ros.synthesis_node import SynthesisNode  # noqa: E402

pytestmark = pytest.mark.ros

NS = "/lifecycle_test"
REQUEST = SynthesizeMotion.Request(spec="S2", cell="paper_cell")


def _node(context: Context, tmp_path, **params) -> SynthesisNode:
    overrides = [Parameter("store_dir", value=str(tmp_path)),
                 *[Parameter(k, value=v) for k, v in params.items()]]
    return SynthesisNode(synthesize_fn=partial(scripted_synthesize, duration=1.0),
                         namespace=NS, context=context, parameter_overrides=overrides)


@pytest.fixture
def context():
    context = Context()
    rclpy.init(context=context)
    yield context
    rclpy.try_shutdown(context=context)


#: The state each transition leads to when it succeeds.
REACHES = {Transition.TRANSITION_CONFIGURE: State.PRIMARY_STATE_INACTIVE,
           Transition.TRANSITION_ACTIVATE: State.PRIMARY_STATE_ACTIVE,
           Transition.TRANSITION_DEACTIVATE: State.PRIMARY_STATE_INACTIVE,
           Transition.TRANSITION_CLEANUP: State.PRIMARY_STATE_UNCONFIGURED}


def _change(session: ClientSession, transition: int) -> bool:
    """Whether ``transition`` took the node to its state. A reply that DDS lost while the
    client's reader was still being matched is sent for again; a repeated transition is
    refused, so the node's state then says whether the first one succeeded."""
    response = session.call(ChangeState, f"{NS}/synthesis_node/change_state",
                            ChangeState.Request(transition=Transition(id=transition)),
                            timeout=30.0, resend_after=3.0)
    return response.success or _state(session) == REACHES[transition]


def _state(session: ClientSession) -> int:
    return session.call(GetState, f"{NS}/synthesis_node/get_state", GetState.Request(),
                        timeout=30.0, resend_after=3.0).current_state.id


def test_commissioning_brings_the_node_up_in_order(context: Context, tmp_path) -> None:
    node = _node(context, tmp_path, autostart=False)
    spinner = SpinThread([node], context, 4)
    try:
        with ClientSession("lifecycle_client") as session:
            catalog = session.watch(MotionCatalog, f"{NS}/motion_catalog", keep=5,
                                    qos=LATCHED_QOS)
            assert _state(session) == State.PRIMARY_STATE_UNCONFIGURED
            refused = session.call(SynthesizeMotion, f"{NS}/synthesize_motion", REQUEST,
                                   timeout=20.0, resend_after=3.0)
            assert not refused.success and "not active" in refused.error_message
            assert _change(session, Transition.TRANSITION_CONFIGURE)
            assert _state(session) == State.PRIMARY_STATE_INACTIVE
            assert catalog.count == 0          # nothing announced before activation
            assert _change(session, Transition.TRANSITION_ACTIVATE)
            assert _state(session) == State.PRIMARY_STATE_ACTIVE
            wait_until(lambda: catalog.count > 0, 10.0, "the catalog once active")
            served = session.call(SynthesizeMotion, f"{NS}/synthesize_motion", REQUEST,
                                  timeout=30.0, resend_after=3.0)
            assert served.success, served.error_message
            assert _change(session, Transition.TRANSITION_DEACTIVATE)
            again = session.call(SynthesizeMotion, f"{NS}/synthesize_motion", REQUEST,
                                 timeout=20.0, resend_after=3.0)
            assert not again.success and "not active" in again.error_message
            assert _change(session, Transition.TRANSITION_CLEANUP)
            assert _state(session) == State.PRIMARY_STATE_UNCONFIGURED
    finally:
        spinner.stop()
        node.destroy_node()


def test_configure_fails_on_a_cell_that_does_not_load(context: Context, tmp_path) -> None:
    node = _node(context, tmp_path, autostart=False, default_cell="no_such_cell")
    spinner = SpinThread([node], context, 4)
    try:
        with ClientSession("lifecycle_client_bad") as session:
            assert not _change(session, Transition.TRANSITION_CONFIGURE)
            assert _state(session) == State.PRIMARY_STATE_UNCONFIGURED
            assert not node.active
    finally:
        spinner.stop()
        node.destroy_node()


def test_autostart_serves_at_once(context: Context, tmp_path) -> None:
    node = _node(context, tmp_path)
    spinner = SpinThread([node], context, 4)
    try:
        assert node.active
        with ClientSession("lifecycle_client_auto") as session:
            assert _state(session) == State.PRIMARY_STATE_ACTIVE
    finally:
        spinner.stop()
        node.destroy_node()
