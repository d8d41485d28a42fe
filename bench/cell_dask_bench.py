"""microcobot.cell.batch on Dask: a LocalCluster of 2 worker processes against one (goal
>= 1.7x), the same campaign, in the same run.

Workload: SEEDS x PARTS automatic cycles (one Dask task per part, ~2-3 s of wall time each). Each
cluster (processes=True, threads_per_worker=1, loopback only, no dashboard) is started before its
timing and warmed up (every worker imports microcobot); a round times one batch() call on each,
rounds alternate 1 worker / 2 workers and the best round of each is kept (the machine is shared:
the best is the least disturbed). The results of every round are checked equal to the first's
(wall_s aside), so the speed-up is not bought with different work. The load average before and
after is printed: the 2-core machine must be near idle for 2 workers to have 2 cores.

    PYTHONPATH=build/release/python /usr/bin/python3 bench/cell_dask_bench.py [rounds] [seeds] [parts]
"""

import json
import os
import sys
import time

from distributed import Client, LocalCluster

from microcobot import cell


def warm(client):
    client.run(lambda: __import__("microcobot.cell"))  # each worker imports the module once


def same(a, b):
    strip = lambda r: [[{k: v for k, v in c.items() if k != "wall_s"} for c in run["cycles"]] for run in r["runs"]]
    return strip(a) == strip(b)


def main():
    rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 2
    n_seeds = int(sys.argv[2]) if len(sys.argv) > 2 else 4
    parts = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    config = {"parts": parts, "mode": "auto"}
    seeds = list(range(100, 100 + n_seeds))  # not the seeds the task was developed on (1, 2)
    load0 = os.getloadavg()
    clusters = {}
    for n in (1, 2):
        # Every socket on 127.0.0.1, ports picked by the system (tests/python/test_cell.py says why
        # the HTTP servers need their own addresses).
        cluster = LocalCluster(n_workers=n, processes=True, threads_per_worker=1, host="127.0.0.1",
                               dashboard_address=None, scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                               worker_dashboard_address="127.0.0.1:0")
        clusters[n] = (cluster, Client(cluster))
        warm(clusters[n][1])
    best = {1: float("inf"), 2: float("inf")}
    reference = None
    try:
        for r in range(rounds):
            for n in (1, 2):
                t0 = time.perf_counter()
                result = cell.batch(config, seeds, client=clusters[n][1])
                wall = time.perf_counter() - t0
                reference = reference or result
                if not same(result, reference):
                    raise SystemExit(f"round {r}, {n} worker(s): results differ from the first round's")
                best[n] = min(best[n], wall)
                print(f"round {r + 1}: {n} worker(s) {wall:.2f} s", file=sys.stderr)
    finally:
        for cluster, client in clusters.values():
            client.close()
            cluster.close()
    s = reference["summary"]
    print(json.dumps({
        "cycles": len(seeds) * parts,
        "seeds": seeds,
        "parts": parts,
        "successes": s["successes"],
        "simulated_s": s["simulated_s"],
        "one_worker_s": best[1],
        "two_workers_s": best[2],
        "speedup": best[1] / best[2],
        "load_before": load0,
        "load_after": os.getloadavg(),
        "cpus": os.cpu_count(),
    }, indent=1))


if __name__ == "__main__":
    main()
