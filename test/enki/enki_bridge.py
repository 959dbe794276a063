#!/usr/bin/python3
"""ROS 1 bridge for the Enki 2-D robot simulator (Debian package python3-enki2, module pyenki).

Written to behave like the third-party simulator bridges found in the wild, NOT like this
package's own nodes: frame ids with a leading slash, start-pose odometry, body-frame twist on
odometry but world-frame twist on ground truth, fresh stamps on stale state, a bursty /clock.

Units: the bridge speaks SI (m, m/s, rad, rad/s); Enki works in cm, cm/s, rad, rad/s and s.

Per robot ``<name>`` (topics relative to the node's namespace):
  * subscribes ``<name>/cmd_vel`` (geometry_msgs/Twist; linear.x m/s, angular.z rad/s),
    turned into wheel speeds with the model's wheel base, each clamped to the model's maximum;
    the last command is held (``~cmd_timeout`` s > 0 zeroes it when older than that);
  * publishes ``<name>/odom`` (nav_msgs/Odometry): frame_id ``/<name>/odom``, child_frame_id
    ``/<name>/base_link``, pose relative to the robot's start pose (``~odom_global``: world pose),
    twist in the body frame;
  * broadcasts tf ``/<name>/odom`` -> ``/<name>/base_link`` (same pose as the odometry);
  * publishes ``<name>/ground_truth`` (nav_msgs/Odometry): world pose, frame_id ``world``,
    child_frame_id ``/<name>/base_link``, twist in the WORLD frame.

Per relative sensor ``{observer, target}`` of ``~relative_sensors`` (a range-and-bearing or
camera-like sensor on the observer that sees the target's centre):
  * publishes ``<observer>/relative/<target>`` (geometry_msgs/PointStamped): the target's centre
    relative to the sensor, in the sensor's frame, at the publish rate with the same fresh stamps;
    the sensor sits at the observer's centre (frame ``/<observer>/base_link``) or, with a mount
    offset x, y (m, in the observer's body frame), in frame ``/<observer>/sensor_<target>``, with a
    static tf ``/<observer>/base_link`` -> it; ``noise`` (m) adds Gaussian noise of that standard
    deviation to each coordinate.

Private parameters (defaults in brackets):
  ~robots        list of {name, type: thymio2|epuck, x, y (m), heading (rad)}
                 [robot_0 at (0, 0, 0) and robot_1 at (-0.5, 0, 0), both thymio2]
  ~physics_step  s of ROS time per Enki step [0.1]
  ~physics_oversampling  Enki physics sub-steps per step [1]
  ~publish_rate  Hz of odometry/tf/ground-truth, stamped with the time of publication [100]
  ~odom_global   bool, odometry pose in the world frame instead of the start frame [false]
  ~world_frame   with a name: a static tf <world_frame> -> /<name>/odom per robot, its start pose
                 (the world itself with ~odom_global), as bridges that know the map do [""]
  ~cmd_timeout   s, 0 = hold the last command forever [0]
  ~publish_clock bool, drive /clock in bursts of physics_step [false]
  ~real_time_factor  sim s per wall s with publish_clock; <= 0 = as fast as possible [1]
  ~arena_radius  m, circular walls centred on the origin; 0 = unbounded world [0]
  ~seed          Enki's random seed (motor noise; with >= 0 also the relative sensors'
                 noise); < 0 = Enki's own [-1]
  ~relative_sensors  list of {observer, target, x (m) [0], y (m) [0], noise (m) [0]} [[]]
  ~wait_for_subscribers  topics (resolved in the node's namespace) that must each have a
                 subscriber (connected, for the bridge's own topics; at the master, for others)
                 before cmd_vel is subscribed and anything published: a recorder's, so that it
                 sees the run from its start [[]]
  ~wait_timeout  wall s of that wait at most; then the bridge starts anyway [10]
"""

import math
import random
import threading
import time

import pyenki
import rosgraph
import rospy
import tf2_ros
from geometry_msgs.msg import Quaternion, TransformStamped, Twist
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock

from relative_sensor import RelativeSensor  # beside this script

# Model facts, hard-coded in libenki's C++ constructors and not readable from Python; measured
# with pyenki 1.6.99: (class, distance between the wheels in cm, maximum wheel speed in cm/s).
MODELS = {
    "thymio2": (pyenki.Thymio2, 9.4, 16.6),
    "epuck": (pyenki.EPuck, 5.1, 12.8),
}
DEFAULT_ROBOTS = [
    {"name": "robot_0", "type": "thymio2", "x": 0.0, "y": 0.0, "heading": 0.0},
    {"name": "robot_1", "type": "thymio2", "x": -0.5, "y": 0.0, "heading": 0.0},
]
CM = 100.0  # cm per m
# Planar covariance as many wheel-odometry drivers give it: x, y, yaw known, z/roll/pitch not.
PLANAR_COVARIANCE = [0.0] * 36
for _i, _v in enumerate((1e-3, 1e-3, 1e6, 1e6, 1e6, 1e-3)):
    PLANAR_COVARIANCE[7 * _i] = _v


def wrap(angle):
    """Angle in rad wrapped to [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def yaw_quaternion(yaw):
    """Quaternion of a rotation by yaw (rad) about z."""
    return Quaternion(0.0, 0.0, math.sin(0.5 * yaw), math.cos(0.5 * yaw))


class SimRobot:
    """One Enki robot and its ROS interface."""

    def __init__(self, spec, world, bridge):
        self.name = str(spec["name"]).strip("/")
        kind = str(spec.get("type", "thymio2")).lower()
        if kind not in MODELS:
            raise ValueError("robot %s: unknown type %r (one of %s)" % (self.name, kind, sorted(MODELS)))
        cls, self.wheel_base_cm, self.max_wheel_cm = MODELS[kind]
        self.x0 = float(spec.get("x", 0.0))
        self.y0 = float(spec.get("y", 0.0))
        self.h0 = float(spec.get("heading", 0.0))
        self.robot = cls()
        self.robot.pos = (self.x0 * CM, self.y0 * CM)
        self.robot.angle = self.h0
        world.addObject(self.robot)
        self.bridge = bridge
        self.odom_frame = "/%s/odom" % self.name
        self.base_frame = "/%s/base_link" % self.name
        self.lock = threading.Lock()
        self.cmd = (0.0, 0.0)  # (m/s, rad/s)
        self.cmd_time = None  # rospy.Time of the last command
        self.odom_pub = rospy.Publisher(self.name + "/odom", Odometry, queue_size=10)
        self.truth_pub = rospy.Publisher(self.name + "/ground_truth", Odometry, queue_size=10)
        self.cmd_sub = None  # listen(): once the bridge is ready

    def listen(self):
        """Subscribes cmd_vel (a driver waiting for a subscriber starts then)."""
        self.cmd_sub = rospy.Subscriber(self.name + "/cmd_vel", Twist, self.on_cmd, queue_size=1)

    def odom_in_world(self, world_frame, odom_global):
        """The static transform world_frame -> odom frame: the start pose (identity if global)."""
        t = TransformStamped()
        t.header.stamp = rospy.Time.now()
        t.header.frame_id = world_frame
        t.child_frame_id = self.odom_frame
        if not odom_global:
            t.transform.translation.x, t.transform.translation.y = self.x0, self.y0
            t.transform.rotation = yaw_quaternion(self.h0)
        else:
            t.transform.rotation.w = 1.0
        return t

    def on_cmd(self, msg):
        with self.lock:
            self.cmd = (msg.linear.x, msg.angular.z)
            self.cmd_time = self.bridge.now()

    def apply_command(self, now, timeout):
        """Set Enki's wheel speeds (cm/s) from the held command."""
        with self.lock:
            v, w = self.cmd
            if timeout > 0.0 and self.cmd_time is not None and (now - self.cmd_time).to_sec() > timeout:
                v, w = 0.0, 0.0
        half = 0.5 * w * self.wheel_base_cm
        limit = self.max_wheel_cm
        self.robot.leftSpeed = max(-limit, min(limit, v * CM - half))
        self.robot.rightSpeed = max(-limit, min(limit, v * CM + half))

    def state(self):
        """World state (x, y m; yaw rad; vx, vy m/s world frame; wz rad/s)."""
        x, y = self.robot.pos
        vx, vy = self.robot.speed
        return x / CM, y / CM, wrap(self.robot.angle), vx / CM, vy / CM, self.robot.angSpeed

    def messages(self, stamp, odom_global):
        """Odometry, ground truth and transform for the current state, all stamped ``stamp``."""
        x, y, yaw, vx, vy, wz = self.state()
        c, s = math.cos(yaw), math.sin(yaw)
        if odom_global:
            ox, oy, oyaw = x, y, yaw
        else:
            dx, dy = x - self.x0, y - self.y0
            c0, s0 = math.cos(self.h0), math.sin(self.h0)
            ox, oy, oyaw = c0 * dx + s0 * dy, -s0 * dx + c0 * dy, wrap(yaw - self.h0)
        odom = Odometry()
        odom.header.stamp = stamp
        odom.header.frame_id = self.odom_frame
        odom.child_frame_id = self.base_frame
        odom.pose.pose.position.x, odom.pose.pose.position.y = ox, oy
        odom.pose.pose.orientation = yaw_quaternion(oyaw)
        odom.pose.covariance = PLANAR_COVARIANCE
        odom.twist.twist.linear.x = c * vx + s * vy  # body frame
        odom.twist.twist.linear.y = -s * vx + c * vy
        odom.twist.twist.angular.z = wz
        odom.twist.covariance = PLANAR_COVARIANCE
        truth = Odometry()
        truth.header.stamp = stamp
        truth.header.frame_id = "world"
        truth.child_frame_id = self.base_frame
        truth.pose.pose.position.x, truth.pose.pose.position.y = x, y
        truth.pose.pose.orientation = yaw_quaternion(yaw)
        truth.twist.twist.linear.x, truth.twist.twist.linear.y = vx, vy  # world frame
        truth.twist.twist.angular.z = wz
        tf = TransformStamped()
        tf.header.stamp = stamp
        tf.header.frame_id = self.odom_frame
        tf.child_frame_id = self.base_frame
        tf.transform.translation.x, tf.transform.translation.y = ox, oy
        tf.transform.rotation = odom.pose.pose.orientation
        return odom, truth, tf


class EnkiBridge:
    """Steps an Enki world on ROS time (or drives /clock) and publishes the robots' state."""

    def __init__(self):
        self.dt = float(rospy.get_param("~physics_step", 0.1))
        self.oversampling = int(rospy.get_param("~physics_oversampling", 1))
        self.publish_rate = float(rospy.get_param("~publish_rate", 100.0))
        self.odom_global = bool(rospy.get_param("~odom_global", False))
        self.cmd_timeout = float(rospy.get_param("~cmd_timeout", 0.0))
        self.publish_clock = bool(rospy.get_param("~publish_clock", False))
        self.rtf = float(rospy.get_param("~real_time_factor", 1.0))
        arena = float(rospy.get_param("~arena_radius", 0.0))
        seed = int(rospy.get_param("~seed", -1))
        specs = rospy.get_param("~robots", DEFAULT_ROBOTS)
        if self.dt <= 0.0 or self.publish_rate <= 0.0 or self.oversampling < 1:
            raise ValueError("~physics_step, ~publish_rate and ~physics_oversampling must be positive")
        self.world = pyenki.World(arena * CM) if arena > 0.0 else pyenki.World()
        if seed >= 0:
            self.world.setRandomSeed(seed)
        self.sim_time = rospy.Time(0)  # the clock this bridge publishes (publish_clock only)
        self.clock_pub = rospy.Publisher("/clock", Clock, queue_size=10) if self.publish_clock else None
        self.robots = [SimRobot(spec, self.world, self) for spec in specs]
        names = [r.name for r in self.robots]
        if len(set(names)) != len(names):
            raise ValueError("robot names must be unique: %s" % names)
        rng = random.Random(seed) if seed >= 0 else random.Random()
        self.sensors = [RelativeSensor(spec, self.robots, rng)
                        for spec in rospy.get_param("~relative_sensors", [])]
        frames = [sensor.frame for sensor in self.sensors]
        if len(set(frames)) != len(frames):
            raise ValueError("two relative sensors of one observer look at one target")
        self.tf_broadcaster = tf2_ros.TransformBroadcaster()
        world_frame = str(rospy.get_param("~world_frame", ""))
        static = [robot.odom_in_world(world_frame, self.odom_global)
                  for robot in self.robots] if world_frame else []
        static += [t for t in (sensor.mount_transform() for sensor in self.sensors) if t is not None]
        self.static_broadcaster = None
        if static:  # one latched message holds them all: a second call would replace the first
            self.static_broadcaster = tf2_ros.StaticTransformBroadcaster()
            self.static_broadcaster.sendTransform(static)
        rospy.loginfo("enki_bridge: %s, physics_step %.3f s, publish_rate %.1f Hz, %s",
                      ", ".join("%s (%s)" % (r.name, type(r.robot).__name__) for r in self.robots),
                      self.dt, self.publish_rate,
                      "publishing /clock (rtf %g)" % self.rtf if self.publish_clock else "on ROS time")
        self.wait_for_subscribers(rospy.get_param("~wait_for_subscribers", []),
                                  float(rospy.get_param("~wait_timeout", 10.0)))
        for robot in self.robots:
            robot.listen()

    def wait_for_subscribers(self, topics, timeout):
        """Waits (wall time, at most timeout s) until each topic has a subscriber: connected to
        this bridge's publisher for its own topics (messages sent before are lost to it), known
        to the master for the others."""
        topics = [rospy.resolve_name(str(topic)) for topic in topics]
        own = {pub.resolved_name: pub for robot in self.robots
               for pub in (robot.odom_pub, robot.truth_pub)}
        own.update({sensor.pub.resolved_name: sensor.pub for sensor in self.sensors})
        master = rosgraph.Master(rospy.get_name())
        end = time.monotonic() + timeout
        while topics and not rospy.is_shutdown():
            subscribed = {topic for topic, _ in master.getSystemState()[1]}
            missing = [topic for topic in topics if (own[topic].get_num_connections() == 0
                                                     if topic in own else topic not in subscribed)]
            if not missing:
                return
            if time.monotonic() >= end:
                rospy.logwarn("enki_bridge: no subscriber to %s after %g s: starting anyway",
                              ", ".join(missing), timeout)
                return
            time.sleep(0.05)

    def now(self):
        """Current time: the bridge's own clock with ~publish_clock, else ROS time."""
        return self.sim_time if self.publish_clock else rospy.Time.now()

    def step(self, now):
        for robot in self.robots:
            robot.apply_command(now, self.cmd_timeout)
        self.world.step(self.dt, self.oversampling)

    def publish(self, stamp):
        transforms = []
        for robot in self.robots:
            odom, truth, tf = robot.messages(stamp, self.odom_global)
            robot.odom_pub.publish(odom)
            robot.truth_pub.publish(truth)
            transforms.append(tf)
        self.tf_broadcaster.sendTransform(transforms)
        for sensor in self.sensors:  # after the tf of the same stamp, which a reader may look up
            sensor.pub.publish(sensor.message(stamp))

    def run_on_ros_time(self):
        """Step whenever physics_step of ROS time has passed; publish at publish_rate."""
        max_catch_up = max(1, int(math.ceil(0.5 / self.dt)))
        while not rospy.is_shutdown() and rospy.Time.now().is_zero():
            time.sleep(0.01)  # /use_sim_time and no /clock yet
        rate = rospy.Rate(self.publish_rate)
        start, steps = rospy.Time.now(), 0
        while not rospy.is_shutdown():
            now = rospy.Time.now()
            if now < start:  # time moved backwards (e.g. a bag or a simulator restarted)
                start, steps = now, 0
            due = int((now - start).to_sec() / self.dt + 1e-9)
            if due - steps > max_catch_up:
                rospy.logwarn_throttle(5.0, "enki_bridge: %d steps behind, skipping" % (due - steps))
                steps = due - max_catch_up
            while steps < due:
                self.step(now)
                steps += 1
            self.publish(rospy.Time.now())
            try:
                rate.sleep()
            except rospy.exceptions.ROSTimeMovedBackwardsException:
                pass

    def run_with_clock(self):
        """Own /clock: advance it by physics_step at once per step, paced by real_time_factor."""
        if not rospy.get_param("/use_sim_time", False):
            rospy.logwarn("enki_bridge: ~publish_clock is set but /use_sim_time is not true")
        step_period = self.dt / self.rtf if self.rtf > 0.0 else 0.0
        pub_period = 1.0 / (self.publish_rate * self.rtf) if self.rtf > 0.0 else None
        next_step = next_pub = time.monotonic()
        while not rospy.is_shutdown():
            wall = time.monotonic()
            if wall >= next_step:
                self.step(self.sim_time)
                self.sim_time += rospy.Duration.from_sec(self.dt)
                self.clock_pub.publish(Clock(clock=self.sim_time))
                next_step = max(next_step + step_period, wall - 1.0)  # give up on > 1 s of lag
                if pub_period is None:
                    self.publish(self.sim_time)
                    continue
            if pub_period is not None and wall >= next_pub:
                self.publish(self.sim_time)
                next_pub = max(next_pub + pub_period, wall - 1.0)
            pause = min(next_step, next_pub if pub_period else next_step) - time.monotonic()
            if pause > 0.0:
                time.sleep(pause)

    def run(self):
        if self.publish_clock:
            self.run_with_clock()
        else:
            self.run_on_ros_time()


def main():
    rospy.init_node("enki_bridge")
    try:
        bridge = EnkiBridge()
    except (ValueError, KeyError, TypeError) as error:
        rospy.logfatal("enki_bridge: bad parameters: %s" % error)
        raise SystemExit(1)
    try:
        bridge.run()
    except rospy.exceptions.ROSInterruptException:
        pass


if __name__ == "__main__":
    main()
