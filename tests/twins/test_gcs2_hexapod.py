"""The hexapod twin (PI C-887 dialect of GCS 2.0) in another process: `microcobot serve --emulate
gcs2-hexapod=127.0.0.1:0` driven over a plain socket and through pyvisa-py. The golden transcripts
of tests/data/gcs2_hexapod (PIPython's connect, start-up and first move; sources in each header)
are replayed by both with their replies checked; a pose sequence ends on target within tolerance;
an unreachable pose is refused with the controller's error and nothing moves."""

import glob
import os
import time

import pytest

from twin_clients import RawGcs, Serve, replay, replay_over_pyvisa

DATA = os.path.join(os.path.dirname(__file__), "..", "data", "gcs2_hexapod")
TRANSCRIPTS = sorted(glob.glob(os.path.join(DATA, "*.txt")))
AXES = "XYZUVW"


@pytest.fixture(scope="module")
def serve():
    s = Serve(protocols=("gcs2-hexapod",))
    yield s
    s.stop()


@pytest.fixture
def client(serve):
    c = RawGcs(serve.ports["gcs2-hexapod"])
    yield c
    c.close()


def ask(c, line, lines=1):
    c.write(line)
    return [c.read_line().rstrip(" ") for _ in range(lines)]


def pose(c, query="POS?"):
    return [float(r.split("=")[1]) for r in ask(c, query, 6)]


def wait_on_target(c, timeout_s=30.0):
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        if ask(c, "ONT? X Y Z U V W", 6) == [f"{a}=1" for a in AXES]:
            return
        time.sleep(0.02)
    raise AssertionError("not on target")


def reference(c):
    c.write("FRF")
    assert ask(c, "ERR?") == ["0"]
    wait_on_target(c)
    assert ask(c, "FRF?", 6) == [f"{a}=1" for a in AXES]


@pytest.mark.parametrize("path", TRANSCRIPTS, ids=os.path.basename)
def test_raw_socket_replays_the_transcript(client, path):
    replay(path, client.write, client.read_line, timeout_s=30.0)


@pytest.mark.parametrize("path", TRANSCRIPTS, ids=os.path.basename)
def test_pyvisa_replays_the_transcript(serve, path):
    replay_over_pyvisa(serve.ports['gcs2-hexapod'], path, timeout_s=30.0)


def test_a_pose_sequence_ends_on_target_within_a_micron_and_a_millidegree(client):
    reference(client)
    client.write("VLS 0.5")
    goals = [(0.05, -0.03, 0.02, 0.2, -0.1, 0.3), (-0.04, 0.02, -0.01, -0.1, 0.2, -0.2), (0, 0, 0, 0, 0, 0)]
    for goal in goals:
        client.write("MOV " + " ".join(f"{a} {v}" for a, v in zip(AXES, goal)))
        assert ask(client, "ERR?") == ["0"]
        wait_on_target(client)
        for a, got, want in zip(AXES, pose(client), goal):
            assert abs(got - want) <= 1e-3, (a, got, want)
        for a, got, want in zip(AXES, pose(client, "MOV?"), goal):
            assert abs(got - want) <= 1e-9, (a, got, want)


def test_an_unreachable_pose_is_refused_with_error_7_and_nothing_moves(client):
    reference(client)
    assert ask(client, "VMO? Z 40") == ["0"]
    before = pose(client)
    target = pose(client, "MOV?")
    client.write("MOV Z 40")
    assert ask(client, "ERR?") == ["7"]
    assert ask(client, "#5") == ["0"]
    time.sleep(0.3)
    assert ask(client, "#5") == ["0"]
    for a, got, want in zip(AXES, pose(client), before):
        assert abs(got - want) <= 1e-4, (a, got, want)
    assert pose(client, "MOV?") == target
    assert ask(client, "ERR?") == ["0"]
