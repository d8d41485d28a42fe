"""The platform: run the teleoperated pick-and-place scenario, get its recording as arrays, read the
MCAP and CSV files it wrote, and save the trajectory as a MATLAB .mat file.

    PYTHONPATH=build/release/python /usr/bin/python3 examples/platform_recording.py
"""

import os
import pathlib
import tempfile

import numpy as np

from microcobot import platform

out = pathlib.Path(os.environ.get("MC_EXAMPLE_OUT") or tempfile.mkdtemp()) / "platform_recording"
out.mkdir(parents=True, exist_ok=True)
r = platform.run("pick-place", duration_s=2.0, out_dir=out)
rec = r["recording"]
print(f"{r['result']['verdict']}; {len(rec['t_s'])} samples of {len(rec)} channels")

mcap = platform.read_mcap(out / "recording.mcap")["/platform/telemetry"]
csv = platform.read_csv(out / "recording.csv")
assert np.array_equal(csv["t_s"], rec["t_s"]) and np.allclose(mcap["t_s"], rec["t_s"], rtol=5e-10, atol=0)  # JSON text: 10 digits

platform.write_mat(out / "session.mat", {k: v for k, v in rec.items()})
back = platform.read_mat(out / "session.mat")
assert np.array_equal(back["t_s"][:, 0], rec["t_s"])
print(f"wrote {out / 'session.mat'} ({len(back)} variables)")
