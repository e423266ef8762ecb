#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The Python module's cost against its anchor, the same C++ call, measured in the same run:

  ratio python batch distance cost: the batch of 6 checkpoints x 50 robot boxes x 100 environment boxes from
      Python (NumPy arrays in and out, the boxes checked and converted, the four result arrays of the call
      before filled again, as a planner's loop does) against the C++ batch alone (collision::constraints on
      the converted boxes, timed in C++): 1.00x would be free; the same with new result arrays each call;
  python single distance: what one cellmap.distance call costs from Python, against one pair of the C++ batch.

Each figure is the best of several rounds (the machine is shared). Run with the module importable:
  PYTHONPATH=build/python python3 bench/python_bench.py [--rounds N]
"""
import argparse
import time

import numpy as np

import cellmap

CHECKPOINTS, ROBOT_BOXES, ENVIRONMENT_BOXES = 6, 50, 100


def random_boxes(rng, shape):
    angles = rng.uniform(0, 2 * np.pi, shape)
    boxes = np.zeros(shape + (10,))
    boxes[..., 0:3] = rng.uniform(0, 3, shape + (3,))
    boxes[..., 3:6] = rng.uniform(0.02, 0.3, shape + (3,))
    boxes[..., 6] = np.cos(angles / 2)
    boxes[..., 9] = np.sin(angles / 2)
    return boxes


def best_seconds(call, rounds, repeats):
    best = float('inf')
    for _ in range(rounds):
        start = time.perf_counter()
        for _ in range(repeats):
            call()
        best = min(best, (time.perf_counter() - start) / repeats)
    return best


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--rounds', type=int, default=15, help='rounds per figure; the best counts (default 15)')
    args = parser.parse_args()
    rng = np.random.default_rng(1)
    robot = random_boxes(rng, (CHECKPOINTS, ROBOT_BOXES))
    environment = random_boxes(rng, (ENVIRONMENT_BOXES,))
    pairs = CHECKPOINTS * ROBOT_BOXES * ENVIRONMENT_BOXES

    out = cellmap.batch_distance(robot, environment)
    python = fresh = cpp = float('inf')
    for _ in range(args.rounds):  # side by side, so that the machine's load changes both alike
        python = min(python, best_seconds(lambda: cellmap.batch_distance(robot, environment, out=out), 1, 5))
        cpp = min(cpp, cellmap._batch_distance_seconds(robot, environment, 5))
        fresh = min(fresh, best_seconds(lambda: cellmap.batch_distance(robot, environment), 1, 5))
    print(f'ratio python batch distance cost: {python / cpp:.2f}x (python {python * 1e6:.0f} us vs C++ '
          f'{cpp * 1e6:.0f} us per batch of {CHECKPOINTS} x {ROBOT_BOXES} x {ENVIRONMENT_BOXES} boxes, '
          f'{python / pairs * 1e9:.0f} vs {cpp / pairs * 1e9:.0f} ns a pair, result arrays reused)')
    print(f'python batch distance, new result arrays each call: {fresh * 1e6:.0f} us ({fresh / cpp:.2f}x; '
          f'{sum(a.nbytes for a in out.values()) / 1e6:.1f} MB of results, whose first touch can cost more '
          f'than the batch when the allocator hands out fresh pages)')

    a, b = robot[0, 0], environment[0]
    single = best_seconds(lambda: cellmap.distance(a, b), args.rounds, 2000)
    print(f'python single distance: {single * 1e6:.2f} us per call (one pair of the C++ batch: '
          f'{cpp / pairs * 1e6:.3f} us)')


if __name__ == '__main__':
    main()
