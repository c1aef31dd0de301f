"""``/diagnostics`` of the long-running nodes, as ``diagnostic_updater`` publishes it.

Each node hands :func:`attach_diagnostics` a function that returns its current
:class:`Status` list; once per ``period`` (default :data:`DIAGNOSTICS_PERIOD`) the node
publishes them as one ``diagnostic_msgs/DiagnosticArray`` on the absolute topic
``/diagnostics`` (where ``rqt_robot_monitor`` and ``diagnostic_aggregator`` read), each
status named ``<node name>: <status name>`` with the node's fully qualified name as
``hardware_id``. What the nodes report: the occupancy stream's missed deadlines, the
synthesis queue, the robot connection of the coexistence node and the skeleton
publisher's playback state.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rclpy.node import Node
from rclpy.publisher import Publisher

from ltl_human_motion.ros.common import STREAM_QOS

DIAGNOSTICS_TOPIC = "/diagnostics"
#: Seconds between two reports (diagnostic_updater's default period is 1 s).
DIAGNOSTICS_PERIOD = 1.0
OK, WARN, ERROR, STALE = 0, 1, 2, 3


@dataclass(frozen=True)
class Status:
    """One component's state: ``level`` (:data:`OK`, :data:`WARN`, :data:`ERROR` or
    :data:`STALE`), a one-line ``message`` and named ``values``."""

    name: str
    level: int
    message: str
    values: dict[str, str] = field(default_factory=dict)


def diagnostic_array(node: Node, statuses: list[Status]) -> DiagnosticArray:
    """The DiagnosticArray of ``statuses`` reported by ``node``, stamped now."""
    msg = DiagnosticArray()
    msg.header.stamp = node.get_clock().now().to_msg()
    for s in statuses:
        msg.status.append(DiagnosticStatus(
            level=bytes([s.level]), name=f"{node.get_name()}: {s.name}", message=s.message,
            hardware_id=node.get_fully_qualified_name(),
            values=[KeyValue(key=k, value=str(v)) for k, v in s.values.items()]))
    return msg


def attach_diagnostics(node: Node, statuses: Callable[[], list[Status]],
                       period: float = DIAGNOSTICS_PERIOD) -> Publisher:
    """Publish ``statuses()`` of ``node`` on ``/diagnostics`` every ``period`` seconds;
    returns the publisher."""
    publisher = node.create_publisher(DiagnosticArray, DIAGNOSTICS_TOPIC, STREAM_QOS)

    def report() -> None:
        publisher.publish(diagnostic_array(node, statuses()))

    node.create_timer(period, report)
    return publisher
