"""The SmarAct MCS2 twin against an independent client: pyvisa-py's TCPIP SOCKET resource (CR LF
terminations, as an MCS2 is opened over TCP port 55551) replays the golden transcripts of
tests/data/mcs2 (the EPICS motorSmarAct MCS2 driver's sequences; kamzik3's, each command followed
by `:SYST:ERR:NEXT?`; sources and syntax in each file's header) against `microcobot serve
--emulate mcs2`, each on a controller just started; then a pick of channel 0's moves through the
same resource: reference, absolute move, step mode."""

import os
import re
import time

import pytest
import pyvisa

from twin_clients import Serve

DATA = os.path.join(os.path.dirname(__file__), "..", "data", "mcs2")
TRANSCRIPTS = ["epics_motorsmaract.txt", "kamzik3.txt"]


@pytest.fixture()
def serve():
    s = Serve(protocols=("mcs2",))
    yield s
    s.stop()


def open_mcs2(port):
    rm = pyvisa.ResourceManager("@py")
    inst = rm.open_resource(f"TCPIP::127.0.0.1::{port}::SOCKET",
                            read_termination="\r\n", write_termination="\r\n", timeout=5000)
    return rm, inst


def matches(pattern, got):
    """A regular expression matched whole, or `&MASK=VALUE` (hex) on an integer reply."""
    if pattern.startswith("&"):
        mask, value = (int(x, 16) for x in pattern[1:].split("="))
        return re.fullmatch(r"-?\d+", got) is not None and int(got) & mask == value
    return re.fullmatch(pattern, got) is not None


def replay(path, write, read, timeout_s=10.0):
    append = None
    with open(path, encoding="utf-8") as f:
        for n, raw in enumerate(f, 1):
            line = raw.rstrip("\n")
            where = f"{os.path.basename(path)}:{n}: {line}"
            if line.startswith("#! append "):
                append = line[len("#! append "):]
            if not line or line.startswith("#"):
                continue
            kind, text = line[0], line[2:]
            if kind == ">":
                write(text)
                if append:
                    write(append)
            elif kind == "<":
                got = read()
                assert matches(text, got), (where, got)
            elif kind == "~":
                query, pattern = text.split(" => ")
                end = time.monotonic() + timeout_s
                while True:
                    write(query)
                    if append:
                        write(append)
                    got = read()
                    if matches(pattern, got):
                        break
                    assert time.monotonic() < end, (where, got)
                    if append:
                        assert read() == '0,"No error"', where
                    time.sleep(0.02)
            else:
                raise ValueError(where)


@pytest.mark.parametrize("name", TRANSCRIPTS)
def test_pyvisa_replays_the_transcript(serve, name):
    rm, inst = open_mcs2(serve.ports["mcs2"])
    try:
        replay(os.path.join(DATA, name), inst.write, inst.read)
        assert inst.query(":SYST:ERR:COUN?") == "0"
    finally:
        inst.close()
        rm.close()


def test_pyvisa_references_moves_and_steps_channel_0(serve):
    rm, inst = open_mcs2(serve.ports["mcs2"])

    def wait_idle(timeout_s=10.0):
        end = time.monotonic() + timeout_s
        while int(inst.query(":CHAN0:STAT?")) & 0x1:
            assert time.monotonic() < end
            time.sleep(0.02)

    try:
        assert inst.query(":DEV:NOCH?") in ("3", "4")
        assert int(inst.query(":CHAN0:STAT?")) & 0x80 == 0  # not referenced at power-up
        inst.write(":CHAN0:HOLD -1;:CHAN0:VEL 1000000000;:REF0")
        wait_idle()
        assert int(inst.query(":CHAN0:STAT?")) & 0x800a0 == 0x800a0  # referenced, in position
        inst.write(":CHAN0:MMOD 0;:MOVE0 -400000000")
        wait_idle()
        assert abs(int(inst.query(":CHAN0:POS?")) + 400_000_000) < 1_000_000  # pm, within 1 um
        before = int(inst.query(":CHAN0:POS?"))
        inst.write(":CHAN0:MMOD 4;:CHAN0:STEP:FREQ 1000;:CHAN0:STEP:AMPL 39321;:MOVE0 300")
        wait_idle()
        after = int(inst.query(":CHAN0:POS?"))
        assert after - before > 1_000_000  # 300 periods at 60 V: micrometres up, open loop
        assert inst.query(":SYST:ERR:NEXT?") == '0,"No error"'
    finally:
        inst.close()
        rm.close()
