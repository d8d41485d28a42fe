"""microcobot.platform: a scenario run as a dict of arrays; the recordings it writes (CSV, MCAP)
read back equal to it."""

import numpy as np
import pytest

from microcobot import platform


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    out = tmp_path_factory.mktemp("session")
    return platform.run("pick-place", duration_s=1.0, out_dir=out), out


def test_run_returns_the_recording(session):
    r, _ = session
    rec = r["recording"]
    t = rec["t_s"]
    n = len(t)
    assert n > 100 and all(v.shape == (n,) for v in rec.values())
    assert np.all(np.diff(t) > 0) and t[-1] <= 1.0 + 1e-9
    assert all(np.all(np.isfinite(v)) for v in rec.values())
    assert r["result"]["duration_s"] == pytest.approx(1.0, abs=0.01)
    # The columns are the telemetry's channels, in order, each with its unit.
    assert [c["name"] for c in r["channels"]] == list(rec)
    units = {c["name"]: c["unit"] for c in r["channels"]}
    assert units["t_s"] == "s" and units["measured_x_m"] == "m" and units["deadman"] == ""
    assert all(c["description"] for c in r["channels"])
    # One second of the scripted operator: the slave has not finished the pick-and-place yet.
    assert isinstance(r["result"]["verdict"], str) and r["result"]["verdict"]


def test_csv_and_mcap_recordings_equal_the_returned_arrays(session):
    r, out = session
    rec = r["recording"]
    csv = platform.read_csv(out / "recording.csv")
    assert list(csv) == list(rec)
    for k in rec:
        np.testing.assert_array_equal(csv[k], rec[k])
    mc = platform.read_mcap(out / "recording.mcap")
    tel = mc["/platform/telemetry"]
    assert tel["messages"] == len(rec["t_s"])
    # MCAP messages carry each value as JSON text with 10 significant digits (telemetry_json.cc):
    # a relative rounding of at most 5e-10.
    for k in rec:
        np.testing.assert_allclose(tel[k], rec[k], rtol=5e-10, atol=0)
    np.testing.assert_allclose(tel["log_time_s"], rec["t_s"], atol=1e-9)
    assert tel["units"] == {c["name"]: c["unit"] for c in r["channels"]}


def test_platform_errors(tmp_path):
    with pytest.raises(ValueError, match="scenario"):
        platform.run("juggling", duration_s=1.0)
    with pytest.raises(ValueError, match="duration"):
        platform.run(duration_s=-1.0)
    with pytest.raises(ValueError, match="no-such.csv"):
        platform.read_csv(tmp_path / "no-such.csv")
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(b"not an mcap")
    with pytest.raises(ValueError, match="bad.mcap"):
        platform.read_mcap(bad)
