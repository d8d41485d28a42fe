"""microcobot.positioner's vectorised calls: nanoseconds per pose, and what a call allocates.

Workload: N reachable poses drawn uniformly within +-3 mm and +-0.1 rad a coordinate (seed 1; the
unreachable draws dropped), their leg coordinates, and a guess 1 um / 1 urad from each pose. Each
call runs over all N rows (the GIL released); the best of `rounds` is kept (the machine is shared:
the best is the least disturbed). The bytes a call allocates are traced by tracemalloc (numpy's
arrays included): with out= they are pybind11's argument handling alone, without it the result.

    PYTHONPATH=build/release/python /usr/bin/python3 bench/python_positioner_bench.py [poses] [rounds]
"""

import json
import sys
import time
import tracemalloc

import numpy as np

from microcobot import positioner


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 100000
    rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 5
    pos = positioner.Positioner()
    rng = np.random.default_rng(1)
    drawn = np.concatenate([rng.uniform(-3e-3, 3e-3, (4 * n, 3)), rng.uniform(-0.1, 0.1, (4 * n, 3))], axis=1)
    poses = np.ascontiguousarray(drawn[pos.reachable(drawn)][:n])
    assert len(poses) == n
    legs = pos.ik(poses)
    guess = poses + 1e-6
    out = np.empty_like(poses)
    jac = np.empty((n, 6, 6))
    calls = {
        "ik_out": lambda: pos.ik(poses, out=out),
        "ik": lambda: pos.ik(poses),
        "fk_from_home_out": lambda: pos.fk(legs, out=out),
        "fk_from_guess_out": lambda: pos.fk(legs, guess, out=out),
        "check": lambda: pos.check(poses),
        "jacobian_out": lambda: pos.jacobian(poses, out=jac),
        "conditioning": lambda: pos.conditioning(poses),
    }
    best = {name: float("inf") for name in calls}
    for _ in range(rounds):
        for name, call in calls.items():
            t0 = time.perf_counter()
            call()
            best[name] = min(best[name], time.perf_counter() - t0)
    allocated = {}
    tracemalloc.start()
    for name in ("ik_out", "ik"):
        tracemalloc.reset_peak()
        before = tracemalloc.get_traced_memory()[0]
        calls[name]()
        allocated[name] = tracemalloc.get_traced_memory()[1] - before
    tracemalloc.stop()
    print(json.dumps({"poses": n, "rounds": rounds,
                      "ns_per_pose": {k: v / n * 1e9 for k, v in best.items()},
                      "bytes_allocated_per_call": allocated}, indent=1))


if __name__ == "__main__":
    main()
