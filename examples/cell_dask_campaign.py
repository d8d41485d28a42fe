"""A campaign of the assembly cell on Dask: every part of several seeds as one task, on a local
Dask cluster (or, unchanged, on any cluster by its scheduler's address), then the campaign's
summary and its cycles in pandas.

    PYTHONPATH=build/release/python /usr/bin/python3 examples/cell_dask_campaign.py [SEEDS] [PARTS] [SCHEDULER]

SCHEDULER: a `dask.distributed` scheduler's address (tcp://host:8786) whose workers can import
microcobot; without it, a LocalCluster of two worker processes on this machine, loopback only.
Tutorial: docs/tutorials/dask-campaign.md. Needs python3-dask and python3-distributed (Debian).
"""

import sys
import time

import pandas as pd
from dask.distributed import Client, LocalCluster

from microcobot import cell

seeds = list(range(100, 100 + (int(sys.argv[1]) if len(sys.argv) > 1 else 2)))
parts = int(sys.argv[2]) if len(sys.argv) > 2 else 2
config = {"parts": parts, "mode": "auto"}  # every key: docs/cell.md, "Campaigns with Dask"

if __name__ == "__main__":  # the worker processes import this file: start the cluster only here
    if len(sys.argv) > 3:
        client = Client(sys.argv[3])
    else:
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                               scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                               worker_dashboard_address="127.0.0.1:0")
        client = Client(cluster)
    print(f"{len(client.scheduler_info()['workers'])} workers")
    t0 = time.monotonic()
    r = cell.batch(config, seeds, client=client)
    print(f"{len(seeds)} seeds x {parts} parts in {time.monotonic() - t0:.1f} s wall")
    s = r["summary"]
    print({k: s[k] for k in ("cycles", "successes") if k in s})
    df = pd.DataFrame([{"seed": run["seed"], **c} for run in r["runs"] for c in run["cycles"]])
    print(df[["seed", "index", "success", "cycle_s", "placement_error_m"]].to_string(index=False))
    client.close()
