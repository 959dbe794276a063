#!/usr/bin/python3
"""Drives one Enki robot through ``<robot>/cmd_vel`` like a script replaying the paper's "push".

Speed profile (forward speed v in m/s, t in s of ROS time since the start, a = push_accel *
push_scale in m/s^2, angular.z always 0):

  * t < push_start:                       v = speed
  * push_start <= t < push_end:           v = speed + a * (t - push_start)    (the push)
  * push_end <= t < push_end + hold:      v = v_push = speed + a * (push_end - push_start)
  * afterwards:                           v ramps from v_push back to speed at |a| m/s^2
                                          (at once when a == 0), then stays at speed.

With the defaults (0.05 m/s, -0.02 m/s^2 from 20 s to 23 s, hold 2 s) the robot slows to
-0.01 m/s (it backs towards a follower behind it), holds that until 25 s and is back at
0.05 m/s at 28 s. Commands beyond the robot's wheel limits are clamped by the bridge.

Private parameters (defaults in brackets):
  ~robot       robot name, the topic is <robot>/cmd_vel (relative) [robot_0]
  ~speed       m/s [0.05]
  ~push_start  s [20]          ~push_end  s [23]
  ~push_accel  m/s^2, negative = backwards [-0.02]
  ~push_scale  factor on push_accel [1]
  ~hold        s the reached speed is held after the push [2]
  ~yaw_rate    rad/s, the robot's turn throughout (angular.z; a circle of radius speed / yaw_rate) [0]
  ~rate        Hz of the published commands [50]
  ~duration    s after the start to publish a zero command and exit; 0 = run forever [0]
  ~wait_for_subscriber  start the profile (t = 0) only once cmd_vel has a subscriber [true]
"""

import math
import time

import rospy
from geometry_msgs.msg import Twist


class PushProfile:
    """Forward speed (m/s) as a function of the time since the start (s)."""

    def __init__(self, speed, push_start, push_end, accel, hold):
        if push_end < push_start or hold < 0.0:
            raise ValueError("need push_start <= push_end and hold >= 0")
        self.speed, self.t0, self.t1, self.accel, self.hold = speed, push_start, push_end, accel, hold
        self.v_push = speed + accel * (push_end - push_start)

    def __call__(self, t):
        if t < self.t0:
            return self.speed
        if t < self.t1:
            return self.speed + self.accel * (t - self.t0)
        t_back = t - self.t1 - self.hold
        if t_back < 0.0:
            return self.v_push
        if self.accel == 0.0:
            return self.speed
        gap = self.speed - self.v_push
        step = abs(self.accel) * t_back
        return self.speed if step >= abs(gap) else self.v_push + math.copysign(step, gap)


def main():
    rospy.init_node("push_leader")
    robot = str(rospy.get_param("~robot", "robot_0")).strip("/")
    profile = PushProfile(
        speed=float(rospy.get_param("~speed", 0.05)),
        push_start=float(rospy.get_param("~push_start", 20.0)),
        push_end=float(rospy.get_param("~push_end", 23.0)),
        accel=float(rospy.get_param("~push_accel", -0.02)) * float(rospy.get_param("~push_scale", 1.0)),
        hold=float(rospy.get_param("~hold", 2.0)))
    yaw_rate = float(rospy.get_param("~yaw_rate", 0.0))
    rate_hz = float(rospy.get_param("~rate", 50.0))
    duration = float(rospy.get_param("~duration", 0.0))
    pub = rospy.Publisher(robot + "/cmd_vel", Twist, queue_size=1)

    if rospy.get_param("~wait_for_subscriber", True):
        while not rospy.is_shutdown() and pub.get_num_connections() == 0:
            time.sleep(0.05)  # wall time: works before the first /clock too
    while not rospy.is_shutdown() and rospy.Time.now().is_zero():
        time.sleep(0.01)  # /use_sim_time and no /clock yet
    start = rospy.Time.now()
    rospy.loginfo("push_leader: %s at %.3f m/s turning at %.3f rad/s, push %.3f m/s^2 from %.1f s "
                  "to %.1f s, v_push %.3f m/s", robot, profile.speed, yaw_rate, profile.accel,
                  profile.t0, profile.t1, profile.v_push)
    rospy.on_shutdown(lambda: pub.publish(Twist()))  # best effort: the bridge holds commands

    rate = rospy.Rate(rate_hz)
    while not rospy.is_shutdown():
        t = (rospy.Time.now() - start).to_sec()
        if duration > 0.0 and t >= duration:
            pub.publish(Twist())
            break
        cmd = Twist()
        cmd.linear.x = profile(t)
        cmd.angular.z = yaw_rate
        pub.publish(cmd)
        try:
            rate.sleep()
        except rospy.exceptions.ROSTimeMovedBackwardsException:
            start = rospy.Time.now()
        except rospy.exceptions.ROSInterruptException:
            break


if __name__ == "__main__":
    main()
