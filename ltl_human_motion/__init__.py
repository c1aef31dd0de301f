"""ltl_human_motion: human motion synthesis from linear temporal logic specifications.

The core (``ltl``, ``motion``, ``scene``, ``planning``) is plain Python and never imports
ROS. The ROS 2 layer lives in ``ltl_human_motion.ros`` and the generated interfaces in
``ltl_human_motion.msg`` / ``ltl_human_motion.srv`` (built by colcon into the install
space; ``extend_path`` lets them be found beside an editable source tree).

Frames follow REP 103: metres, seconds, radians, right-handed, z up. The paper uses
y up; cell files written in the paper's frame are converted once, when loaded
(see :func:`ltl_human_motion.scene.frames.zup_from_yup`).
"""

from pkgutil import extend_path

__path__ = extend_path(__path__, __name__)

__version__ = "0.1.0"
