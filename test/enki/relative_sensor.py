"""The Enki bridge's relative position sensor (test/enki/enki_bridge.py, ``~relative_sensors``):
the target robot's centre seen from a sensor mounted on the observer robot, as relative
localisation systems (UWB range and bearing, a camera seeing a marker) publish it."""

import math

import rospy
from geometry_msgs.msg import PointStamped, TransformStamped


class RelativeSensor:
    """The target's centre seen from a sensor mounted on the observer (PointStamped)."""

    def __init__(self, spec, robots, rng):
        names = {robot.name: robot for robot in robots}
        observer = str(spec["observer"]).strip("/")
        target = str(spec["target"]).strip("/")
        if observer not in names or target not in names or observer == target:
            raise ValueError("relative sensor %r: observer and target must be two of the robots %s"
                             % (spec, sorted(names)))
        self.observer, self.target = names[observer], names[target]
        self.mount = (float(spec.get("x", 0.0)), float(spec.get("y", 0.0)))
        self.noise = float(spec.get("noise", 0.0))
        if not all(math.isfinite(v) for v in self.mount) or not self.noise >= 0.0:
            raise ValueError("relative sensor %r: x, y must be finite and noise >= 0" % (spec,))
        self.rng = rng
        mounted = self.mount != (0.0, 0.0)
        self.frame = ("/%s/sensor_%s" % (observer, target)) if mounted else self.observer.base_frame
        self.pub = rospy.Publisher("%s/relative/%s" % (observer, target), PointStamped, queue_size=10)

    def mount_transform(self):
        """The static transform observer base_link -> sensor frame, or None at the centre."""
        if self.frame == self.observer.base_frame:
            return None
        t = TransformStamped()
        t.header.stamp = rospy.Time.now()
        t.header.frame_id = self.observer.base_frame
        t.child_frame_id = self.frame
        t.transform.translation.x, t.transform.translation.y = self.mount
        t.transform.rotation.w = 1.0
        return t

    def message(self, stamp):
        """The target's centre in the sensor's frame (m), stamped ``stamp``."""
        x, y, yaw = self.observer.state()[:3]
        tx, ty = self.target.state()[:2]
        c, s = math.cos(yaw), math.sin(yaw)
        dx, dy = tx - x, ty - y
        msg = PointStamped()
        msg.header.stamp = stamp
        msg.header.frame_id = self.frame
        msg.point.x = c * dx + s * dy - self.mount[0]
        msg.point.y = -s * dx + c * dy - self.mount[1]
        if self.noise > 0.0:
            msg.point.x += self.rng.gauss(0.0, self.noise)
            msg.point.y += self.rng.gauss(0.0, self.noise)
        return msg
