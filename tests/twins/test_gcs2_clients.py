"""The GCS 2.0 twin against independent clients: pyvisa-py (TCPIP SOCKET resource) and a
raw-socket script replay the golden transcripts of tests/data/gcs2 (written from PI's public
manuals; sources in each file) against `microcobot serve --emulate gcs2`."""

import glob
import os

import pytest

from twin_clients import RawGcs, Serve, replay, replay_over_pyvisa

DATA = os.path.join(os.path.dirname(__file__), "..", "data", "gcs2")
TRANSCRIPTS = sorted(glob.glob(os.path.join(DATA, "*.txt")))


@pytest.fixture(scope="module")
def serve():
    s = Serve()
    yield s
    s.stop()


@pytest.mark.parametrize("path", TRANSCRIPTS, ids=os.path.basename)
def test_raw_socket_replays_the_transcript(serve, path):
    c = RawGcs(serve.ports["gcs2"])
    try:
        replay(path, c.write, c.read_line)
    finally:
        c.close()


@pytest.mark.parametrize("path", TRANSCRIPTS, ids=os.path.basename)
def test_pyvisa_replays_the_transcript(serve, path):
    replay_over_pyvisa(serve.ports['gcs2'], path)
