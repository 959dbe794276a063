"""Helpers shared by the Python rostests."""

import time

import rospy


def wait_for(test, condition, what, deadline):
    """Polls `condition` every 10 ms for up to `deadline` wall seconds; fails `test` with `what`
    if it never holds."""
    end = time.monotonic() + deadline
    while time.monotonic() < end and not rospy.is_shutdown():
        if condition():
            return
        time.sleep(0.01)
    test.assertTrue(condition(), what)
