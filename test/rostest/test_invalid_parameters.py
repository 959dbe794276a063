#!/usr/bin/python3
"""rostest: the follower, the plant, the leader and the command adapter refuse invalid parameters
(the adapter in its own cases, as it reads no scenario). For every case each node that reads
the spoiled parameter must exit with code 1 (not 0, not a signal) within a
deadline, printing "invalid parameter <key>: <reason>" where <key> is the parameter's full name
("~scenario/controller/alpha", "~measurement_timeout"); a node that starts instead (logs that it
is running) fails the case at once.

The cases are tables, one per class of invalid parameter (missing key, wrong type, out of range,
non-Hurwitz gain, d not in ker(A), wrong size, unknown key, bad node option, scenario over a
limit of size, depth or nodes, a value the nodes refuse that the design would name otherwise). Each case puts the
paper's Run 2 scenario (spoiled) and its node options into a fresh private namespace on the one
master of the test, then the nodes run there, several at a time. A positive test checks that
whole numbers where the format expects reals (alpha: 0, control_rate: 100) are accepted."""

import collections
import copy
import functools
import math
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import unittest
import xmlrpc.client
from concurrent.futures import ThreadPoolExecutor

import rospkg
import rospy
import rostest
import yaml
from ros_test_helpers import node_executable

PACKAGE = "projection_collision_avoidance"
# Wall seconds for a node to exit on a bad parameter or log that it runs, and to exit after
# SIGINT (~deadline, ~stop_deadline): bounds that only a hang reaches. A node takes well under a
# second for either, but twelve starting at once on a loaded 2-core machine took over 10 s to
# start and over 5 s to stop.
DEADLINE = 60.0
STOP_DEADLINE = 30.0
PARALLEL = 12  # node processes at a time (they mostly wait on the master, not on a CPU)

FOLLOWER, PLANT, LEADER = "follower_node", "plant_node", "leader_node"
ALL_NODES = (FOLLOWER, PLANT, LEADER)
ADAPTER = "command_adapter"  # reads no scenario: only its own cases name it
RELAY = "link_relay"  # only its own cases name it
# What each node logs once it runs, i.e. once it has accepted its parameters.
RUNNING = {
    FOLLOWER: ", running at ",
    PLANT: ": simulating a leader",
    LEADER: ": playing the leader's input",
    ADAPTER: "from command, stop after",
    RELAY: " -> ",
}
NAN, INF = math.nan, math.inf
MISSING = object()  # the ~scenario parameter is not set at all


@functools.lru_cache(maxsize=None)
def paper_path():
    return os.path.join(rospkg.RosPack().get_path(PACKAGE), "config", "scenarios",
                        "paper_run2.yaml")


@functools.lru_cache(maxsize=None)
def _paper_scenario():
    with open(paper_path()) as stream:
        return yaml.safe_load(stream)


def paper_scenario():
    """A fresh copy of the paper's Run 2 scenario, as a tree of Python values."""
    return copy.deepcopy(_paper_scenario())


def _walk(tree, dotted):
    """(parent, last element) of a dotted path; numeric elements index lists."""
    keys = [int(k) if k.isdigit() else k for k in dotted.split(".")]
    for key in keys[:-1]:
        tree = tree[key] if isinstance(key, int) else tree.setdefault(key, {})
    return tree, keys[-1]


def S(*assignments):
    """A change setting each dotted path to its value: S("controller.alpha", 1.5, ...)."""
    pairs = list(zip(assignments[::2], assignments[1::2]))

    def change(scenario):
        for dotted, value in pairs:
            parent, last = _walk(scenario, dotted)
            parent[last] = copy.deepcopy(value)
    return change


def D(dotted):
    """A change deleting the entry at a dotted path."""
    def change(scenario):
        parent, last = _walk(scenario, dotted)
        del parent[last]
    return change


def two_axes(scenario):
    """The paper's scenario on two axes (a valid 2-D scenario, pole-form gains)."""
    S("model.dimension", 2,
      "controller.separation", [5.0, 0.0, 0.0, 0.0],
      "controller.tracker", {"enabled": True, "natural_frequency": 3.0, "damping": 0.9},
      "leader.initial_state", [5.0, 0.0, 0.0, 0.0],
      "follower.initial_state", [0.0, 0.0, 0.0, 0.0],
      "leader.disturbance", [{"start": 20.0, "end": 23.0, "vector": [-2.0, 0.0, -2.0, 0.0]}])(
          scenario)


def then(*changes):
    def change(scenario):
        for c in changes:
            c(scenario)
    return change


Case = collections.namedtuple("Case", "name key change scenario options nodes")


# The sections of a scenario that only the simulation reads: the follower reads its own (model,
# controller, formation) alone and starts whatever these hold (configuration/ConfigurationLoader).
SIMULATION_SECTIONS = ("~scenario/leader", "~scenario/follower", "~scenario/simulation",
                       "~scenario/controller/leader_information/link")
SIMULATION_NODES = (PLANT, LEADER)


def case(name, key, change=None, scenario=None, options=None, nodes=None):
    """A run of each node of NODES (default: those that read KEY; every node when KEY is None)."""
    if nodes is None:
        reads_simulation = key is not None and any(
            key == section or key.startswith(section + "/") for section in SIMULATION_SECTIONS)
        nodes = SIMULATION_NODES if reads_simulation else ALL_NODES
    return Case(name, key, change, scenario, options or {}, nodes)


def baseline_gain(value):
    return S("controller.baseline", {"gain": value})


# File-backed cases: ~scenario as a path; the files are written in setUpClass.
FILES = {
    "syntax_error.yaml": "model:\n  type: double_integrator\n  dimension: [1\ncontroller: {\n",
    "tabs.yaml": "model:\n\ttype: double_integrator\n",
    "empty.yaml": "",
    "list.yaml": "- model\n- controller\n",
    "quoted_alpha.yaml": None,  # the paper's file with alpha: "0.2"
    "complex_key.yaml": None,  # the paper's file with a list as a key in controller
    "bad_dimension.yaml": None,  # the paper's file with dimension: 4
    "too_large.yaml": None,  # the paper's file padded with a comment beyond the size limit
    "too_deep.yaml": None,  # the paper's file with lists nested beyond the depth limit
    "alias_bomb.yaml": None,  # the paper's file with aliases that expand beyond the node limit
    "slow_rate.yaml": None,  # the paper's file with control_rate: 0.999
}

# The limits of scenario files (ConfigurationLoader.hpp: kMaxScenarioBytes, kMaxScenarioDepth).
MAX_BYTES = 1 << 20
MAX_DEPTH = 64


def nested_lists(depth):
    """depth lists nested in one another around a 1: [[[1]]]."""
    value = 1
    for _ in range(depth):
        value = [value]
    return value


def alias_bomb():
    """YAML lines l0 .. l9, each ten aliases of the one before: 10^10 nodes once expanded."""
    lines = ["l0: &l0 [x, x, x, x, x, x, x, x, x, x]"]
    for i in range(1, 10):
        lines.append(f"l{i}: &l{i} [" + ", ".join([f"*l{i - 1}"] * 10) + "]")
    return "\n".join(lines) + "\n"


MISSING_KEY = [
    case("~scenario not set", "~scenario", scenario=MISSING),
    case("~scenario an empty map", "~scenario/model", scenario={}),
    case("model", "~scenario/model", D("model")),
    case("model.type", "~scenario/model/type", D("model.type")),
    case("model.dimension", "~scenario/model/dimension", D("model.dimension")),
    case("controller", "~scenario/controller", D("controller")),
    case("controller.control_rate", "~scenario/controller/control_rate",
         D("controller.control_rate")),
    case("controller.alpha", "~scenario/controller/alpha", D("controller.alpha")),
    case("controller.epsilon", "~scenario/controller/epsilon", D("controller.epsilon")),
    case("controller.separation", "~scenario/controller/separation",
         D("controller.separation")),
    case("controller.baseline", "~scenario/controller/baseline", D("controller.baseline")),
    case("controller.baseline.damping", "~scenario/controller/baseline/damping",
         D("controller.baseline.damping")),
    case("controller.baseline.gain (neither form)", "~scenario/controller/baseline/gain",
         S("controller.baseline", {})),
    case("controller.estimator.gain", "~scenario/controller/estimator/gain",
         D("controller.estimator.gain")),
    case("controller.estimator.lyapunov_weight", "~scenario/controller/estimator/lyapunov_weight",
         D("controller.estimator.lyapunov_weight")),
    case("controller.tracker.enabled", "~scenario/controller/tracker/enabled",
         D("controller.tracker.enabled")),
    case("controller.tracker.gain", "~scenario/controller/tracker/gain",
         D("controller.tracker.gain")),
    case("leader", "~scenario/leader", D("leader")),
    case("leader.initial_state", "~scenario/leader/initial_state", D("leader.initial_state")),
    case("leader.disturbance.0.vector", "~scenario/leader/disturbance/0/vector",
         D("leader.disturbance.0.vector")),
    case("leader.input.pulses.0.end", "~scenario/leader/input/pulses/0/end",
         S("leader.input", {"pulses": [{"start": 0.0, "vector": [0.5]}]})),
    case("follower.initial_state", "~scenario/follower/initial_state",
         D("follower.initial_state")),
    case("simulation", "~scenario/simulation", D("simulation")),
    case("simulation.duration", "~scenario/simulation/duration", D("simulation.duration")),
]

WRONG_TYPE = [
    case("~scenario a number", "~scenario", scenario=5),
    case("~scenario a real", "~scenario", scenario=2.5),
    case("~scenario a list", "~scenario", scenario=[1, 2]),
    case("~scenario a boolean", "~scenario", scenario=True),
    case("~scenario an empty string", "~scenario", scenario=""),
    case("~scenario a missing file", "~scenario", scenario="@missing.yaml"),
    case("~scenario a directory", "~scenario", scenario="@"),
    case("~scenario a file with a syntax error", "~scenario", scenario="@syntax_error.yaml"),
    case("~scenario a file with tabs", "~scenario", scenario="@tabs.yaml"),
    case("~scenario an empty file", "~scenario", scenario="@empty.yaml"),
    case("~scenario a file holding a list", "~scenario", scenario="@list.yaml"),
    case("~scenario file: alpha quoted", "~scenario/controller/alpha",
         scenario="@quoted_alpha.yaml"),
    case("~scenario file: a list as a key", "~scenario/controller",
         scenario="@complex_key.yaml"),
    case("model a string", "~scenario/model", S("model", "double_integrator")),
    case("model.type a number", "~scenario/model/type", S("model.type", 3)),
    case("model.dimension a string", "~scenario/model/dimension", S("model.dimension", "one")),
    case("model.dimension a numeric string", "~scenario/model/dimension",
         S("model.dimension", "1")),
    case("model.dimension not whole", "~scenario/model/dimension", S("model.dimension", 1.5)),
    case("alpha a string", "~scenario/controller/alpha", S("controller.alpha", "high")),
    case("alpha a numeric string", "~scenario/controller/alpha", S("controller.alpha", "0.2")),
    case("alpha a boolean", "~scenario/controller/alpha", S("controller.alpha", True)),
    case("alpha binary data", "~scenario/controller/alpha",
         S("controller.alpha", xmlrpc.client.Binary(b"0.2"))),
    case("epsilon a list", "~scenario/controller/epsilon", S("controller.epsilon", [0.2])),
    case("control_rate a map", "~scenario/controller/control_rate",
         S("controller.control_rate", {"hz": 100})),
    case("control_rate a string", "~scenario/controller/control_rate",
         S("controller.control_rate", "100")),
    case("separation a string", "~scenario/controller/separation",
         S("controller.separation", "5, 0")),
    case("separation a number", "~scenario/controller/separation",
         S("controller.separation", 5.0)),
    case("separation a map", "~scenario/controller/separation",
         S("controller.separation", {"x": 5.0})),
    case("separation an entry a string", "~scenario/controller/separation",
         S("controller.separation", [5.0, "0"])),
    case("baseline a number", "~scenario/controller/baseline", S("controller.baseline", 3)),
    case("natural_frequency a string", "~scenario/controller/baseline/natural_frequency",
         S("controller.baseline.natural_frequency", "fast")),
    case("baseline.gain a map", "~scenario/controller/baseline/gain",
         baseline_gain({"a": 1.0})),
    case("baseline.gain a row a string", "~scenario/controller/baseline/gain",
         baseline_gain(["1, 1.4"])),
    case("baseline.gain a flat list", "~scenario/controller/baseline/gain",
         baseline_gain([1.0, 1.4])),
    case("estimator.gain a map", "~scenario/controller/estimator/gain",
         S("controller.estimator.gain", {"L": -5})),
    case("estimator.gain a string", "~scenario/controller/estimator/gain",
         S("controller.estimator.gain", "-5")),
    case("lyapunov_weight a boolean", "~scenario/controller/estimator/lyapunov_weight",
         S("controller.estimator.lyapunov_weight", True)),
    case("tracker.gain an entry a string", "~scenario/controller/tracker/gain/0",
         S("controller.tracker.gain", [[10.0, "5"]])),
    case("tracker.gain an entry a list", "~scenario/controller/tracker/gain/0",
         S("controller.tracker.gain", [[10.0, [5.0]]])),
    case("substeps too few for RK4 with this L", "~scenario/controller/estimator/substeps",
         S("controller.estimator.gain", -5000.0)),
    case("substeps a string", "~scenario/controller/estimator/substeps",
         S("controller.estimator.substeps", "2")),
    case("substeps not whole", "~scenario/controller/estimator/substeps",
         S("controller.estimator.substeps", 2.5)),
    case("initial_estimate a list", "~scenario/controller/estimator/initial_estimate",
         S("controller.estimator.initial_estimate", ["zero"])),
    case("tracker.enabled a string", "~scenario/controller/tracker/enabled",
         S("controller.tracker.enabled", "true")),
    case("tracker.enabled an integer", "~scenario/controller/tracker/enabled",
         S("controller.tracker.enabled", 1)),
    case("tracker.enabled a word", "~scenario/controller/tracker/enabled",
         S("controller.tracker.enabled", "maybe")),
    case("leader_information.command a string",
         "~scenario/controller/leader_information/command",
         S("controller.leader_information", {"command": "yes"})),
    case("leader_information.disturbance shared with nobody",
         "~scenario/controller/leader_information/disturbance",
         S("controller.leader_information", {"disturbance": True})),
    case("formation.followers 0", "~scenario/formation/followers",
         S("formation", {"followers": 0})),
    case("formation.followers missing", "~scenario/formation/followers",
         S("formation", {"topology": "chain"})),
    case("formation.topology a ring", "~scenario/formation/topology",
         S("formation", {"followers": 2, "topology": "ring"})),
    case("formation.shape v in 1-D", "~scenario/formation/shape",
         S("formation", {"followers": 2, "shape": "v"})),
    case("~trigger measurement with path slots", "~trigger",
         S("formation", {"followers": 1, "slots": "path"}), options={"trigger": "measurement"},
         nodes=(FOLLOWER,)),
    case("formation.path.damping 0", "~scenario/formation/path/damping",
         S("formation", {"followers": 1, "slots": "path", "path": {"damping": 0.0}})),
    case("formation.path.capacity 1", "~scenario/formation/path/capacity",
         S("formation", {"followers": 1, "slots": "path", "path": {"capacity": 1}})),
    case("acceleration_limit a string", "~scenario/controller/acceleration_limit",
         S("controller.acceleration_limit", "inf")),
    case("leader.initial_state nested", "~scenario/leader/initial_state",
         S("leader.initial_state", [[5.0], [0.0]])),
    case("leader.disturbance a map", "~scenario/leader/disturbance",
         S("leader.disturbance", {"start": 20.0, "end": 23.0, "vector": [-2.0, -2.0]})),
    case("leader.disturbance item a number", "~scenario/leader/disturbance/0",
         S("leader.disturbance", [5])),
    case("leader.disturbance.0.start a string", "~scenario/leader/disturbance/0/start",
         S("leader.disturbance.0.start", "20")),
    case("leader.input a list", "~scenario/leader/input", S("leader.input", [1.0])),
    case("leader.input.sinusoids a string", "~scenario/leader/input/sinusoids",
         S("leader.input", {"sinusoids": "none"})),
    case("follower a list", "~scenario/follower", S("follower", [0.0, 0.0])),
    case("simulation.duration a string", "~scenario/simulation/duration",
         S("simulation.duration", "60 s")),
]

OUT_OF_RANGE = [
    case("alpha = 1", "~scenario/controller/alpha", S("controller.alpha", 1.0)),
    case("alpha = 1 (integer)", "~scenario/controller/alpha", S("controller.alpha", 1)),
    case("alpha = 1.5", "~scenario/controller/alpha", S("controller.alpha", 1.5)),
    case("alpha < 0", "~scenario/controller/alpha", S("controller.alpha", -0.1)),
    case("alpha NaN", "~scenario/controller/alpha", S("controller.alpha", NAN)),
    case("epsilon = 0", "~scenario/controller/epsilon", S("controller.epsilon", 0.0)),
    case("epsilon < 0", "~scenario/controller/epsilon", S("controller.epsilon", -0.2)),
    case("epsilon inf", "~scenario/controller/epsilon", S("controller.epsilon", INF)),
    case("control_rate = 0", "~scenario/controller/control_rate",
         S("controller.control_rate", 0)),
    case("control_rate < 0", "~scenario/controller/control_rate",
         S("controller.control_rate", -100.0)),
    case("control_rate NaN", "~scenario/controller/control_rate",
         S("controller.control_rate", NAN)),
    case("control_rate inf", "~scenario/controller/control_rate",
         S("controller.control_rate", INF)),
    case("control_rate -inf", "~scenario/controller/control_rate",
         S("controller.control_rate", -INF)),
    case("control_rate far too low for ROS", "~scenario/controller/control_rate",
         S("controller.control_rate", 1e-9)),
    case("control_rate far too high for ROS", "~scenario/controller/control_rate",
         S("controller.control_rate", 1e12)),
    case("separation NaN", "~scenario/controller/separation",
         S("controller.separation", [NAN, 0.0])),
    case("separation inf", "~scenario/controller/separation",
         S("controller.separation", [INF, 0.0])),
    case("separation zero", "~scenario/controller/separation",
         S("controller.separation", [0.0, 0.0])),
    case("baseline.gain NaN", "~scenario/controller/baseline/gain",
         baseline_gain([[NAN, 1.4]])),
    case("natural_frequency < 0", "~scenario/controller/baseline/natural_frequency",
         S("controller.baseline.natural_frequency", -1.0)),
    case("natural_frequency inf", "~scenario/controller/baseline/natural_frequency",
         S("controller.baseline.natural_frequency", INF)),
    case("damping = 0", "~scenario/controller/baseline/damping",
         S("controller.baseline.damping", 0.0)),
    case("damping NaN", "~scenario/controller/baseline/damping",
         S("controller.baseline.damping", NAN)),
    case("estimator.gain inf", "~scenario/controller/estimator/gain",
         S("controller.estimator.gain", INF)),
    case("estimator.gain NaN entry", "~scenario/controller/estimator/gain",
         S("controller.estimator.gain", [[-5.0, 0.0], [0.0, NAN]])),
    case("lyapunov_weight NaN", "~scenario/controller/estimator/lyapunov_weight",
         S("controller.estimator.lyapunov_weight", NAN)),
    case("lyapunov_weight not positive definite",
         "~scenario/controller/estimator/lyapunov_weight",
         S("controller.estimator.lyapunov_weight", [[1.0, 2.0], [2.0, 1.0]])),
    case("lyapunov_weight negative", "~scenario/controller/estimator/lyapunov_weight",
         S("controller.estimator.lyapunov_weight", -1.0)),
    case("lyapunov_weight not symmetric", "~scenario/controller/estimator/lyapunov_weight",
         S("controller.estimator.lyapunov_weight", [[1.0, 0.5], [0.0, 1.0]])),
    case("substeps = 0", "~scenario/controller/estimator/substeps",
         S("controller.estimator.substeps", 0)),
    case("substeps < 0", "~scenario/controller/estimator/substeps",
         S("controller.estimator.substeps", -1)),
    case("substeps = 1001", "~scenario/controller/estimator/substeps",
         S("controller.estimator.substeps", 1001)),
    case("substeps huge", "~scenario/controller/estimator/substeps",
         S("controller.estimator.substeps", 2000000000)),
    case("substeps beyond an int", "~scenario/controller/estimator/substeps",
         S("controller.estimator.substeps", 1e12)),
    case("substeps NaN", "~scenario/controller/estimator/substeps",
         S("controller.estimator.substeps", NAN)),
    case("initial_estimate unknown", "~scenario/controller/estimator/initial_estimate",
         S("controller.estimator.initial_estimate", "guess")),
    case("reference_gain NaN", "~scenario/controller/tracker/reference_gain",
         S("controller.tracker.reference_gain", [[NAN, 0.0]])),
    case("acceleration_limit = 0", "~scenario/controller/acceleration_limit",
         S("controller.acceleration_limit", 0.0)),
    case("acceleration_limit < 0", "~scenario/controller/acceleration_limit",
         S("controller.acceleration_limit", -1.0)),
    case("acceleration_limit NaN", "~scenario/controller/acceleration_limit",
         S("controller.acceleration_limit", NAN)),
    case("acceleration_limit -inf", "~scenario/controller/acceleration_limit",
         S("controller.acceleration_limit", -INF)),
    case("model.type unknown", "~scenario/model/type", S("model.type", "triple_integrator")),
    case("model.type linear (valid, but not for the nodes)", "~scenario/model/type",
         S("model", {"type": "linear", "A": [[0.0, 1.0], [0.0, 0.0]], "B": [[0.0], [1.0]],
                     "position_dimension": 1},
           "controller.baseline", {"gain": [[1.0, 1.4]]})),
    case("leader.initial_state NaN", "~scenario/leader/initial_state",
         S("leader.initial_state", [NAN, 0.0])),
    case("follower.initial_state inf", "~scenario/follower/initial_state",
         S("follower.initial_state", [0.0, INF])),
    case("disturbance vector NaN", "~scenario/leader/disturbance/0/vector",
         S("leader.disturbance.0.vector", [NAN, 0.0])),
    case("disturbance start NaN", "~scenario/leader/disturbance/0/start",
         S("leader.disturbance.0.start", NAN)),
    case("disturbance end before start", "~scenario/leader/disturbance/0/end",
         S("leader.disturbance.0.end", 10.0)),
    case("input pulse vector inf", "~scenario/leader/input/pulses/0/vector",
         S("leader.input", {"pulses": [{"start": 0.0, "end": 1.0, "vector": [INF]}]})),
    case("input sinusoid frequency NaN", "~scenario/leader/input/sinusoids/0/frequency",
         S("leader.input", {"sinusoids": [{"amplitude": [0.1], "frequency": NAN}]})),
    case("simulation.duration = 0", "~scenario/simulation/duration",
         S("simulation.duration", 0)),
    case("simulation.duration < 0", "~scenario/simulation/duration",
         S("simulation.duration", -5.0)),
    case("simulation.duration inf", "~scenario/simulation/duration",
         S("simulation.duration", INF)),
]

NOT_HURWITZ = [
    case("G = 0", "~scenario/controller/baseline/gain", baseline_gain([[0.0, 0.0]])),
    case("G negative stiffness", "~scenario/controller/baseline/gain",
         baseline_gain([[-1.0, 1.4]])),
    case("G negative damping", "~scenario/controller/baseline/gain",
         baseline_gain([[1.0, -1.4]])),
    case("L = +5 I", "~scenario/controller/estimator/gain", S("controller.estimator.gain", 5.0)),
    case("L with A_c + L C unstable", "~scenario/controller/estimator/gain",
         S("controller.estimator.gain", [[1.0, 0.0], [0.0, -5.0]])),
    case("G_e negative", "~scenario/controller/tracker/gain",
         S("controller.tracker.gain", [[-10.0, -5.0]])),
    case("G_e marginal (eigenvalue 0)", "~scenario/controller/tracker/gain",
         S("controller.tracker.gain", [[-1.0, 0.0]])),
    case("G_e anti-damping", "~scenario/controller/tracker/gain",
         S("controller.tracker.gain", [[0.0, -3.0]])),
]

NOT_IN_KERNEL = [
    case("d = [5, 1]", "~scenario/controller/separation", S("controller.separation", [5.0, 1.0])),
    case("d = [5, -0.5]", "~scenario/controller/separation",
         S("controller.separation", [5.0, -0.5])),
    case("d = [5, 1e-3]", "~scenario/controller/separation",
         S("controller.separation", [5.0, 1e-3])),
    case("d = [0, 1] (velocity only)", "~scenario/controller/separation",
         S("controller.separation", [0.0, 1.0])),
    case("2-D, d with a velocity", "~scenario/controller/separation",
         then(two_axes, S("controller.separation", [5.0, 0.0, 0.0, 0.5]))),
]

WRONG_SIZE = [
    case("model.dimension = 0", "~scenario/model/dimension", S("model.dimension", 0)),
    case("model.dimension = 4", "~scenario/model/dimension", S("model.dimension", 4)),
    case("model.dimension < 0", "~scenario/model/dimension", S("model.dimension", -1)),
    case("model.dimension huge", "~scenario/model/dimension", S("model.dimension", 1000000)),
    case("model.C wrong columns", "~scenario/model/C", S("model.C", [[1.0, 0.0, 0.0]])),
    case("G wrong columns", "~scenario/controller/baseline/gain",
         baseline_gain([[1.0, 1.4, 0.0]])),
    case("G wrong rows", "~scenario/controller/baseline/gain",
         baseline_gain([[1.0, 1.4], [1.0, 1.4]])),
    case("G an empty list", "~scenario/controller/baseline/gain", baseline_gain([])),
    case("G an empty row", "~scenario/controller/baseline/gain", baseline_gain([[]])),
    case("G a number (not square)", "~scenario/controller/baseline/gain", baseline_gain(1.0)),
    case("natural_frequency one per axis too many",
         "~scenario/controller/baseline/natural_frequency",
         S("controller.baseline.natural_frequency", [1.0, 1.0])),
    case("damping one per axis too many", "~scenario/controller/baseline/damping",
         S("controller.baseline.damping", [0.7, 0.7])),
    case("L wrong rows", "~scenario/controller/estimator/gain",
         S("controller.estimator.gain", [[-5.0, 0.0]])),
    case("L ragged rows", "~scenario/controller/estimator/gain",
         S("controller.estimator.gain", [[-5.0, 0.0], [0.0]])),
    case("Q wrong size", "~scenario/controller/estimator/lyapunov_weight",
         S("controller.estimator.lyapunov_weight", [[1.0]])),
    case("G_e wrong columns", "~scenario/controller/tracker/gain",
         S("controller.tracker.gain", [[10.0]])),
    case("G_e ragged rows", "~scenario/controller/tracker/gain",
         S("controller.tracker.gain", [[10.0, 5.0], [1.0]])),
    case("S_21 wrong columns", "~scenario/controller/tracker/reference_gain",
         S("controller.tracker.reference_gain", [[0.0, 0.0, 0.0]])),
    case("S_21 a number (not square)", "~scenario/controller/tracker/reference_gain",
         S("controller.tracker.reference_gain", 1.0)),
    case("d too short", "~scenario/controller/separation", S("controller.separation", [5.0])),
    case("d too long", "~scenario/controller/separation",
         S("controller.separation", [5.0, 0.0, 0.0])),
    case("d empty", "~scenario/controller/separation", S("controller.separation", [])),
    case("2-D, d of 1-D length", "~scenario/controller/separation",
         then(two_axes, S("controller.separation", [5.0, 0.0]))),
    case("~scenario file: model.dimension = 4", "~scenario/model/dimension",
         scenario="@bad_dimension.yaml"),
    case("leader.initial_state too short", "~scenario/leader/initial_state",
         S("leader.initial_state", [5.0])),
    case("follower.initial_state too long", "~scenario/follower/initial_state",
         S("follower.initial_state", [0.0, 0.0, 0.0])),
    case("2-D, follower.initial_state of 1-D length", "~scenario/follower/initial_state",
         then(two_axes, S("follower.initial_state", [0.0, 0.0]))),
    case("disturbance vector too short", "~scenario/leader/disturbance/0/vector",
         S("leader.disturbance.0.vector", [-2.0])),
    case("input pulse vector too long", "~scenario/leader/input/pulses/0/vector",
         S("leader.input", {"pulses": [{"start": 0.0, "end": 1.0, "vector": [0.5, 0.5]}]})),
    case("sinusoid amplitude too long", "~scenario/leader/input/sinusoids/0/amplitude",
         S("leader.input", {"sinusoids": [{"amplitude": [0.1, 0.1], "frequency": 0.05}]})),
]

UNKNOWN_KEY = [
    case("controller.alfa", "~scenario/controller/alfa", S("controller.alfa", 0.2)),
    case("top level", "~scenario/extra", S("extra", 1)),
    case("controller.tracker.gian", "~scenario/controller/tracker/gian",
         S("controller.tracker.gian", [[1.0, 1.0]])),
    case("leader.disturbance.0.strength", "~scenario/leader/disturbance/0/strength",
         S("leader.disturbance.0.strength", 1.0)),
    case("model.A for a double integrator", "~scenario/model/A", S("model.A", [[0.0]])),
]


# Each refusal names the limit (the message of the node is checked for it) and where.
SIZE_LIMIT = [
    case("~scenario file over the size limit", "~scenario", scenario="@too_large.yaml"),
]
DEPTH_LIMIT = [
    case("~scenario file nested beyond the depth limit", "~scenario",
         scenario="@too_deep.yaml"),
    # From the parameter server: the innermost list beyond the limit, by its path (the
    # scenario's map is the first level, extra's lists the next ones).
    case("~scenario map nested beyond the depth limit",
         "~scenario/extra" + "/0" * (MAX_DEPTH - 1), S("extra", nested_lists(MAX_DEPTH))),
]
NODE_LIMIT = [
    case("~scenario file with an alias bomb", "~scenario", scenario="@alias_bomb.yaml"),
]

# Values the nodes refuse that the controller design would refuse too, naming another key: the
# nodes' own check runs first and names the key as written.
NODE_RANGE_FIRST = [
    case("control_rate 0.999 (RK4 also unstable with one substep)",
         "~scenario/controller/control_rate", S("controller.control_rate", 0.999)),
    case("~scenario file: control_rate 0.999", "~scenario/controller/control_rate",
         scenario="@slow_rate.yaml"),
    case("model.type linear with a gain that does not stabilise it", "~scenario/model/type",
         S("model", {"type": "linear", "A": [[0.0, 1.0], [0.0, 0.0]], "B": [[0.0], [1.0]],
                     "position_dimension": 1},
           "controller.baseline", {"gain": [[-1.0, 1.4]]})),
]


def opt(name, node, key, value):
    return case(name, "~" + key, options={key: value}, nodes=(node,))


def vehicle(name, key, entry, agent="follower", change=None):
    """A plant whose ~vehicles/<agent> is @p entry, refused naming ~vehicles/<agent>[/key]."""
    return case(name, f"~vehicles/{agent}" + (f"/{key}" if key else ""), change,
                options={"vehicles": {agent: entry}}, nodes=(PLANT,))


def on_thread(name, key, value):
    """A follower option spoiled on a follower with ~control_loop thread."""
    return case(name, "~" + key, options={"control_loop": "thread", key: value}, nodes=(FOLLOWER,))


# Run 2 with a time headway: the follower subscribes its own odometry (odom).
HEADWAY = S("controller.spacing", {"time_headway": 0.3})


def on_input(name, key, source, **options):
    """A follower on ~input @p source with @p options ("group/key" nested), refused naming
    @p key."""
    tree = {"input": source}
    for path, value in options.items():
        group, _, leaf = path.rpartition("/")
        (tree.setdefault(group, {}) if group else tree)[leaf] = value
    return case(name, "~" + key, options=tree, nodes=(FOLLOWER,))


NODE_OPTIONS = [
    # follower_node: the measurement's source and its adapters' options
    opt("input unknown", FOLLOWER, "input", "gps"),
    on_input("odometry twist_frame unknown", "odometry/twist_frame", "odometry",
             **{"odometry/twist_frame": "map"}),
    on_input("odometry max_skew < 0", "odometry/max_skew", "odometry",
             **{"odometry/max_skew": -0.1}),
    on_input("odometry pose_frame unknown", "odometry/pose_frame", "odometry",
             measurement_frame="world", **{"odometry/pose_frame": "map"}),
    on_input("odometry pose_frame world without a world frame", "measurement_frame",
             "odometry", **{"odometry/pose_frame": "world"}),
    # the time headway's own odometry (S1) reads the odometry conventions too
    case("time headway: odometry pose_frame unknown", "~odometry/pose_frame", HEADWAY,
         options={"odometry": {"pose_frame": "child"}}, nodes=(FOLLOWER,)),
    case("time headway: odometry twist_frame unknown", "~odometry/twist_frame", HEADWAY,
         options={"odometry": {"twist_frame": "world"}}, nodes=(FOLLOWER,)),
    # command_adapter: the own odometry's conventions
    case("adapter odometry pose_frame unknown", "~odometry/pose_frame",
         options={"odometry": {"pose_frame": "World"}}, nodes=(ADAPTER,)),
    case("adapter odometry pose_frame world without a world frame", "~world_frame",
         options={"odometry": {"pose_frame": "world"}}, nodes=(ADAPTER,)),
    case("adapter odometry twist_frame unknown", "~odometry/twist_frame",
         options={"odometry": {"twist_frame": "world"}}, nodes=(ADAPTER,)),
    # command_adapter: the vehicle's response delay
    case("adapter velocity delay past max_delay", "~velocity/delay",
         options={"velocity": {"delay": 0.5, "max_delay": 0.3}}, nodes=(ADAPTER,)),
    case("adapter velocity max_delay past 255 periods", "~velocity/max_delay",
         options={"velocity": {"max_delay": 3.0}}, nodes=(ADAPTER,)),
    case("adapter velocity averaging_time zero", "~velocity/averaging_time",
         options={"velocity": {"averaging_time": 0.0}}, nodes=(ADAPTER,)),
    # command_adapter: the output limits are finite and > 0 (0 no longer means none)
    case("adapter velocity max_speed 0", "~velocity/max_speed",
         options={"velocity": {"max_speed": 0.0}}, nodes=(ADAPTER,)),
    case("adapter velocity max_speed inf", "~velocity/max_speed",
         options={"velocity": {"max_speed": INF}}, nodes=(ADAPTER,)),
    case("adapter unicycle max_speed NaN", "~unicycle/max_speed",
         options={"outputs": "unicycle", "unicycle": {"max_speed": NAN}}, nodes=(ADAPTER,)),
    case("adapter unicycle max_yaw_rate 0", "~unicycle/max_yaw_rate",
         options={"outputs": "unicycle", "unicycle": {"max_yaw_rate": 0.0}}, nodes=(ADAPTER,)),
    case("adapter unicycle max_yaw_rate past 1e4", "~unicycle/max_yaw_rate",
         options={"outputs": "unicycle", "unicycle": {"max_yaw_rate": 1e5}}, nodes=(ADAPTER,)),
    on_input("tf without a world frame", "measurement_frame", "tf",
             **{"tf/self_frame": "follower", "tf/target_frame": "leader"}),
    on_input("tf without its own frame", "tf/self_frame", "tf", measurement_frame="world",
             **{"tf/target_frame": "leader"}),
    on_input("tf without the target's frame", "tf/target_frame", "tf", measurement_frame="world",
             **{"tf/self_frame": "follower"}),
    on_input("tf rate above the control rate", "tf/rate", "tf", measurement_frame="world",
             **{"tf/self_frame": "follower", "tf/target_frame": "leader", "tf/rate": 1e5}),
    on_input("position velocity_bandwidth 0", "position/velocity_bandwidth", "position",
             **{"position/velocity_bandwidth": 0.0}),
    on_input("position velocity_bandwidth NaN", "position/velocity_bandwidth", "position",
             **{"position/velocity_bandwidth": NAN}),
    on_input("position max_gap 0", "position/max_gap", "position", **{"position/max_gap": 0.0}),
    on_input("position min_interval 0", "position/min_interval", "position",
             **{"position/min_interval": 0.0}),
    on_input("position min_interval NaN", "position/min_interval", "position",
             **{"position/min_interval": NAN}),
    on_input("position min_interval not below max_gap", "position/min_interval", "position",
             **{"position/min_interval": 0.2, "position/max_gap": 0.1}),
    on_input("position max_speed 0", "position/max_speed", "position",
             **{"position/max_speed": 0.0}),
    on_input("position max_speed inf", "position/max_speed", "position",
             **{"position/max_speed": INF}),
    on_input("position max_speed a string", "position/max_speed", "position",
             **{"position/max_speed": "fast"}),
    # follower_node: links and clocks (doc/multi_host.md)
    opt("transport unknown", FOLLOWER, "transport", "sctp"),
    opt("status_rate < 0", FOLLOWER, "status_rate", -1.0),
    opt("status_rate above the control rate", FOLLOWER, "status_rate", 1e6),
    case("clock_skew policy unknown", "~clock_skew/policy",
         options={"clock_skew": {"policy": "ntp"}}, nodes=(FOLLOWER,)),
    case("clock_skew window 0", "~clock_skew/window",
         options={"clock_skew": {"policy": "estimate", "window": 0.0}}, nodes=(FOLLOWER,)),
    case("clock_skew max_offset < 0", "~clock_skew/max_offset",
         options={"clock_skew": {"max_offset": -1.0}}, nodes=(FOLLOWER,)),
    case("clock_skew max_drift_rate > 1", "~clock_skew/max_drift_rate",
         options={"clock_skew": {"policy": "estimate", "max_drift_rate": 2.0}},
         nodes=(FOLLOWER,)),
    case("clock_skew max_drift_rate NaN", "~clock_skew/max_drift_rate",
         options={"clock_skew": {"max_drift_rate": NAN}}, nodes=(FOLLOWER,)),
    # follower_node
    opt("measurement_timeout < 0", FOLLOWER, "measurement_timeout", -1.0),
    opt("measurement_timeout = 0", FOLLOWER, "measurement_timeout", 0),
    opt("measurement_timeout below a period", FOLLOWER, "measurement_timeout", 1e-4),
    opt("measurement_timeout NaN", FOLLOWER, "measurement_timeout", NAN),
    opt("measurement_timeout inf", FOLLOWER, "measurement_timeout", INF),
    opt("measurement_timeout a string", FOLLOWER, "measurement_timeout", "fast"),
    opt("measurement_timeout a numeric string", FOLLOWER, "measurement_timeout", "0.5"),
    opt("measurement_timeout a list", FOLLOWER, "measurement_timeout", [1.0]),
    opt("measurement_timeout a boolean", FOLLOWER, "measurement_timeout", True),
    opt("measurement_timeout a map", FOLLOWER, "measurement_timeout", {"s": 1.0}),
    opt("leader_timeout = 0", FOLLOWER, "leader_timeout", 0.0),
    opt("leader_timeout a string", FOLLOWER, "leader_timeout", "x"),
    opt("max_future_stamp < 0", FOLLOWER, "max_future_stamp", -0.1),
    opt("max_future_stamp NaN", FOLLOWER, "max_future_stamp", NAN),
    opt("use_leader_broadcast a string", FOLLOWER, "use_leader_broadcast", "true"),
    opt("use_leader_broadcast an integer", FOLLOWER, "use_leader_broadcast", 1),
    opt("measurement_frame a number", FOLLOWER, "measurement_frame", 5),
    opt("measurement_frame a boolean", FOLLOWER, "measurement_frame", True),
    opt("leader_broadcast_frame a number", FOLLOWER, "leader_broadcast_frame", 7),
    opt("follower_frame a number", FOLLOWER, "follower_frame", 3.0),
    opt("follower_frame a list", FOLLOWER, "follower_frame", ["follower"]),
    opt("formation_index beyond the formation", FOLLOWER, "formation_index", 2),
    opt("formation_index 0", FOLLOWER, "formation_index", 0),
    opt("formation_index a string", FOLLOWER, "formation_index", "1"),
    opt("marker_rate a string", FOLLOWER, "marker_rate", "fast"),
    opt("marker_rate < 0", FOLLOWER, "marker_rate", -1.0),
    opt("marker_rate above the control rate", FOLLOWER, "marker_rate", 1e6),
    opt("marker_rate NaN", FOLLOWER, "marker_rate", NAN),
    opt("trigger unknown", FOLLOWER, "trigger", "sometimes"),
    opt("trigger empty", FOLLOWER, "trigger", ""),
    opt("trigger capitalised", FOLLOWER, "trigger", "Timer"),
    opt("trigger a number", FOLLOWER, "trigger", 1),
    opt("trigger a boolean", FOLLOWER, "trigger", True),
    opt("control_loop unknown", FOLLOWER, "control_loop", "realtime"),
    opt("control_loop empty", FOLLOWER, "control_loop", ""),
    opt("control_loop capitalised", FOLLOWER, "control_loop", "Thread"),
    opt("control_loop a number", FOLLOWER, "control_loop", 1),
    opt("control_loop a boolean", FOLLOWER, "control_loop", True),
    on_thread("control_priority 100", "control_priority", 100),
    on_thread("control_priority -1", "control_priority", -1),
    on_thread("control_priority not whole", "control_priority", 50.5),
    on_thread("control_priority a string", "control_priority", "80"),
    on_thread("control_priority a boolean", "control_priority", True),
    opt("control_priority without ~control_loop", FOLLOWER, "control_priority", 80),
    case("control_priority with ~control_loop timer", "~control_priority",
         options={"control_loop": "timer", "control_priority": 1}, nodes=(FOLLOWER,)),
    opt("lock_memory a string", FOLLOWER, "lock_memory", "true"),
    opt("lock_memory an integer", FOLLOWER, "lock_memory", 1),
    # plant_node
    opt("rate < 0", PLANT, "rate", -1.0),
    opt("rate = 0", PLANT, "rate", 0),
    opt("rate NaN", PLANT, "rate", NAN),
    opt("rate inf", PLANT, "rate", INF),
    opt("rate too high", PLANT, "rate", 1e5),
    opt("rate a string", PLANT, "rate", "fast"),
    opt("rate a boolean", PLANT, "rate", True),
    opt("world_frame empty", PLANT, "world_frame", ""),
    opt("world_frame a number", PLANT, "world_frame", 5),
    opt("leader_frame = world_frame", PLANT, "leader_frame", "world"),
    opt("follower_frame = leader_frame", PLANT, "follower_frame", "leader"),
    opt("follower_frame empty", PLANT, "follower_frame", ""),
    opt("measurement_noise_position < 0", PLANT, "measurement_noise_position", -0.1),
    opt("measurement_noise_position NaN", PLANT, "measurement_noise_position", NAN),
    opt("measurement_noise_position a string", PLANT, "measurement_noise_position", "x"),
    opt("measurement_noise_velocity < 0", PLANT, "measurement_noise_velocity", -1.0),
    opt("measurement_noise_velocity inf", PLANT, "measurement_noise_velocity", INF),
    opt("measurement_dropout > 1", PLANT, "measurement_dropout", 1.5),
    opt("measurement_dropout = 1", PLANT, "measurement_dropout", 1),
    opt("measurement_dropout = 1.0", PLANT, "measurement_dropout", 1.0),
    opt("measurement_dropout < 0", PLANT, "measurement_dropout", -0.1),
    opt("measurement_dropout NaN", PLANT, "measurement_dropout", NAN),
    opt("measurement_latency < 0", PLANT, "measurement_latency", -0.1),
    opt("measurement_latency too long", PLANT, "measurement_latency", 2.0),
    opt("measurement_latency NaN", PLANT, "measurement_latency", NAN),
    opt("measurement_outage_start < 0", PLANT, "measurement_outage_start", -1.0),
    opt("measurement_outage_start a string", PLANT, "measurement_outage_start", "later"),
    opt("measurement_outage_duration NaN", PLANT, "measurement_outage_duration", NAN),
    opt("measurement_outage_duration inf", PLANT, "measurement_outage_duration", INF),
    opt("noise_seed < 0", PLANT, "noise_seed", -1),
    opt("noise_seed not whole", PLANT, "noise_seed", 1.5),
    opt("noise_seed a string", PLANT, "noise_seed", "x"),
    opt("command_timeout = 0", PLANT, "command_timeout", 0.0),
    opt("command_timeout < 0", PLANT, "command_timeout", -1.0),
    opt("command_timeout NaN", PLANT, "command_timeout", NAN),
    opt("publish_clock a string", PLANT, "publish_clock", "yes"),
    opt("publish_clock an integer", PLANT, "publish_clock", 1),
    opt("real_time_factor = 0", PLANT, "real_time_factor", 0.0),
    opt("real_time_factor < 0", PLANT, "real_time_factor", -1.0),
    opt("real_time_factor inf", PLANT, "real_time_factor", INF),
    opt("duration < 0", PLANT, "duration", -1.0),
    opt("duration NaN", PLANT, "duration", NAN),
    opt("wait_for_subscribers a string", PLANT, "wait_for_subscribers", "/follower/status"),
    opt("wait_for_subscribers a map", PLANT, "wait_for_subscribers", {"a": 1}),
    case("wait_for_subscribers entry a number", "~wait_for_subscribers[1]",
         options={"wait_for_subscribers": ["/a", 3]}, nodes=(PLANT,)),
    case("wait_for_subscribers entry not a name", "~wait_for_subscribers[0]",
         options={"wait_for_subscribers": ["no spaces"]}, nodes=(PLANT,)),
    case("wait_for_subscribers entry empty", "~wait_for_subscribers[0]",
         options={"wait_for_subscribers": [""]}, nodes=(PLANT,)),
    case("wait_for_subscribers over 1024 entries", "~wait_for_subscribers",
         options={"wait_for_subscribers": ["/a"] * 1025}, nodes=(PLANT,)),
    case("wait_for_subscribers without publish_clock", "~wait_for_subscribers",
         options={"wait_for_followers": 5.0, "wait_for_subscribers": ["/a"]}, nodes=(PLANT,)),
    case("wait_for_subscribers without wait_for_followers", "~wait_for_subscribers",
         options={"publish_clock": True, "wait_for_subscribers": ["/a"]}, nodes=(PLANT,)),
    # plant_node ~vehicles (Run 2 is 1-D with one follower: agents leader and follower)
    opt("vehicles a list", PLANT, "vehicles", [1, 2]),
    vehicle("vehicles entry a string", "", "velocity"),
    vehicle("vehicles unknown agent", "", {"kind": "velocity"}, agent="follower_1"),
    vehicle("vehicle kind unknown", "kind", {"kind": "tank"}),
    vehicle("vehicle odom_frame the world frame", "odom_frame",
            {"kind": "velocity", "odom_frame": "world"}),
    vehicle("vehicle kind a number", "kind", {"kind": 2}),
    vehicle("unicycle on one axis", "kind", {"kind": "unicycle"}),
    vehicle("vehicle key unknown", "wheel_base", {"kind": "velocity", "wheel_base": 0.3}),
    vehicle("velocity_lag on a double integrator", "velocity_lag", {"velocity_lag": 0.1},
            agent="leader"),
    vehicle("max_yaw_rate on a velocity vehicle", "max_yaw_rate",
            {"kind": "velocity", "max_yaw_rate": 1.0}),
    vehicle("twist_frame on a unicycle", "twist_frame",
            {"kind": "unicycle", "twist_frame": "world"}, change=two_axes),
    vehicle("velocity_lag < 0", "velocity_lag", {"kind": "velocity", "velocity_lag": -0.1}),
    vehicle("velocity_lag NaN", "velocity_lag", {"kind": "velocity", "velocity_lag": NAN}),
    vehicle("max_speed = 0", "max_speed", {"kind": "velocity", "max_speed": 0.0}),
    vehicle("max_speed a string", "max_speed", {"kind": "velocity", "max_speed": "fast"}),
    vehicle("heading inf", "heading", {"kind": "velocity", "heading": INF}),
    vehicle("twist_frame unknown", "twist_frame", {"kind": "velocity", "twist_frame": "base"}),
    vehicle("max_yaw_rate < 0", "max_yaw_rate", {"kind": "unicycle", "max_yaw_rate": -1.0},
            change=two_axes),
    # leader_node
    opt("rate = 0", LEADER, "rate", 0.0),
    opt("rate < 0", LEADER, "rate", -5),
    opt("rate NaN", LEADER, "rate", NAN),
    opt("rate inf", LEADER, "rate", INF),
    opt("rate a string", LEADER, "rate", "x"),
    opt("leader_frame empty", LEADER, "leader_frame", ""),
    opt("leader_frame a number", LEADER, "leader_frame", 3),
    opt("share_disturbance a string", LEADER, "share_disturbance", "false"),
    opt("share_disturbance an integer", LEADER, "share_disturbance", 0),
    # link_relay
    opt("relay max_in_flight_bytes below 1024", RELAY, "max_in_flight_bytes", 100),
    opt("relay max_in_flight_bytes a double", RELAY, "max_in_flight_bytes", 1e6),
    opt("relay max_future_stamp < 0", RELAY, "max_future_stamp", -0.1),
    opt("relay max_future_stamp NaN", RELAY, "max_future_stamp", NAN),
]

# outcome: "exited", "running" or "hung"; stopped: after "running", whether SIGINT ended it
# within STOP_DEADLINE (else it was killed).
Result = collections.namedtuple("Result", "outcome code output seconds stopped")


class InvalidParameters(unittest.TestCase):
    counter = 0
    directory = None

    @classmethod
    def setUpClass(cls):
        cls.directory = tempfile.mkdtemp(prefix="invalid_parameters_")
        with open(paper_path()) as stream:
            paper_text = stream.read()
        def spoiled(old, new):
            assert paper_text.count(old) == 1, f"paper_run2.yaml: no single '{old}'"
            return paper_text.replace(old, new)

        contents = dict(FILES)
        contents["quoted_alpha.yaml"] = spoiled("alpha: 0.2", 'alpha: "0.2"')
        contents["complex_key.yaml"] = spoiled("controller:\n", "controller:\n  [1, 2]: 3\n")
        contents["bad_dimension.yaml"] = spoiled("dimension: 1", "dimension: 4")
        contents["too_large.yaml"] = paper_text + "#" + "x" * MAX_BYTES + "\n"
        contents["too_deep.yaml"] = spoiled(
            "controller:\n", "controller:\n  extra: " + "[" * (2 * MAX_DEPTH) +
            "]" * (2 * MAX_DEPTH) + "\n")
        contents["alias_bomb.yaml"] = paper_text + alias_bomb()
        contents["slow_rate.yaml"] = spoiled("control_rate: 1000.0", "control_rate: 0.999")
        for name, text in contents.items():
            with open(os.path.join(cls.directory, name), "w") as stream:
                stream.write(text)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.directory, ignore_errors=True)

    # --- running nodes -------------------------------------------------------------------------

    def prepare(self, executable, scenario, options):
        """Sets the parameters of a fresh private namespace; returns the node name."""
        InvalidParameters.counter += 1
        name = f"invalid_{InvalidParameters.counter}_{executable}"
        tree = dict(options)
        if scenario is not MISSING:
            tree["scenario"] = scenario
        if tree:
            rospy.set_param(f"/{name}", tree)
        return name

    @staticmethod
    def run_node(executable, name, deadline=None, prefix=()):
        """Runs a node (after the command @p prefix, if any) until it exits, logs that it runs
        (then it is stopped) or the deadline passes (then it is killed). The outcome is
        "exited", "running" or "hung"."""
        deadline = DEADLINE if deadline is None else deadline
        start = time.monotonic()
        # Line-buffered stdout, so that "running" is seen as soon as it is logged.
        environment = dict(os.environ, ROSCONSOLE_STDOUT_LINE_BUFFERED="1")
        process = subprocess.Popen([*prefix, node_executable(executable), f"__name:={name}"],
                                   stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                   errors="replace", env=environment)
        lines = []
        running = threading.Event()

        def pump():
            for line in process.stdout:
                lines.append(line)
                if RUNNING[executable] in line:
                    running.set()

        reader = threading.Thread(target=pump, daemon=True)
        reader.start()
        outcome = "hung"
        while time.monotonic() - start < deadline:
            if process.poll() is not None:
                outcome = "exited"
                break
            if running.wait(0.02):
                outcome = "running"
                break
        seconds = time.monotonic() - start
        stopped = True
        if outcome != "exited":
            process.send_signal(signal.SIGINT)
            try:
                process.wait(timeout=STOP_DEADLINE)
            except subprocess.TimeoutExpired:
                stopped = False
                process.kill()
                process.wait()
        reader.join(timeout=5.0)
        return Result(outcome, process.returncode, "".join(lines), seconds, stopped)

    def run_cases(self, cases, prefix=()):
        """Runs every (case, node) pair, several at a time, each after the command @p prefix;
        returns [(case, node, result)]."""
        jobs = []
        for c in cases:
            for node in c.nodes:
                scenario = c.scenario
                if scenario is None:
                    scenario = paper_scenario()
                    if c.change:
                        c.change(scenario)
                elif isinstance(scenario, str) and scenario.startswith("@"):
                    scenario = os.path.join(self.directory, scenario[1:])
                jobs.append((c, node, self.prepare(node, scenario, c.options)))
        with ThreadPoolExecutor(max_workers=PARALLEL) as pool:
            results = list(pool.map(lambda job: self.run_node(job[1], job[2], prefix=prefix),
                                    jobs))
        return [(c, node, result) for (c, node, _), result in zip(jobs, results)]

    def check_refused(self, cases, prefix=(), reasons=()):
        """Every run of @p cases must exit 1 naming the key (and, given @p reasons, with one of
        them in its output)."""
        failures = []
        runs = self.run_cases(cases, prefix)
        for c, node, r in runs:
            expected = f"invalid parameter {c.key}: "
            problem = None
            if r.outcome == "running":
                problem = "accepted it and started"
            elif r.outcome == "hung":
                problem = f"still running after {DEADLINE} s"
            elif r.code < 0 or r.code in (134, 139):
                problem = f"crashed (exit status {r.code})"
            elif r.code == 0:
                problem = "exited 0"
            elif r.code != 1:
                problem = f"exited {r.code}, expected 1"
            elif expected not in r.output:
                problem = f"the message does not name {c.key}"
            elif reasons and not any(reason in r.output for reason in reasons):
                problem = f"the message gives none of the reasons {reasons}"
            if problem:
                output = r.output if len(r.output) < 2000 else r.output[-2000:]
                failures.append(f"[{node}] {c.name}: {problem}\n{output.rstrip()}")
        if failures:
            self.fail(f"{len(failures)} of {len(runs)} runs failed:\n\n" + "\n\n".join(failures))

    # --- the classes of invalid parameter ------------------------------------------------------

    def test_missing_key(self):
        self.check_refused(MISSING_KEY)

    def test_wrong_type(self):
        self.check_refused(WRONG_TYPE)

    def test_out_of_range(self):
        self.check_refused(OUT_OF_RANGE)

    def test_not_hurwitz(self):
        self.check_refused(NOT_HURWITZ)

    def test_separation_not_in_kernel(self):
        self.check_refused(NOT_IN_KERNEL)

    def test_wrong_size(self):
        self.check_refused(WRONG_SIZE)

    def test_unknown_key(self):
        self.check_refused(UNKNOWN_KEY)

    def test_bad_node_option(self):
        self.check_refused(NODE_OPTIONS)

    def test_scenario_over_a_limit(self):
        self.check_refused(SIZE_LIMIT, reasons=("over the size limit of a scenario",))
        self.check_refused(DEPTH_LIMIT, reasons=("nested deeper than the depth limit",))
        self.check_refused(NODE_LIMIT, reasons=("over the node limit of a scenario",))

    def test_nodes_range_checks_before_the_design(self):
        self.check_refused(NODE_RANGE_FIRST,
                           reasons=("the ROS nodes run at", "the ROS nodes run double_integrator"))

    def test_thread_loop_refused_on_simulated_time(self):
        """~control_loop thread sleeps on the monotonic clock: with /use_sim_time true the
        follower refuses it naming ~control_loop (the timer loop still starts). /use_sim_time is
        global, so this runs alone and restores it."""
        previous = rospy.get_param("/use_sim_time", None)
        rospy.set_param("/use_sim_time", True)
        try:
            self.check_refused([
                case("control_loop thread on simulated time", "~control_loop",
                     options={"control_loop": "thread"}, nodes=(FOLLOWER,)),
                case("control_loop thread on simulated time, trigger measurement",
                     "~control_loop", options={"control_loop": "thread",
                                               "trigger": "measurement"}, nodes=(FOLLOWER,)),
            ])
            c = case("control_loop timer on simulated time", None,
                     options={"control_loop": "timer"}, nodes=(FOLLOWER,))
            [(_, _, r)] = self.run_cases([c])
            self.assertEqual(r.outcome, "running", r.output)
        finally:
            if previous is None:
                rospy.delete_param("/use_sim_time")
            else:
                rospy.set_param("/use_sim_time", previous)

    def test_realtime_refused_by_the_kernel(self):
        """A real-time request the kernel refuses ends the follower naming the parameter and the
        reason, rather than running without it: the node runs without CAP_SYS_NICE and
        CAP_IPC_LOCK (setpriv), with RLIMIT_RTPRIO 0 and a 64 KiB RLIMIT_MEMLOCK (prlimit)."""
        prefix = ("setpriv", "--inh-caps=-sys_nice,-ipc_lock",
                  "--bounding-set=-sys_nice,-ipc_lock", "prlimit", "--rtprio=0:0",
                  "--memlock=65536:65536")
        if not all(shutil.which(tool) for tool in ("setpriv", "prlimit")):
            self.skipTest("setpriv and prlimit (util-linux) are needed to drop the privileges")
        if subprocess.run([*prefix, "true"], capture_output=True).returncode != 0:
            self.skipTest("cannot drop CAP_SYS_NICE / CAP_IPC_LOCK here (setpriv needs "
                          "CAP_SETPCAP)")
        cases = [
            case("control_priority 80 without CAP_SYS_NICE", "~control_priority",
                 options={"control_loop": "thread", "control_priority": 80},
                 nodes=(FOLLOWER,)),
            case("lock_memory without CAP_IPC_LOCK", "~lock_memory",
                 options={"lock_memory": True}, nodes=(FOLLOWER,)),
        ]
        # The reason is the kernel's (strerror of EPERM or ENOMEM), not a generic failure.
        self.check_refused(cases, prefix,
                           reasons=("Operation not permitted", "Cannot allocate memory"))

    # --- valid parameters are accepted ---------------------------------------------------------

    def test_odometry_conventions_are_accepted(self):
        """~odometry/pose_frame world starts the follower on odometry with ~measurement_frame,
        the follower with a time headway alone (whose own odometry needs no world frame), and the
        command adapter with ~world_frame."""
        cases = [
            case("odometry input, pose_frame world", None,
                 options={"input": "odometry", "measurement_frame": "world",
                          "odometry": {"pose_frame": "world", "twist_frame": "header"}},
                 nodes=(FOLLOWER,)),
            case("time headway, pose_frame world", None, HEADWAY,
                 options={"odometry": {"pose_frame": "world"}}, nodes=(FOLLOWER,)),
            case("adapter, pose_frame world", None,
                 options={"world_frame": "world", "odometry": {"pose_frame": "world"}},
                 nodes=(ADAPTER,)),
        ]
        for c, node, r in self.run_cases(cases):
            self.assertEqual(r.outcome, "running", f"[{node}] {c.name}:\n{r.output}")
            self.assertTrue(r.stopped, f"[{node}] {c.name}: SIGINT did not end it")


    def test_whole_numbers_where_reals_are_expected_are_accepted(self):
        """alpha: 0, control_rate: 100 and the like (YAML integers) are valid: each node starts.
        Also the 2-D variant the kernel and size cases spoil, and ~scenario as a file path."""
        integers = paper_scenario()
        S("controller.control_rate", 100,
          "controller.alpha", 0,
          "controller.epsilon", 1,
          "controller.separation", [5, 0],
          "controller.baseline", {"gain": [[1, 2]]},
          "controller.estimator", {"gain": -5, "lyapunov_weight": 1, "substeps": 2},
          "controller.tracker", {"enabled": True, "gain": [[10, 5]], "reference_gain": 0},
          "controller.acceleration_limit", 50,
          "leader.initial_state", [5, 0],
          "leader.input", {"pulses": [{"start": 0, "end": 1, "vector": [1]}],
                           "sinusoids": [{"amplitude": [1], "frequency": 1, "phase": 0}]},
          "leader.disturbance", [{"start": 20, "end": 23, "vector": [-2, -2]}],
          "follower.initial_state", [0, 0],
          "simulation.duration", 60)(integers)
        options = {
            FOLLOWER: {"measurement_timeout": 1, "leader_timeout": 1, "max_future_stamp": 0,
                       "marker_rate": 10},
            PLANT: {"rate": 100, "measurement_noise_position": 0, "measurement_dropout": 0,
                    "measurement_latency": 0, "command_timeout": 1, "real_time_factor": 1,
                    "duration": 0},
            LEADER: {"rate": 100},
        }
        planar = paper_scenario()
        two_axes(planar)
        cases = [case("integers", None, scenario=integers, options=options[node], nodes=(node,))
                 for node in ALL_NODES]
        cases.append(case("2-D", None, scenario=planar))
        # The follower reads its own sections alone: without the simulation's it starts.
        followers_alone = paper_scenario()
        for section in ("leader", "follower", "simulation"):
            del followers_alone[section]
        cases.append(case("the follower's sections alone", None, scenario=followers_alone,
                          nodes=(FOLLOWER,)))
        cases.append(case("file path", None, scenario=paper_path()))
        for trigger in ("timer", "measurement"):
            cases.append(case("trigger " + trigger, None, options={"trigger": trigger},
                              nodes=(FOLLOWER,)))
            # The thread loop starts, and stops cleanly on SIGINT (checked below).
            cases.append(case("trigger %s, control_loop thread" % trigger, None,
                              options={"trigger": trigger, "control_loop": "thread",
                                       "control_priority": 0, "lock_memory": False},
                              nodes=(FOLLOWER,)))
        cases.append(case("control_loop timer, priority 0", None,
                          options={"control_loop": "timer", "control_priority": 0},
                          nodes=(FOLLOWER,)))
        failures = []
        for c, node, r in self.run_cases(cases):
            if r.outcome != "running":
                failures.append(f"[{node}] {c.name}: {r.outcome} (exit status {r.code}) instead "
                                f"of running\n{r.output.rstrip()}")
            elif not r.stopped:
                failures.append(f"[{node}] {c.name}: still running {STOP_DEADLINE} s after "
                                f"SIGINT\n{r.output.rstrip()[-2000:]}")
            elif r.code < 0 or r.code in (134, 139):
                failures.append(f"[{node}] {c.name}: crashed on SIGINT (exit status {r.code})")
        if failures:
            self.fail("\n\n".join(failures))


if __name__ == "__main__":
    rospy.init_node("test_invalid_parameters", anonymous=True)
    DEADLINE = rospy.get_param("~deadline", DEADLINE)
    STOP_DEADLINE = rospy.get_param("~stop_deadline", STOP_DEADLINE)
    rostest.rosrun(PACKAGE, "invalid_parameters", InvalidParameters, sys.argv)
