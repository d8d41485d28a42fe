"""Talk to a PI GCS 2.0 controller and an Attocube ANC300 as a lab script does: here to the digital
twins of `microcobot serve --emulate gcs2 --emulate anc300`, then unchanged to the real controllers.

    microcobot serve --emulate gcs2 --emulate anc300 --out twin &
    /usr/bin/python3 examples/clients/vendor_twin_clients.py [GCS_HOST:PORT]

GCS 2.0 over a plain TCP socket (what PI's manuals describe: one ASCII command per line, replies
ending with a line without a trailing space); the ANC300 through pymeasure's own driver (Debian's
python3-pymeasure), which logs in to its telnet console on port 7230 with the factory password.
Tutorial: docs/tutorials/vendor-controller.md.
"""

import socket
import sys
import time

from pymeasure.instruments.attocube import ANC300Controller

host, port = (sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50000").rsplit(":", 1)


def gcs(sock, command):
    """One GCS 2.0 command; the reply's lines for a query (a multi-line reply's lines end with ' ')."""
    sock.sendall((command + "\n").encode())
    if "?" not in command:
        return []
    reply = b""
    while not reply.endswith(b"\n") or reply.split(b"\n")[-2].endswith(b" "):
        reply += sock.recv(4096)
    return reply.decode().splitlines()


with socket.create_connection((host, int(port)), timeout=5) as s:
    print("*IDN?", gcs(s, "*IDN?"))
    print("SAI?", gcs(s, "SAI?"))
    print("POS? 1", gcs(s, "POS? 1"), "PUN? 1", gcs(s, "PUN? 1"))
    gcs(s, "SVO 1 1")              # servo on
    gcs(s, "FRF 1")                # reference move (to the reference switch)
    while gcs(s, "FRF? 1") != ["1=1"] or gcs(s, "ONT? 1") != ["1=1"]:
        time.sleep(0.05)
    print("after FRF 1: POS? 1", gcs(s, "POS? 1"))
    gcs(s, "VEL 1 1")              # mm/s
    gcs(s, "MVR 1 0.05")           # 50 um further along axis 1
    while gcs(s, "ONT? 1") != ["1=1"]:
        time.sleep(0.05)
    print("after MVR 1 0.05: POS? 1", gcs(s, "POS? 1"), "ERR?", gcs(s, "ERR?"))

anc = ANC300Controller("127.0.0.1", ["x", "y", "z"], "123456")
print("ANC300:", anc.version[0])
anc.x.frequency = 500              # setf 1 500 [Hz]
anc.x.voltage = 60                 # setv 1 60 [V]
anc.x.move(100)                    # 100 steps up: setm stp, stepu, stepw, setm gnd
print(f"ANC300 axis x: {anc.x.frequency} Hz, {anc.x.voltage} V, mode {anc.x.mode} after 100 steps")

