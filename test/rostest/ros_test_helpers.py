"""Helpers shared by the Python rostests."""

import os
import time

import rospy

PACKAGE = "projection_collision_avoidance"


def node_executable(name):
    """The package's executable `name` in the devel space or install space rostest runs from."""
    for prefix in os.environ.get("CMAKE_PREFIX_PATH", "").split(os.pathsep):
        candidate = os.path.join(prefix, "lib", PACKAGE, name)
        if prefix and os.access(candidate, os.X_OK):
            return candidate
    raise RuntimeError(f"{name} not found under CMAKE_PREFIX_PATH")


def wait_for(test, condition, what, deadline):
    """Polls `condition` every 10 ms for up to `deadline` wall seconds; fails `test` with `what`
    if it never holds."""
    end = time.monotonic() + deadline
    while time.monotonic() < end and not rospy.is_shutdown():
        if condition():
            return
        time.sleep(0.01)
    test.assertTrue(condition(), what)
