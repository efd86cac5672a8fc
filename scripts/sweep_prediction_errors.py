#!/usr/bin/env python3
"""How well the controller's model predicts an object that the re-aim's sweep passes.

Reads a batch run with --logs (`airtwin batch SCENES --seeds N --logs --out DIR`): for every
decision after the first, every object, its predicted end (plans.csv: end_x, end_y) against where
it was at the next decision (plans.csv: x, y), and the closest the stagnation point came to it
while the servos turned from the previous command to this one (decisions.csv: pan_deg,
tilt_deg; the servos' rest-to-rest moves at the rig's 7 rad/s and 30 rad/s^2, every 10 ms, the
segments between; eqs. (1)-(2) with the default field model's geometry, airtwin.stagnation_point).
Prints the prediction error by that closest pass, for the re-aims whose s passes the object
closer than the new s lies from it (by 5 cm or more), and for the other decisions.
docs/controller.md ("The re-aim's sweep") has the figures and why they matter.

Usage: PYTHONPATH=build/python python3 scripts/sweep_prediction_errors.py DIR
"""
import csv
import glob
import math
import os
import sys
from collections import defaultdict

import airtwin

SPEED, ACCEL = 7.0, 30.0  # the servos' limits (rad/s, rad/s^2), models/nozzle_response.h
STEP = 0.01  # s
BINS = [0.0, 0.05, 0.10, 0.15, 0.20, 0.30, math.inf]


def servo_move(start, end):
    """The axis angle (rad) as a function of time for a rest-to-rest move, and its duration."""
    d = abs(end - start)
    sign = 1.0 if end >= start else -1.0
    if d == 0.0:
        return (lambda t: start), 0.0
    ramp = min(math.sqrt(d / ACCEL), SPEED / ACCEL)
    cruise = (d - ACCEL * ramp * ramp) / (ACCEL * ramp)
    total = 2.0 * ramp + cruise

    def angle(t):
        if t <= 0.0:
            return start
        if t >= total:
            return end
        if t < ramp:
            return start + sign * 0.5 * ACCEL * t * t
        if t < ramp + cruise:
            return start + sign * (0.5 * ACCEL * ramp * ramp + ACCEL * ramp * (t - ramp))
        return end - sign * 0.5 * ACCEL * (total - t) ** 2

    return angle, total


def sweep_path(from_deg, to_deg):
    """The stagnation points (m) every STEP while the servos turn from one command to another."""
    pan, t_pan = servo_move(math.radians(from_deg[0]), math.radians(to_deg[0]))
    tilt, t_tilt = servo_move(math.radians(from_deg[1]), math.radians(to_deg[1]))
    duration = max(t_pan, t_tilt)
    n = max(1, math.ceil(duration / STEP))
    return [airtwin.stagnation_point(math.degrees(pan(k * duration / n)),
                                     max(0.0, math.degrees(tilt(k * duration / n))))
            for k in range(n + 1)]


def segment_distance(p, a, b):
    dx, dy = b[0] - a[0], b[1] - a[1]
    l2 = dx * dx + dy * dy
    u = 0.0 if l2 == 0.0 else max(0.0, min(1.0, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2))
    return math.hypot(a[0] + u * dx - p[0], a[1] + u * dy - p[1])


def quantile(values, q):
    values = sorted(values)
    return values[min(len(values) - 1, int(q * len(values)))] if values else float("nan")


def main():
    if len(sys.argv) != 2 or not os.path.isdir(sys.argv[1]):
        sys.exit("usage: sweep_prediction_errors.py BATCH_DIR (a batch run with --logs)")
    files = sorted(glob.glob(os.path.join(sys.argv[1], "runs", "*", "*.decisions.csv")))
    if not files:
        sys.exit(f"{sys.argv[1]}: no runs/*/*.decisions.csv (was the batch run with --logs?)")
    passing, other = defaultdict(list), []
    for decisions_file in files:
        base = decisions_file[: -len(".decisions.csv")]
        if not os.path.isfile(base + ".plans.csv"):
            sys.exit(f"{base}.plans.csv: missing beside {decisions_file}")
        decisions = list(csv.DictReader(open(decisions_file)))
        plans = defaultdict(dict)
        for row in csv.DictReader(open(base + ".plans.csv")):
            plans[row["t"]][row["id"]] = row
        for i in range(1, len(decisions) - 1):
            now, later = plans.get(decisions[i]["t"]), plans.get(decisions[i + 1]["t"])
            if not now or not later:
                continue
            command = lambda d: (float(d["pan_deg"]), float(d["tilt_deg"]))
            path = sweep_path(command(decisions[i - 1]), command(decisions[i]))
            for object_id, row in now.items():
                if object_id not in later:
                    continue
                p = (float(row["x"]), float(row["y"]))
                closest = min(segment_distance(p, a, b) for a, b in zip(path, path[1:]))
                to_new_s = math.dist(p, path[-1])
                error = math.dist((float(later[object_id]["x"]), float(later[object_id]["y"])),
                                  (float(row["end_x"]), float(row["end_y"])))
                if closest < to_new_s - 0.05:
                    bin_index = next(k for k in range(len(BINS) - 1) if closest < BINS[k + 1])
                    passing[bin_index].append(error)
                else:
                    other.append(error)
    print(f"{len(files)} runs; prediction error |where it was - where it was predicted| (cm)")
    print("closest pass (m)  n      median  p90    share > 10 cm")
    for k in range(len(BINS) - 1):
        e = passing[k]
        label = f"{BINS[k]:.2f}-{BINS[k + 1]:.2f}" if BINS[k + 1] < math.inf else f">= {BINS[k]:.2f}"
        print(f"{label:16s}  {len(e):5d}  {100 * quantile(e, 0.5):6.1f}  {100 * quantile(e, 0.9):5.1f}"
              f"  {sum(x > 0.1 for x in e) / max(1, len(e)):.2f}")
    print(f"{'other decisions':16s}  {len(other):5d}  {100 * quantile(other, 0.5):6.1f}"
          f"  {100 * quantile(other, 0.9):5.1f}  {sum(x > 0.1 for x in other) / max(1, len(other)):.2f}")


if __name__ == "__main__":
    main()
