#!/usr/bin/env python3
"""The Python module's speed against the C++ on the same work (docs/benchmarks.md, "Python
module"). Figures, not assertions; run on a quiet machine.

  field  Field.velocity on 1e6 points (pan 90 deg, tilt 17 deg, uniform over +-1.25 m: the work
         of BM_FieldVelocities) into one output array, against BM_FieldVelocities run now by the
         build's airtwin_bench; and into a new array each call.
  twin   25 tracers (the grid of BM_TwinStep/tracers_25, as a scenario) under a fixed nozzle,
         stepped one 25 ms camera frame per call from Python (Twin.step: command, advance, states
         as an array) against the same frames of a twin of the same seed advanced in one C++ call
         (Twin.advance_to): the same physics, so the difference is the binding's.
  env    the same 25 tracers in airtwin.env.AirJetEnv, one step (a turn of the closed loop:
         aim at s = (0.9, 0.9) m, 1.8 s of 72 camera frames with the log and the task kept,
         observation and reward as arrays) per call, against the same turn in one C++ call
         (the module's Episode.step_at) and against the twin alone advanced over the same 1.8 s
         in one C++ call (Twin.advance_to).

Usage (from the repository's top folder, the module built):
  PYTHONPATH=build/python python3 bench/python_bench.py [--build build] [--repeats 5]
"""

import argparse
import json
import math
import os
import subprocess
import tempfile
import time

import numpy as np

import airtwin
import airtwin.env


def best_of(repeats, work):
    """The shortest wall time (s) of `repeats` calls of work()."""
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        work()
        best = min(best, time.perf_counter() - start)
    return best


def field(build, repeats):
    points = np.random.default_rng(42).uniform(-1.25, 1.25, size=(1_000_000, 2))
    model = airtwin.Field.default()
    out = np.empty_like(points)
    # Into one output array, as the C++ benchmark writes into one matrix; and into a new array
    # each call (its pages are new to the process: the first writes fault them in).
    python_ns = best_of(repeats, lambda: model.velocity(90.0, 17.0, points, out=out)) * 1e9 / 1e6
    new_ns = best_of(repeats, lambda: model.velocity(90.0, 17.0, points)) * 1e9 / 1e6
    done = subprocess.run([os.path.join(build, "bench", "airtwin_bench"),
                           "--benchmark_filter=^BM_FieldVelocities$",
                           f"--benchmark_repetitions={repeats}", "--benchmark_format=json"],
                          capture_output=True, text=True, check=True)
    runs = [b for b in json.loads(done.stdout)["benchmarks"] if b.get("run_type") == "iteration"]
    cpp_ns = min(b["ns_per_point"] for b in runs)
    print(f"field, 1e6 points: Python {python_ns:.1f} ns/point (a new array each call: "
          f"{new_ns:.1f}), C++ {cpp_ns:.1f} ns/point, ratio {python_ns / cpp_ns:.2f}")


def tracers_25_scenario(folder):
    """scenes/line.yaml with the 25 tracers of BM_TwinStep/tracers_25 instead of its one."""
    rows = []
    for i in range(25):
        x = 0.26 * (i % 5 - 2) + 0.05 * math.sin(1.7 * i + 0.3)
        y = 0.26 * (i // 5 - 2) + 0.05 * math.cos(2.3 * i + 1.1)
        rows.append(f"  - {{id: t{i}, type: tracer, x: {x!r}, y: {y!r}}}")
    with open("scenes/line.yaml") as f:
        text = f.read()
    text = text.replace("  - {id: t1, type: tracer, x: -0.26, y: 0.25}", "\n".join(rows))
    path = os.path.join(folder, "tracers_25.yaml")
    with open(path, "w") as f:
        f.write(text)
    return path


def twin(repeats, frames=400):
    with tempfile.TemporaryDirectory() as folder:
        scenario = tracers_25_scenario(folder)
        pan_deg, tilt_deg = 30.0, 20.0

        def from_python():
            t = airtwin.Twin(scenario, 1, pan_deg, tilt_deg)
            start = time.perf_counter()
            for _ in range(frames):
                t.step(pan_deg, tilt_deg)
            return time.perf_counter() - start

        def in_cpp():
            t = airtwin.Twin(scenario, 1, pan_deg, tilt_deg)
            start = time.perf_counter()
            t.advance_to(frames * 0.025)
            return time.perf_counter() - start

        python_s = min(from_python() for _ in range(repeats)) / frames
        cpp_s = min(in_cpp() for _ in range(repeats)) / frames
    print(f"twin, 25 tracers, a 25 ms frame: Python {python_s * 1e3:.3f} ms, C++ "
          f"{cpp_s * 1e3:.3f} ms, ratio {python_s / cpp_s:.3f}")


def env(repeats, steps=10):
    with tempfile.TemporaryDirectory() as folder:
        scenario = tracers_25_scenario(folder)
        action = np.array([0.9, 0.9])

        def from_python():
            e = airtwin.env.AirJetEnv(scenario, seed=1)
            e.reset()
            start = time.perf_counter()
            for _ in range(steps):
                e.step(action)
            return time.perf_counter() - start

        def turn_in_cpp():
            e = airtwin._core.Episode(scenario, 1)
            start = time.perf_counter()
            for _ in range(steps):
                e.step_at(0.9, 0.9)
            return time.perf_counter() - start

        def twin_in_cpp():
            t = airtwin.Twin(scenario, 1, 30.0, 20.0)
            start = time.perf_counter()
            t.advance_to(steps * 1.8)
            return time.perf_counter() - start

        python_s = min(from_python() for _ in range(repeats)) / steps
        turn_s = min(turn_in_cpp() for _ in range(repeats)) / steps
        twin_s = min(twin_in_cpp() for _ in range(repeats)) / steps
    print(f"env, 25 tracers, a step (1.8 s): Python {python_s * 1e3:.2f} ms, the C++ turn "
          f"{turn_s * 1e3:.2f} ms (ratio {python_s / turn_s:.3f}), the twin alone "
          f"{twin_s * 1e3:.2f} ms (ratio {python_s / twin_s:.3f})")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build", help="the build folder (its airtwin_bench)")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    field(args.build, args.repeats)
    twin(args.repeats)
    env(args.repeats)


if __name__ == "__main__":
    main()
