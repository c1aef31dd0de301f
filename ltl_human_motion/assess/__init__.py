"""Assessment of a motion: ergonomics (REBA, RULA, OWAS, NIOSH lifting) and cycle time.

Plain Python (numpy); no ROS.
"""

from ltl_human_motion.assess.angles import BodyAngles, body_angles
from ltl_human_motion.assess.cycle import cycle_breakdown
from ltl_human_motion.assess.ergonomics import ErgonomicsReport, ErgonomicsSettings, assess_motion

__all__ = ["BodyAngles", "ErgonomicsReport", "ErgonomicsSettings", "assess_motion",
           "body_angles", "cycle_breakdown"]
