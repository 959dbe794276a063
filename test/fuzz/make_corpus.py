#!/usr/bin/env python3
"""Writes the seed corpus of fuzz_follower_controller into test/fuzz/corpus/ (or argv[1]).

The layout is the one decoded by test/fuzz/fuzz_follower_controller.cpp: a 64-byte parameter
header (bytes 0..15 the structural choices, zero bytes elsewhere: the default gains), then
operations, one byte each (low nibble: the call, high nibble r: repeated 1 + r^2 times) followed by
their values (a mode byte, 0 = ordinary, and a little-endian int16: value = ||d|| * v / 32768).
"""
import pathlib
import struct
import sys

# Header byte offsets.
KIND, AXES, ORDER, SUBSTEPS, LIMIT, FALLBACK, GAINS, FLAGS, NON_FINITE, SHADOW, OUTPUT = range(11)
TRACKER_OFF, LEADER_IN_COMMAND, LEADER_IN_ESTIMATOR, ZERO_INITIAL = 1, 2, 4, 8
# Operation codes (low nibble).
STEP, STEP_LEADER, FALLBACK_OP, FALLBACK_LEADER, SET_DESIGN, RESET = 0, 6, 10, 12, 13, 14


def header(**fields):
    data = bytearray(64)
    for name, value in fields.items():
        data[globals()[name.upper()]] = value
    return data


def value(x):
    """An ordinary entry x (in units of ||d||, |x| < 1)."""
    return bytes([0]) + struct.pack("<h", round(x * 32768))


def special(mode, extra=b""):
    return bytes([mode]) + extra


def op(code, repeat=0, *values):
    return bytes([code | (repeat << 4)]) + b"".join(values)


def seeds():
    # The paper's 1-D scenario: the leader 0.6 ||d|| beyond the slot, closing, for 1 + 15^2 ticks
    # (saturating the estimate), then the fallback, and the measurement back.
    yield "di1_paper", header() + op(STEP, 15, value(0.6), value(-0.2)) + op(
        FALLBACK_OP, 5) + op(STEP, 3, value(0.1), value(0.0))
    # 2-D with an acceleration limit, the leader's input shared, and the generic controller
    # alongside.
    yield "di2_limit_leader", header(
        axes=1, limit=4, flags=LEADER_IN_COMMAND | LEADER_IN_ESTIMATOR, shadow=3) + op(
            STEP_LEADER, 10, value(0.5), value(-0.5), value(0.1), value(0.2), value(0.3),
            value(-0.3)) + op(FALLBACK_LEADER, 4, value(0.2), value(0.0)) + op(
                STEP, 2, value(-0.9), value(0.9), value(0.0), value(0.0))
    # 3-D with NaN/inf measurements allowed: ordinary, NaN, +inf, then ordinary again.
    nan = special(14, bytes([0]))
    inf = special(14, bytes([1]))
    yield "di3_non_finite", header(axes=2, non_finite=3, limit=5, substeps=3) + op(
        STEP, 4, *[value(0.1 * i) for i in range(6)]) + op(
            STEP, 2, nan, *[value(0.0)] * 5) + op(STEP, 1, inf, *[value(0.5)] * 5) + op(
                STEP, 4, *[value(-0.2)] * 6)
    # Huge finite entries: DBL_MAX in the position, the denormal minimum in the velocity.
    yield "di1_huge", header(limit=4) + op(
        STEP, 2, special(13, bytes([0])), special(13, bytes([1]))) + op(
            STEP, 2, value(0.2), value(0.1))
    # Chains of three integrators on one axis behind a general C (p = n = 3).
    yield "chain3", header(kind=6, order=2) + op(STEP, 8, value(0.3), value(0.1), value(-0.1))
    # Two chains of two integrators with a stacked C (p = 2 n = 8), zero initial estimate.
    yield "chain2x2_stacked", header(kind=6, axes=1, order=1, output=1,
                                     flags=ZERO_INITIAL) + op(
                                         STEP, 6, *[value(0.05 * i) for i in range(8)])
    # dynamic_reconfigure and resets: alpha changes, the tracker goes off and on again.
    yield "di1_reconfigure", header(fallback=1) + op(STEP, 10, value(0.7), value(0.0)) + op(
        SET_DESIGN, 0, bytes([127]), bytes([1])) + op(STEP, 3, value(0.7), value(0.0)) + op(
            SET_DESIGN, 0, bytes([200]), bytes([0])) + op(RESET) + op(
                STEP, 2, value(-0.3), value(0.3))


def main():
    out = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else pathlib.Path(__file__).with_name(
        "corpus")
    out.mkdir(parents=True, exist_ok=True)
    for name, data in seeds():
        (out / name).write_bytes(bytes(data))
        print(f"{out / name}: {len(data)} bytes")


if __name__ == "__main__":
    main()
