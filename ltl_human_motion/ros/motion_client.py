"""Ask a running bringup for motions: call ``/synthesize_motion``, optionally play one.

What ``ltl-human-motion call`` does, for users without the ``ros2`` command line: a
client node in its own rclpy context calls the synthesis service of a running
``ltl-human-motion bringup`` (or ``ros2 launch ltl_human_motion bringup.launch.py``) over
DDS and, if asked, starts the first motion on a skeleton publisher's ``play_motion``.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field

from ltl_human_motion.errors import LtlHumanMotionError
from ltl_human_motion.ros.client import ClientSession
from ltl_human_motion.srv import PlayMotion, SynthesizeMotion

__all__ = ["BringupUnavailableError", "CallResult", "ServiceRefusedError", "SynthesisRequest",
           "call_synthesis"]

SYNTHESIS_SERVICE = "/synthesize_motion"
#: Seconds after which an unanswered synthesis request is sent again (a response lost
#: while the server had not yet discovered the new client costs this long).
RESEND_AFTER = 30.0


class BringupUnavailableError(LtlHumanMotionError):
    """No node offered the service within the wait, or it did not answer in time."""


class ServiceRefusedError(LtlHumanMotionError):
    """The service answered ``success: false``; the message is the service's reason."""


@dataclass(frozen=True)
class SynthesisRequest:
    """One request to ``/synthesize_motion`` (the fields of ``SynthesizeMotion.Request``).

    ``cell`` empty means the node's ``default_cell``; ``stature`` 0 the default 1.75 m.
    """

    spec: str
    cell: str = ""
    variants: int = 1
    seed: int = 0
    cycles: int = 1
    stature: float = 0.0
    options_json: str = ""


@dataclass
class CallResult:
    """What the service returned, one entry per motion, and what was played.

    ``durations`` and ``cycle_times`` in s; ``played`` the motion (or strategy) id started
    on ``player`` (the play service's namespace), or None; ``strategy_id`` the strategy of a
    reactive specification (then there are no motions), else "".
    """

    motion_ids: list[str]
    sequences: list[str]
    durations: list[float]
    cycle_times: list[float] = field(default_factory=list)
    reba_max: list[int] = field(default_factory=list)
    rula_max: list[int] = field(default_factory=list)
    wall_time: float = 0.0
    played: str | None = None
    player: str = ""
    strategy_id: str = ""


def call_synthesis(request: SynthesisRequest, *, play: bool = False, human_id: str = "1",
                   loop: bool = False, rate: float = 1.0, wait: float = 10.0,
                   timeout: float = 600.0) -> CallResult:
    """Call the synthesis service of a running bringup; optionally play the first motion.

    Parameters
    ----------
    request : SynthesisRequest
    play : bool
        Start the first motion (or the strategy, on a reactive player) on
        ``/human_<human_id>/play_motion``.
    loop, rate : bool, float
        Playback: repeat the motion; speed (1.0 = real time).
    wait : float
        Seconds to wait for the services to appear.
    timeout : float
        Seconds to wait for the synthesis to answer.

    Raises
    ------
    BringupUnavailableError
        No ``/synthesize_motion`` (or, with ``play``, no ``play_motion``) within ``wait``
        s, or no answer within ``timeout`` s.
    ServiceRefusedError
        The service answered with ``success: false`` (e.g. a spec error, with its line
        and column).
    """
    ros_request = SynthesizeMotion.Request(
        spec=request.spec, cell=request.cell, variants=request.variants, seed=request.seed,
        cycles=request.cycles, stature=request.stature, options_json=request.options_json)
    player = f"/human_{human_id}/play_motion"
    with ClientSession("ltl_human_motion_call") as session:
        started = time.monotonic()
        response = _call(session, SynthesizeMotion, SYNTHESIS_SERVICE, ros_request, wait,
                         timeout, resend_after=min(RESEND_AFTER, timeout))
        wall = time.monotonic() - started
        if not response.success:
            where = (f" (spec line {response.error_line}, column {response.error_column})"
                     if response.error_line > 0 else "")
            raise ServiceRefusedError(f"{SYNTHESIS_SERVICE} refused: {response.error_message}"
                                 f"{where}")
        result = CallResult(
            motion_ids=list(response.motion_ids), sequences=list(response.task_sequences),
            durations=[float(d) for d in response.durations],
            cycle_times=[float(c) for c in response.cycle_times],
            reba_max=[int(r) for r in response.reba_max],
            rula_max=[int(r) for r in response.rula_max], wall_time=wall,
            strategy_id=response.strategy_id)
        target = result.motion_ids[0] if result.motion_ids else result.strategy_id
        if play and target:
            answer = _call(session, PlayMotion, player, PlayMotion.Request(
                command="play", motion_id=target, loop=loop, rate=rate), wait,
                timeout=max(wait, 10.0))
            if not answer.success:
                raise ServiceRefusedError(f"{player} refused to play {target}: "
                                     f"{answer.message}")
            result.played, result.player = target, player
        return result


def _call(session: ClientSession, srv_type: type, name: str, request: object, wait: float,
          timeout: float, resend_after: float | None = None) -> object:
    if not session.service_ready(srv_type, name, wait):
        hint = ("is this worker in the bringup file's `humans` list and skeleton_publisher "
                "in its `nodes`?" if srv_type is PlayMotion else
                "start one with `ltl-human-motion bringup` in another shell (after "
                "`. scripts/env.sh`)")
        raise BringupUnavailableError(
            f"no node offers {name} (waited {wait:g} s): {hint}; this shell uses "
            f"ROS_DOMAIN_ID={os.environ.get('ROS_DOMAIN_ID', '0')}, the bringup must too; "
            f"or wait longer with --wait")
    try:
        return session.call(srv_type, name, request, timeout=timeout,
                            resend_after=resend_after)
    except TimeoutError as exc:
        raise BringupUnavailableError(f"{exc}; raise --timeout for a long synthesis") from None
