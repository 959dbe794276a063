"""The scenario format of reference_sim.py: the allowed keys, --set overrides and the
value checks (doc/cf_sim.md, section 'Scenario files')."""

from __future__ import annotations

import math

import numpy as np
import yaml

import barrier_reference


PROG = "reference_sim"


class ScenarioError(Exception):
    """A scenario or override that does not follow doc/cf_sim.md, section 'Scenario files'."""


# A dict maps allowed keys to the schema of their value; None is a leaf
# (its value is checked when the scenario is built); a one-element list
# [schema] is a YAML list whose items follow schema.
_PULSE = {"start": None, "end": None, "vector": None}
_SINUSOID = {"amplitude": None, "frequency": None, "phase": None}
_GAIN = {"gain": None, "natural_frequency": None, "damping": None}
_VEHICLE = {"acceleration_limit": None, "input_gain": None, "actuator_lag": None}
SCHEMA = {
    "model": {
        "type": None,
        "dimension": None,
        "A": None,
        "B": None,
        "position_dimension": None,
        "C": None,
    },
    "controller": {
        "control_rate": None,
        "separation": None,
        "alpha": None,
        "epsilon": None,
        "baseline": dict(_GAIN),
        "estimator": {
            "gain": None,
            "lyapunov_weight": None,
            "substeps": None,
            "initial_estimate": None,
        },
        "tracker": {"enabled": None, "reference_gain": None, **_GAIN},
        "leader_information": {"command": None, "estimator": None, "disturbance": None},
        "acceleration_limit": None,     # sampled loop only (world, neighbours, --sampled)
        "jerk_limit": None,             # sampled loop only
        "safety_filter": barrier_reference.SCHEMA,   # sampled loop only (barrier_reference.py)
    },
    "leader": {
        "initial_state": None,
        "input": {"pulses": [_PULSE], "sinusoids": [_SINUSOID]},
        "disturbance": [_PULSE],
    },
    "follower": {"initial_state": None},
    "simulation": {"duration": None},
    "world": {
        "seed": None,
        "vehicle": dict(_VEHICLE),
        "followers": [{"index": None, "disturbance": [_PULSE], "sinusoids": [_SINUSOID],
                       "vehicle": dict(_VEHICLE)}],
        "gusts": {"rate": None, "magnitude": None, "min_duration": None, "max_duration": None,
                  "start": None, "end": None},
        "measurement_noise": {"position": None, "velocity": None},
    },
    "formation": {
        "followers": None,
        "topology": None,
        "shape": None,
        "half_angle": None,
        "slots": None,
        "turning": {
            "natural_frequency": None,
            "damping": None,
            "max_yaw_rate": None,
            "max_yaw_acceleration": None,
            "min_speed": None,
            "reversing": None,
        },
        "neighbours": {
            "radius": None,
            "perimeter": None,
            "braking_acceleration": None,
            "neighbour_acceleration": None,
            "rate": None,
            "max_neighbours": None,
        },
    },
}


def check_keys(node, schema, path=""):
    """Raise ScenarioError naming the first key that the format does not define."""
    if schema is None:
        return
    if isinstance(schema, list):
        if node is None:
            return
        if not isinstance(node, list):
            raise ScenarioError(f"{path}: expected a list")
        for i, item in enumerate(node):
            check_keys(item, schema[0], f"{path}.{i}")
        return
    if node is None:
        return
    if not isinstance(node, dict):
        raise ScenarioError(f"{path or '<root>'}: expected a mapping")
    for key, value in node.items():
        sub = f"{path}.{key}" if path else str(key)
        if key not in schema:
            raise ScenarioError(f"unknown key '{sub}'")
        check_keys(value, schema[key], sub)


def apply_override(root, assignment):
    """Apply one ``--set a.b.c=VALUE`` override to the raw scenario tree.

    VALUE is parsed as YAML. A path element that is an integer indexes a list
    (index == len appends, for the last element only). Missing mappings on
    the path are created; whether the resulting key is allowed is checked
    afterwards by check_keys().
    """
    if "=" not in assignment:
        raise ScenarioError(f"--set '{assignment}': expected key=value")
    dotted, text = assignment.split("=", 1)
    parts = dotted.strip().split(".")
    if not dotted.strip() or any(not p for p in parts):
        raise ScenarioError(f"--set '{assignment}': empty key")
    try:
        value = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise ScenarioError(f"--set {dotted}: cannot parse value: {exc}") from None
    node = root
    for depth, part in enumerate(parts):
        last = depth == len(parts) - 1
        where = ".".join(parts[: depth + 1])
        if isinstance(node, list):
            try:
                index = int(part)
            except ValueError:
                raise ScenarioError(f"--set {dotted}: '{where}' must be a list index") from None
            if index == len(node) and last:
                node.append(value)
                return
            if not 0 <= index < len(node):
                raise ScenarioError(f"--set {dotted}: index {index} out of range at '{where}'")
            if last:
                node[index] = value
                return
            node = node[index]
        elif isinstance(node, dict):
            if last:
                node[part] = value
                return
            if node.get(part) is None:
                node[part] = {}
            node = node[part]
        else:
            parent = ".".join(parts[:depth])
            raise ScenarioError(f"--set {dotted}: '{parent}' is not a mapping or list")


# --------------------------------------------------------------------------
# Value parsing helpers
# --------------------------------------------------------------------------

def is_number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def get(node, key, path, default=None, required=True):
    """Return node[key]; raise naming path.key if it is required and missing."""
    if isinstance(node, dict) and node.get(key) is not None:
        return node[key]
    if required:
        raise ScenarioError(f"missing key '{path + '.' if path else ''}{key}'")
    return default


def as_float(v, path):
    if not is_number(v):
        raise ScenarioError(f"{path}: expected a number, got {v!r}")
    x = float(v)
    if not math.isfinite(x):
        raise ScenarioError(f"{path}: not finite")
    return x


def as_bool(v, path):
    if not isinstance(v, bool):
        raise ScenarioError(f"{path}: expected true or false, got {v!r}")
    return v


def as_vector(v, path, size):
    if not isinstance(v, list) or not all(is_number(x) for x in v):
        raise ScenarioError(f"{path}: expected a list of {size} numbers")
    if len(v) != size:
        raise ScenarioError(f"{path}: expected {size} entries, got {len(v)}")
    return np.array(v, dtype=float)


def as_matrix(v, path, rows, cols):
    """A list of rows, or a plain number s meaning s*I (square only; 0 is any shape)."""
    if is_number(v):
        if rows != cols and float(v) != 0.0:
            raise ScenarioError(
                f"{path}: a plain number means s*I and needs a square matrix, "
                f"but the expected size is {rows} x {cols}")
        return float(v) * np.eye(rows, cols)
    if (not isinstance(v, list) or not v
            or not all(isinstance(r, list) and all(is_number(x) for x in r) for r in v)):
        raise ScenarioError(f"{path}: expected a {rows} x {cols} matrix (a list of rows)")
    if len(v) != rows or any(len(r) != cols for r in v):
        shape = f"{len(v)} x {len(v[0])}" if len(set(map(len, v))) == 1 else "ragged"
        raise ScenarioError(f"{path}: expected a {rows} x {cols} matrix, got {shape}")
    return np.array(v, dtype=float)


def as_axis_values(v, path, k):
    """A number (same on every axis) or a list of k numbers."""
    if is_number(v):
        return np.full(k, float(v))
    return as_vector(v, path, k)


def is_hurwitz(M):
    return M.size == 0 or bool(np.max(np.linalg.eigvals(M).real) < 0.0)
