"""Issue #30: Debian's pymeasure ANC300 driver (ANC300Controller over its telnet adapter) drives the
ANC300 twin of `microcobot serve --emulate anc300`: it logs in with the factory password, sets
frequency and voltage, steps N up and N down (Axis.move: setm stp, stepu/stepd, stepw, setm gnd);
the stage moves what the stick-slip model says for the same drive (`microcobot stickslip simulate`)."""

import json
import os
import socket
import subprocess
import time

import pytest
from pymeasure.instruments.attocube import anc300 as anc300_module

from twin_clients import Serve

N, FREQUENCY_HZ, VOLTAGE_V = 100, 500, 60
TRANSIENT = 10  # periods
# The model's figure is `stickslip simulate`'s displacement for the same drive. Its first periods
# differ from the twin's by construction: simulate starts from rest with the power-up transient
# (the hysteresis' initial loading, the contact's first strain), the axis from its hold voltage
# through the entry edge. OpenLoop.Periods{Up,Down}* (tests/platform/open_loop_test.cc) measure
# both parts at this drive: the first 10 periods 0.60 um up (model 1.28) and -1.10 um down (model
# -0.53); the steady periods 10-100 within 15% of the model (-11.5% up, +5.1% down). Hence the
# tolerance: |simulate over 10 periods| + 15% of simulate's periods 10 to N.
STEADY_TOL = 0.15

@pytest.fixture(scope="module")
def serve():
    s = Serve()
    yield s
    s.stop()


def position_m(port, axis):
    """The twin's getpos (its sensor) over a second, raw console connection."""
    with socket.create_connection(("127.0.0.1", port), timeout=5) as s:
        f = s.makefile("rwb", buffering=0)

        def until(marker):
            text = b""
            while marker not in text:
                chunk = s.recv(4096)
                assert chunk, text
                text += chunk
            return text.decode()

        until(b"code: ")
        s.sendall(b"123456\r\n")
        until(b"> ")
        s.sendall(b"echo off\r\n")
        until(b"OK\r\n")
        s.sendall(f"getpos {axis}\r\n".encode())
        reply = until(b"OK\r\n")
        f.close()
    line = reply.split("\r\n")[0]
    assert line.startswith("position = ") and line.endswith(" m"), reply
    return float(line.split()[2])


def simulated_displacement_m(direction, periods):
    """`stickslip simulate`'s displacement for `periods` periods of the drive, from rest."""
    out = subprocess.run([os.environ["MC_CLI"], "stickslip", "simulate", "--wave", "sawtooth",
                          "--amplitude", str(VOLTAGE_V), "--frequency", str(FREQUENCY_HZ),
                          "--direction", direction, "--duration", str(periods / FREQUENCY_HZ), "--json"],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout)["displacement_m"]


def expect_like_the_model(moved, direction):
    whole = simulated_displacement_m(direction, N)
    transient = simulated_displacement_m(direction, TRANSIENT)
    tolerance = abs(transient) + STEADY_TOL * abs(whole - transient)
    print(f"{direction}: moved {moved:.4e} m, simulate {whole:.4e} m, tolerance {tolerance:.2e} m")
    assert moved * whole > 0
    assert abs(moved - whole) <= tolerance


def test_pymeasure_steps_the_twin_as_the_model_moves(serve):
    port = serve.ports["anc300"]
    adapter = anc300_module.AttocubeConsoleAdapter
    # ANC300Controller always dials 7230; the twin listens on a free port (port 0).
    anc300_module.AttocubeConsoleAdapter = lambda host, _port, passwd, **kw: adapter(host, port, passwd, **kw)
    try:
        ctrl = anc300_module.ANC300Controller("127.0.0.1", ["x", "y", "z"], "123456")
    finally:
        anc300_module.AttocubeConsoleAdapter = adapter
    for axis in (ctrl.x, ctrl.y):
        axis.frequency = FREQUENCY_HZ  # setf N 500.000
        axis.voltage = VOLTAGE_V  # setv N 60.000
        assert axis.frequency == FREQUENCY_HZ
        assert float(axis.voltage) == VOLTAGE_V
        assert axis.mode == "gnd"

    x0, y0 = position_m(port, 1), position_m(port, 2)
    ctrl.x.move(N)  # setm stp, stepu N, stepw (returns when done), setm gnd
    assert ctrl.x.mode == "gnd"
    ctrl.y.move(-N)  # ... stepd N ...
    time.sleep(0.2)  # the position loop holds the axes again
    x1, y1 = position_m(port, 1), position_m(port, 2)
    expect_like_the_model(x1 - x0, "forward")
    expect_like_the_model(y1 - y0, "backward")
    # Back down on the axis that just stepped up: it moves back (the figure is in the report).
    ctrl.x.move(-N)
    time.sleep(0.2)
    x2 = position_m(port, 1)
    print(f"x down after up: {x2 - x1:.4e} m")
    assert x2 - x1 < 0


def test_a_wrong_password_is_refused(serve):
    with pytest.raises(Exception, match="authorization failed 'Authorization failed'"):
        anc300_module.AttocubeConsoleAdapter("127.0.0.1", serve.ports["anc300"], "000000")
