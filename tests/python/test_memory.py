"""10 000 twin steps through the module (with resets, predictions and field calls among them)
leave the process's memory where a warm-up left it: the arrays handed to Python are freed with
them, and rebuilding a twin frees the last one. Measured in allocations, not pages: the C heap's
bytes in use (glibc's mallinfo2: numpy's data, MuJoCo, the libraries) and Python's allocated
blocks (its small objects)."""

import ctypes
import gc
import os
import sys

import numpy as np

import airtwin
from conftest import SOURCE_DIR

OCTAGON = os.path.join(SOURCE_DIR, "scenes/octagon.yaml")


class MallInfo2(ctypes.Structure):
    _fields_ = [(name, ctypes.c_size_t) for name in
                ("arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks", "fsmblks", "uordblks",
                 "fordblks", "keepcost")]


LIBC = ctypes.CDLL("libc.so.6")
LIBC.mallinfo2.restype = MallInfo2


def heap_bytes_in_use():
    info = LIBC.mallinfo2()
    return info.uordblks + info.hblkhd  # allocated from the arenas, and mmap-ed blocks


def steps(twin, field, n):
    xi = np.tile(airtwin.object_dynamics("tracer"), (4, 1))
    for k in range(n):
        states = twin.step(30.0 + (k % 50), 20.0)
        if k % 10 == 0:
            field.velocity(30.0, 20.0, states[:, :2])
            airtwin.predict(field, 30.0, 20.0, states[:, :2], xi, sample_rate_hz=40.0).samples
        if k % 1000 == 999:
            twin.reset()


def test_ten_thousand_steps_without_memory_growth():
    twin = airtwin.Twin(OCTAGON, 1, 30.0, 20.0)
    field = airtwin.Field.default()
    steps(twin, field, 2000)  # warm-up: allocator pools, MuJoCo's buffers, twin rebuilt twice
    heap, blocks = heap_bytes_in_use(), sys.getallocatedblocks()
    steps(twin, field, 10_000)
    heap_grown, blocks_grown = heap_bytes_in_use() - heap, sys.getallocatedblocks() - blocks
    # Measured: +3 KB and a few blocks. A leak of 16 bytes or one object a step would be 160 KB
    # or 10 000 blocks; of one twin per reset, megabytes.
    assert heap_grown < 64_000, f"the C heap grew by {heap_grown} bytes"
    assert blocks_grown < 1000, f"Python holds {blocks_grown} more blocks"


def rss_bytes():
    """The process's resident set (/proc/self/statm's second field, in pages)."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def env_steps(env, rng, n, reset_every):
    """n env steps of a random policy, a new episode every reset_every steps (or at its end);
    ends on a reset, so that every measurement finds a fresh episode's log."""
    env.reset(seed=1)
    for k in range(1, n + 1):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample(rng))
        if terminated or truncated or k % reset_every == 0:
            env.reset(seed=1 + k % 3)
    env.reset(seed=1)


# 10 000 steps of the line task take ~1 min: the acceptance tier's (docs/testing.md);
# CI's unit tier takes 600 (a few seconds).
ENV_STEPS = 10_000 if os.environ.get("AIRTWIN_TEST_TIER") == "acceptance" else 600


def test_env_steps_without_memory_growth():
    from airtwin.env import AirJetEnv
    env = AirJetEnv("line", seed=1)
    rng = np.random.default_rng(1)
    env_steps(env, rng, 300, 50)  # warm-up: every episode length and the allocator's pools
    # Counted without the cycles the collector has not visited yet (their number drifts by
    # hundreds of blocks either way from one moment to the next).
    gc.collect()
    heap, blocks, rss = heap_bytes_in_use(), sys.getallocatedblocks(), rss_bytes()
    env_steps(env, rng, ENV_STEPS, 50)
    gc.collect()
    heap_grown = heap_bytes_in_use() - heap
    blocks_grown = sys.getallocatedblocks() - blocks
    rss_grown = rss_bytes() - rss
    print(f"{ENV_STEPS} env steps: heap {heap_grown:+d} B, blocks {blocks_grown:+d}, "
          f"RSS {rss_grown:+d} B")
    # An episode's log (72 frames a step) and the twin are freed at each reset: what a step
    # leaves behind would grow with the steps. 16 bytes a step would be 160 KB over 10 000.
    assert heap_grown < 64_000, f"the C heap grew by {heap_grown} bytes"
    assert blocks_grown < 1000, f"Python holds {blocks_grown} more blocks"
    assert rss_grown < 4 << 20, f"the resident set grew by {rss_grown} bytes"
