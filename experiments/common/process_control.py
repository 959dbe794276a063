"""Process helpers shared by the measurement scripts (formation_scale.py, ros_latency.py)."""

import os
import signal
import subprocess


def start_spinners():
    """One lowest-priority busy loop per core: keeps the VM's cores from halting when idle."""
    return [subprocess.Popen(["nice", "-n", "19", "sh", "-c", "while :; do :; done"])
            for _ in range(os.cpu_count())]


def stop(proc, timeout=20.0, on_unanswered=None):
    """SIGINT, then SIGTERM, then SIGKILL to one process the caller started; waits @p timeout s
    after SIGINT. on_unanswered(signal name) is called for each signal the process outlives."""
    for sig, wait in ((signal.SIGINT, timeout), (signal.SIGTERM, 10.0), (signal.SIGKILL, 5.0)):
        if proc.poll() is not None:
            return
        proc.send_signal(sig)
        try:
            proc.wait(wait)
            return
        except subprocess.TimeoutExpired:
            if on_unanswered is not None:
                on_unanswered(signal.Signals(sig).name)
