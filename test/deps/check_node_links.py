#!/usr/bin/python3
"""Checks that the nodes a vehicle runs load no simulation code.

Usage::

    check_node_links.py --lib DIR [--xunit FILE]

DIR is the package's library folder of a build (devel/lib or install/lib). The follower node, the
command adapter and the nodelet library that holds them must not load, directly or through
another library, the package's simulation libraries (``_sim``, ``_scenario``, ``_ros_sim``).
So that the check cannot pass by finding nothing, the plant node and the simulation's nodelet
library must load ``_sim``. The libraries a program loads are ldd's list (the dynamic loader's
own resolution, RUNPATH included). One JUnit test case per program with --xunit; the exit status
is 1 when one fails.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_dependencies import write_xunit  # noqa: E402

PACKAGE = "projection_collision_avoidance"
SIMULATION = {"sim", "scenario", "ros_sim"}
# program (relative to DIR) -> True when it must load the simulation, False when it must not
PROGRAMS = {
    f"{PACKAGE}/follower_node": False,
    f"{PACKAGE}/command_adapter": False,
    f"lib{PACKAGE}_nodelets.so": False,
    f"{PACKAGE}/plant_node": True,
    f"lib{PACKAGE}_sim_nodelets.so": True,
}


def package_libraries(path):
    """The package's libraries PATH loads, by their part after the package's name ("ros", ...)."""
    listing = subprocess.run(["ldd", path], check=True, capture_output=True, text=True).stdout
    if "not found" in listing:
        raise RuntimeError(f"{path}: a library is not found:\n{listing}")
    return set(re.findall(rf"lib{PACKAGE}_(\w+?)\.so", listing))


def check(lib_dir):
    results = []
    for program, needs_simulation in PROGRAMS.items():
        path = os.path.join(lib_dir, program)
        if not os.path.exists(path):
            results.append((program, f"{path} does not exist"))
            continue
        loaded = package_libraries(path)
        simulation = sorted(loaded & SIMULATION)
        problem = None
        if needs_simulation and "sim" not in loaded:
            problem = f"loads no simulation library (loads {sorted(loaded)}): the check sees nothing"
        elif not needs_simulation and simulation:
            problem = f"loads simulation code it does not run: {simulation}"
        results.append((program, problem))
        print(f"{program}: {'ok' if problem is None else problem} ({', '.join(sorted(loaded))})")
    return results


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lib", required=True, help="the build's library folder (devel/lib)")
    ap.add_argument("--xunit", metavar="FILE", help="also write the results as JUnit XML")
    args = ap.parse_args(argv)
    results = check(args.lib)
    if args.xunit:
        write_xunit(args.xunit, results, suite_name="node_links")
    return 1 if any(problem for _, problem in results) else 0


if __name__ == "__main__":
    sys.exit(main())
