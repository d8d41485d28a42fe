#!/usr/bin/env python3
"""What one stepping run moves on the ANC300 twin (docs/hardware.md "anc300").

Against `microcobot serve --emulate anc300=127.0.0.1:PORT` (loopback): axis 1 at 60 V, 1 kHz,
runs of n = 1, 1, 1, 2, 5, 10, 20, 20, 20 periods up then down (`stepu/stepd 1 n`, `stepw 1`),
each measured by the twin's sensor (`getpos 1`) 20 ms after its end, and 0.1 s later (the hold's
creep). Usage: python3 bench/anc300_step_probe.py PORT
"""
import re
import socket
import sys
import time

sock = socket.create_connection(("127.0.0.1", int(sys.argv[1])))
sock.settimeout(5)
buf = b""


def until(pattern):
    global buf
    while not re.search(pattern, buf):
        buf += sock.recv(4096)
    m = re.search(pattern, buf)
    out, buf = buf[: m.end()], buf[m.end():]
    return out.decode()


def cmd(line):
    sock.sendall(line.encode() + b"\r\n")
    return until(rb"(OK|ERROR)\r\n")


def pos():
    return float(re.search(r"position = (\S+)", cmd("getpos 1")).group(1))


until(rb"Authorization code: ")
sock.sendall(b"123456\r\n")
until(rb"success\r\n")
sock.sendall(b"echo off\r\n")
until(rb"OK\r\n")
for line in ("setm 1 stp", "setf 1 1000", "setv 1 60"):
    cmd(line)
for d in ("stepu", "stepd"):
    for n in (1, 1, 1, 2, 5, 10, 20, 20, 20):
        p0 = pos()
        cmd(f"{d} 1 {n}")
        cmd("stepw 1")
        time.sleep(0.02)
        p1 = pos()
        time.sleep(0.1)
        p2 = pos()
        print(f"{d} {n:2d}: moved {(p1 - p0) * 1e9:8.1f} nm, {(p1 - p0) * 1e9 / n:7.1f} nm per period, "
              f"then {(p2 - p1) * 1e9:5.1f} nm in 0.1 s")
