"""The shared numeric kernel of the core: segment and capsule distances, rotations, caches.

Every layer (scene, motion, robot, ROS) takes these from here instead of writing its own:

- :mod:`~ltl_human_motion.kernel.segments`: exact segment/capsule distances, elementwise
  and pairwise, numba-compiled where numba is installed (numpy fallback, same results);
- :mod:`~ltl_human_motion.kernel.rotations`: rotation conversions with pytransform3d names;
- :mod:`~ltl_human_motion.kernel.cache`: one small identity-keyed memo for derived arrays.
"""
