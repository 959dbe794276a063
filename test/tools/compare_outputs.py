#!/usr/bin/env python3
"""Compares two directories written by test/tools/cf_sim_outputs.sh: for each file, identical
byte for byte, or the largest absolute difference of the numbers in it (CSV cells, summary
values) and the column where it is largest.

Usage: compare_outputs.py BEFORE AFTER
"""
import os
import re
import sys

NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[-+]?inf|nan")


def cells(path):
    with open(path) as f:
        lines = f.read().splitlines()
    if path.endswith(".csv"):
        header = lines[0].split(",")
        rows = [line.split(",") for line in lines[1:]]
        return header, rows
    return None, [[m.group(0) for m in NUMBER.finditer(line)] for line in lines]


def largest_difference(before, after):
    header, a = cells(before)
    _, b = cells(after)
    if len(a) != len(b) or any(len(x) != len(y) for x, y in zip(a, b)):
        return float("inf"), "shape"
    worst, where = 0.0, ""
    for x, y in zip(a, b):
        for j, (u, v) in enumerate(zip(x, y)):
            if u == v:
                continue
            d = abs(float(u) - float(v))
            if not d <= worst:
                worst, where = d, header[j] if header else f"value {j}"
    return worst, where


def main():
    before, after = sys.argv[1], sys.argv[2]
    same = 0
    for name in sorted(os.listdir(before)):
        a, b = os.path.join(before, name), os.path.join(after, name)
        if not os.path.exists(b):
            print(f"{name}: missing after")
            continue
        with open(a, "rb") as f, open(b, "rb") as g:
            if f.read() == g.read():
                same += 1
                continue
        worst, where = largest_difference(a, b)
        print(f"{name}: largest difference {worst:.3g} ({where})")
    print(f"{same} of {len(os.listdir(before))} files identical")


if __name__ == "__main__":
    main()
