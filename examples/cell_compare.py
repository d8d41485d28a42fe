"""The assembly cell from Python: the same parts by the robot and by the simulated person, with
and without shared control, their cycles as a pandas DataFrame (as `microcobot cell compare`).

    PYTHONPATH=build/release/python /usr/bin/python3 examples/cell_compare.py [PARTS (default 1)] [SEED]

Tutorial: docs/tutorials/cell-batch.md.
"""

import sys

import pandas as pd

from microcobot import cell

parts = int(sys.argv[1]) if len(sys.argv) > 1 else 1
seed = int(sys.argv[2]) if len(sys.argv) > 2 else 7
batch = cell.Batch(scene=None, parts=parts, seed=seed)  # the default scene; the seed draws the parts
rows = []
for mode in ("auto", "assisted", "manual"):
    for c in batch.run(mode=mode):  # one CycleResult dict per part (GIL released while it simulates)
        rows.append({"mode": mode, **c})
df = pd.DataFrame(rows)
df["placement_um"] = df["placement_error_m"] * 1e6
print(df.groupby("mode")[["success", "cycle_s", "placement_um"]].median().round(2).to_string())
