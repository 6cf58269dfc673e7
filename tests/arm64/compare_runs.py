#!/usr/bin/env python3
"""Compares the outputs of one patrolmap run on amd64 and the same run on arm64 (scripts/cross_arm64.sh).

    compare_runs.py AMD64_DIR ARM64_DIR

Decisions must be identical: the node list (flight, time, frame), the loop closures (which nodes, which frames),
the change list's ids, every object's id and state, the summary's counts and the onboard events (type and id, in
order). Measured values may differ by what floating point allows between the two builds (GCC contracts
multiply-adds on aarch64; OpenCV's kernels differ at 1e-5): the tolerances below. Prints the largest difference of
each value and exits 1 on the first decision that differs or value out of its tolerance.
"""
import csv
import json
import math
import os
import sys

# Tolerances, set before the first comparison was run.
FEATURES = (2, 0.02)  # features of a node: absolute, relative
INLIERS = (2, 0.05)
BOW_SCORE = 0.02
MATCHED_FRACTION = 0.02
LOG_NFA = 2.0
POSITION_M = 0.05
CONFIDENCE = 0.02
VOXELS = (2, 0.02)


class Comparison:
    def __init__(self, left, right):
        self.left, self.right = left, right
        self.largest = {}
        self.failures = []

    def fail(self, what):
        self.failures.append(what)

    def same(self, what, a, b):
        if a != b:
            self.fail(f"{what}: {a!r} on amd64, {b!r} on arm64")

    def near(self, what, a, b, tolerance, relative=0.0):
        a, b = float(a), float(b)
        difference = abs(a - b)
        self.largest[what] = max(self.largest.get(what, 0.0), difference)
        if difference > max(tolerance, relative * max(abs(a), abs(b))):
            self.fail(f"{what}: {a} on amd64, {b} on arm64")

    def points(self, what, a, b):
        if a is None or b is None:
            self.same(what + " (located)", a is None, b is None)
            return
        self.near(what, math.dist(a, b), 0.0, POSITION_M)


def read_csv(folder, name):
    path = os.path.join(folder, name)
    with open(path, newline="") as file:
        return list(csv.DictReader(file))


def compare_nodes(c):
    left, right = read_csv(c.left, "nodes.csv"), read_csv(c.right, "nodes.csv")
    c.same("nodes", len(left), len(right))
    for a, b in zip(left, right):
        for key in ("node", "flight", "timestamp_ns", "frame_index"):
            c.same(f"node {a['node']} {key}", a[key], b[key])
        c.near("node features", a["features"], b["features"], *FEATURES)
    return len(left)


def compare_closures(c):
    left, right = read_csv(c.left, "loop_closures.csv"), read_csv(c.right, "loop_closures.csv")
    c.same("loop closures", len(left), len(right))
    for a, b in zip(left, right):
        name = f"closure {a['query_node']}"
        for key in ("query_node", "matched_node", "query_frame", "matched_frame"):
            c.same(f"{name} {key}", a[key], b[key])
        c.near("closure bow_score", a["bow_score"], b["bow_score"], BOW_SCORE)
        c.near("closure matched_fraction", a["matched_fraction"], b["matched_fraction"], MATCHED_FRACTION)
        c.near("closure inliers", a["inliers"], b["inliers"], *INLIERS)
        c.near("closure log_nfa", a["log_nfa"], b["log_nfa"], LOG_NFA)
    return len(left)


def compare_changes(c):
    path = os.path.join(c.left, "changes.json")
    if not os.path.exists(path):
        return None
    with open(path) as file:
        left = json.load(file)
    with open(os.path.join(c.right, "changes.json")) as file:
        right = json.load(file)
    c.same("summary", left["summary"], right["summary"])
    c.same("change ids", [e["id"] for e in left["changes"]], [e["id"] for e in right["changes"]])
    for a, b in zip(left["changes"], right["changes"]):
        c.same(f"{a['id']} channels", a["channels"], b["channels"])
        c.points("change position", a.get("position"), b.get("position"))
        c.near("change confidence", a["confidence"], b["confidence"], CONFIDENCE)
    objects = {o["id"]: o for o in right["objects"]}
    c.same("object ids", sorted(o["id"] for o in left["objects"]), sorted(objects))
    for a in left["objects"]:
        b = objects.get(a["id"])
        if b is None:
            continue
        c.same(f"{a['id']} state", a["state"], b["state"])
        c.same(f"{a['id']} site object", a.get("site_object"), b.get("site_object"))
        for end in ("before", "after"):
            c.points(f"object {end}", a.get(end), b.get(end))
    c.near("changed voxels", left["geometry"]["changed_voxels"], right["geometry"]["changed_voxels"], *VOXELS)
    return len(left["changes"])


def compare_events(c):
    path = os.path.join(c.left, "events.jsonl")
    if not os.path.exists(path):
        return None
    with open(path) as file:
        left = [json.loads(line) for line in file]
    with open(os.path.join(c.right, "events.jsonl")) as file:
        right = [json.loads(line) for line in file]
    c.same("events", [(e["type"], e["id"]) for e in left], [(e["type"], e["id"]) for e in right])
    for a, b in zip(left, right):
        c.points("event position", a.get("position"), b.get("position"))
    return len(left)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    c = Comparison(sys.argv[1], sys.argv[2])
    counts = {
        "nodes": compare_nodes(c),
        "loop closures": compare_closures(c),
        "changes": compare_changes(c),
        "events": compare_events(c),
    }
    said = ", ".join(f"{n} {what}" for what, n in counts.items() if n is not None)
    largest = ", ".join(f"{what} {value:.3g}" for what, value in sorted(c.largest.items()))
    name = os.path.basename(os.path.normpath(c.left)).removesuffix("-amd64")
    if c.failures:
        print(f"{name}: amd64 and arm64 differ ({said}):")
        for failure in c.failures[:20]:
            print("  " + failure)
        sys.exit(1)
    print(f"{name}: amd64 and arm64 agree on {said}; largest differences: {largest or 'none'}")


if __name__ == "__main__":
    main()
