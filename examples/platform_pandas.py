"""Drive the platform from Python and read its recording in pandas: the scripted pick-and-place
with a changed configuration, its telemetry as a DataFrame, the phases of the task, and the same
recording read back from the MCAP file the run wrote.

    PYTHONPATH=build/release/python /usr/bin/python3 examples/platform_pandas.py [OUT_DIR]

Tutorial: docs/tutorials/python-pandas.md. Needs python3-pandas (Debian).
"""

import sys
import tempfile
from pathlib import Path

import pandas as pd

from microcobot import platform

out = Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp()) / "session"
# The configuration as a dict: the defaults, then what this run changes (every key:
# docs/reference/configuration.md). Here the stage runs without its tracking controller (the
# hybrid stepping-scanning control of the thesis instead).
config = platform.config()
config["stage"]["tracking_enabled"] = False
r = platform.run("pick-place", duration_s=60.0, config=config, out_dir=out)
print(r["result"]["verdict"], f"(placement error {r['result']['placement_error_m'] * 1e6:.2f} um)")

df = pd.DataFrame(r["recording"]).set_index("t_s")
print(f"{len(df)} samples x {len(df.columns)} channels, {df.index[-1]:.1f} s")

# The stage's speed and the grip force, per second of the task.
speed = (df[["measured_x_m", "measured_y_m"]].diff().pow(2).sum(axis=1) ** 0.5) / df.index.to_series().diff()
per_s = pd.DataFrame({"speed_um_s": speed * 1e6, "grip_uN": df["grip_force_N"] * 1e6})
per_s = per_s.groupby(per_s.index.astype(int)).mean()
print(per_s.round(1).iloc[::5].to_string())

# The part's state (part_phase, a whole number per state): when it changed.
phase_starts = df["part_phase"].ne(df["part_phase"].shift()).loc[lambda s: s].index
print("part phase changes at t =", ", ".join(f"{t:.2f} s" for t in phase_starts))

# The same telemetry from the recording's MCAP file, as Foxglove would read it.
mcap = platform.read_mcap(out / "recording.mcap")["/platform/telemetry"]
back = pd.DataFrame({k: v for k, v in mcap.items() if k in df.columns or k == "t_s"}).set_index("t_s")
print(f"recording.mcap: {len(back)} samples; largest difference from the run's arrays "
      f"{(back['measured_x_m'] - df['measured_x_m']).abs().max():.1e} m")
