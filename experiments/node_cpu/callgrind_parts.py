"""Instructions per control tick of each part of follower_node, from one callgrind run.

  callgrind_parts.py ANNOTATE.txt CALLGRIND.OUT

ANNOTATE.txt: `callgrind_annotate --inclusive=yes` of CALLGRIND.OUT. Under valgrind the threads
run one at a time, so a thread's idle loop (ros::spin's timed waits) can cost instructions it does
not cost outside; the parts below are the work done, not the waiting. The ticks are the calls of
FollowerCycle::tickLatched (the tick once its inputs are latched) counted in CALLGRIND.OUT; a part's figure is the inclusive instruction count of
its functions (the first function matching each pattern, in the order given) divided by the ticks.
"""

import re
import sys

# (part, [substrings of the function's name; the counts of all matches are added]).
PARTS = [
    ("whole process (all threads, start-up included)", ["PROGRAM TOTALS"]),
    ("roscpp network thread (receive, write; the input callbacks where they run there)",
     ["ros::PollManager::threadFunc"]),
    ("input callbacks: relative_measurement (guard, admit)",
     ["FollowerInputs::onMeasurement"]),
    ("input callbacks: leader_broadcast (guard, admit)", ["FollowerInputs::onLeaderBroadcast"]),
    ("callbacks run from callback queues (the inputs', the timer's)",
     ["ros::CallbackQueue::callOneCB"]),
    ("roscpp timer thread (the timer's hand-off)", ["TimerManager<ros::Time, ros::Duration, ros::TimerEvent>::threadFunc"]),
    ("tick thread (PeriodicThread)", ["PeriodicThread::run"]),
    ("control tick: latching the inputs (LatchedInputs::latch)",
     ["LatchedInputs::latch("]),
    ("control tick: FollowerCycle::tickLatched (mode, accounting, the core's step)",
     ["FollowerCycle::tickLatched("]),
    ("the core's step: DynamicFollowerController::step", ["DynamicFollowerController::step("]),
    ("outputs: FollowerOutputs::publish (all of it)", ["FollowerOutputs::publish("]),
    ("publication of command (AccelStamped)", ["Publisher::publish<geometry_msgs::AccelStamped_"]),
    ("publication of broadcast (LeaderBroadcast)",
     ["Publisher::publish<projection_collision_avoidance::LeaderBroadcast_"]),
    ("making the status message (toStatusMsg)", ["toStatusMsg("]),
    ("publication of status (FollowerStatus)",
     ["Publisher::publish<projection_collision_avoidance::FollowerStatus_"]),
    ("markers (FollowerOutputs::publishMarkers)", ["FollowerOutputs::publishMarkers("]),
    ("diagnostics (diagnostic_updater::Updater::update)", ["diagnostic_updater::Updater::update("]),
]


def call_counts(path, pattern):
    """Calls of the functions whose name contains @p pattern, from a callgrind output file."""
    names = {}
    total = 0
    pending = None
    with open(path, errors="replace") as f:
        for line in f:
            m = re.match(r"c?fn=\((\d+)\)(?: (.*))?", line)
            if m:
                if m.group(2):
                    names[m.group(1)] = m.group(2)
                pending = names.get(m.group(1), "") if line.startswith("cfn") else None
                continue
            if pending is not None and line.startswith("calls="):
                if pattern in pending:
                    total += int(line.split()[0].split("=")[1])
                pending = None
    return total


def inclusive(annotate):
    """[(instructions, function name)] from callgrind_annotate --inclusive=yes."""
    rows = []
    with open(annotate, errors="replace") as f:
        for line in f:
            m = re.match(r"\s*([\d,]+) \([\s\d.]+%\)\s+(.*)$", line)
            if m:
                rows.append((int(m.group(1).replace(",", "")), m.group(2)))
            elif "PROGRAM TOTALS" in line:
                m = re.match(r"\s*([\d,]+)", line)
                if m:
                    rows.append((int(m.group(1).replace(",", "")), "PROGRAM TOTALS"))
    return rows


def main():
    annotate, raw = sys.argv[1], sys.argv[2]
    ticks = call_counts(raw, "FollowerCycle::tickLatched(")
    if ticks == 0:
        sys.exit("callgrind_parts: no call of FollowerCycle::tickLatched in " + raw)
    rows = inclusive(annotate)
    print("ticks: %d" % ticks)
    print("| part | instructions per tick |")
    print("|---|---:|")
    for part, patterns in PARTS:
        count = 0
        for pattern in patterns:
            count += next((n for n, name in rows if pattern in name), 0)
        print("| %s | %s |" % (part, "{:,}".format(round(count / ticks)) if count else "0"))


if __name__ == "__main__":
    main()
