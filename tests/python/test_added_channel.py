"""A telemetry channel added to the live platform in one place (LiveParams::telemetry_channels)
reaches the Python side with its name and unit: the recording that the C++ test
AddedChannel.ReachesTheLiveSchemaTheMessagesTheMcapAndTheCsvWithItsUnit wrote, read through the
module's read_csv and read_mcap."""

import os
import subprocess

import numpy as np
import pytest

from microcobot import platform


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    live_tests = os.environ.get("MC_LIVE_TESTS")
    if not live_tests:
        pytest.skip("MC_LIVE_TESTS (the live module's test executable) is not set")
    out = tmp_path_factory.mktemp("added_channel")
    env = dict(os.environ, MC_ADDED_CHANNEL_OUT=str(out))
    run = subprocess.run(
        [live_tests, "--gtest_filter=AddedChannel.ReachesTheLiveSchema*"],
        env=env, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-4000:]
    return out


def test_the_csv_has_the_added_column_after_the_built_in_ones(recording):
    csv = platform.read_csv(recording / "recording.csv")
    names = list(csv)
    builtin = [c["name"] for c in platform.telemetry_channels(simulation=True)]
    assert names[: len(builtin)] == builtin
    assert names[len(builtin):] == ["probe_x_m"]
    home_x = csv["measured_x_m"] - csv["probe_x_m"]
    np.testing.assert_allclose(home_x, home_x[0], atol=1e-12)


def test_the_mcap_has_the_added_field_with_its_unit(recording):
    tel = platform.read_mcap(recording / "recording.mcap")["/platform/telemetry"]
    assert "probe_x_m" in tel
    assert tel["units"]["probe_x_m"] == "m"
    assert tel["units"]["deadman"] == ""  # a flag
    units = {c["name"]: c["unit"] for c in platform.telemetry_channels()}
    assert all(tel["units"][k] == u for k, u in units.items())
    csv = platform.read_csv(recording / "recording.csv")
    np.testing.assert_allclose(tel["probe_x_m"], csv["probe_x_m"], rtol=5e-10, atol=1e-18)
