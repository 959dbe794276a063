"""Generated hostile messages for the nodes' inputs, and what the boundary contract
(doc/boundary.md) says each must meet: an oracle written apart from the nodes' guards.

A Generator draws, from a seeded random.Random, messages of every kind the contract names (zero,
future, stale, out-of-order and repeated stamps over the whole range of ros::Time; wrong sizes;
NaN, inf and extreme finite values; wrong and long frame_ids) interleaved with good ones, and says
for each whether it must be accepted or refused, given the receiver's clock. Stamps near a limit
are avoided by a margin, so that the verdict does not hang on the transport's delay."""

import math

import rospy

LATEST = (4294967295, 999999999)  # the largest ros::Time
MARGIN = 0.3  # s kept between a generated stamp and any limit


def to_time(seconds):
    seconds = min(max(seconds, 0.0), 4294967295.0)
    secs = int(seconds)
    return rospy.Time(secs, min(999999999, int(round((seconds - secs) * 1e9))))


def stamp_seconds(stamp):
    return stamp.secs + 1e-9 * stamp.nsecs


class Generator:
    """Draws (kind, stamp, frame, vectors, expect_accepted) for an input whose guard has the
    given limits; `good_values` makes the vectors of an acceptable message."""

    def __init__(self, rng, frame, max_future, max_age, sizes, good_values):
        self.rng = rng
        self.frame = frame
        self.max_future = max_future
        self.max_age = max_age
        self.sizes = sizes  # {field: (entries, ...)}: the sizes the receiver accepts, good first
        self.good_values = good_values
        self.last_accepted = None  # stamp of the last message the oracle accepted
        self.accepted = 0
        self.refused = 0

    def good_stamp(self, now):
        """A stamp the contract accepts at `now`: after the last accepted, not too old."""
        stamp = now - 0.05
        if self.last_accepted is not None:
            stamp = max(stamp, stamp_seconds(self.last_accepted) + 0.001)
        return to_time(stamp)

    def draw(self, now):
        kind = self.rng.choice(KINDS)
        stamp, frame, vectors, accepted = kind(self, now)
        if accepted:
            self.accepted += 1
            self.last_accepted = stamp
        else:
            self.refused += 1
        return kind.__name__, stamp, frame, vectors, accepted

    # Each kind: (stamp, frame, vectors, must be accepted).
    def good(self, now):
        return self.good_stamp(now), self.frame, self.good_values(self.rng), True

    def extreme_finite(self, now):
        vectors = {name: [self.rng.choice((1e308, -1e308, 5e-324, 1e30)) for _ in range(n[0])]
                   for name, n in self.sizes.items()}
        return self.good_stamp(now), self.frame, vectors, True

    def zero_stamp(self, now):
        return rospy.Time(0, 0), self.frame, self.good_values(self.rng), False

    def future_stamp(self, now):
        low = now + self.max_future + MARGIN
        stamp = self.rng.choice((to_time(self.rng.uniform(low, low + 10.0)),
                                 to_time(self.rng.uniform(low, 4294967295.0)),
                                 rospy.Time(*LATEST)))
        return stamp, self.frame, self.good_values(self.rng), False

    def stale_stamp(self, now):
        high = now - self.max_age - MARGIN
        stamp = self.rng.choice((rospy.Time(0, 1), rospy.Time(1, 0),
                                 to_time(self.rng.uniform(1.0, high))))
        return stamp, self.frame, self.good_values(self.rng), False

    def out_of_order(self, now):
        if self.last_accepted is None:
            return self.zero_stamp(now)
        stamp = to_time(stamp_seconds(self.last_accepted) - self.rng.uniform(0.001, 0.1))
        return stamp, self.frame, self.good_values(self.rng), False

    def repeated_stamp(self, now):
        if self.last_accepted is None:
            return self.zero_stamp(now)
        return self.last_accepted, self.frame, self.good_values(self.rng), False

    def wrong_size(self, now):
        vectors = self.good_values(self.rng)
        name = self.rng.choice(sorted(self.sizes))
        wrong = self.rng.choice([n for n in (0, 1, 2, 3, 7, 1000) if n not in self.sizes[name]])
        vectors[name] = [0.0] * wrong
        return self.good_stamp(now), self.frame, vectors, False

    def non_finite(self, now):
        vectors = self.good_values(self.rng)
        name = self.rng.choice(sorted(self.sizes))
        vectors[name][0] = self.rng.choice((math.nan, math.inf, -math.inf))  # good sizes are > 0
        return self.good_stamp(now), self.frame, vectors, False

    def slashed_frame(self, now):
        """The frame with a leading slash, as ROS 1 drivers write it: the same frame."""
        return self.good_stamp(now), "/" + self.frame, self.good_values(self.rng), True

    def wrong_frame(self, now):
        # "/" + frame names the same frame for tf2 (accepted); "//" + frame does not.
        frame = self.rng.choice(("", "map", self.frame + " ", "x" * (1 << 20),
                                 "\u00e9\u4e2d\u0000", "//" + self.frame))
        return self.good_stamp(now), frame, self.good_values(self.rng), False


KINDS = [Generator.good, Generator.good, Generator.good, Generator.extreme_finite,
         Generator.zero_stamp, Generator.future_stamp, Generator.stale_stamp,
         Generator.out_of_order, Generator.repeated_stamp, Generator.wrong_size,
         Generator.non_finite, Generator.wrong_frame, Generator.slashed_frame]


def any_values(rng, sizes):
    """Random vectors of arbitrary sizes and values, good or not (for inputs whose verdicts the
    test does not count); `sizes`: {field: usual entries}."""
    return {name: [rng.choice((0.0, 1.0, -3.5, math.nan, math.inf, 1e300))
                   for _ in range(rng.choice((0, n, n, n, 5)))] for name, n in sizes.items()}
