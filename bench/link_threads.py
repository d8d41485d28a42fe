#!/usr/bin/env python3
"""What the DDS link costs the machine, per thread (docs/benchmarks.md).

    /usr/bin/python3 bench/link_threads.py [MICROCOBOT [DOMAIN]]

Starts `serve --role slave` and `serve --role master` on a DDS domain (default 87), both holding
(no client), waits 3 s, then reads every thread's voluntary context switches and CPU time
(/proc/<pid>/task/*/{status,stat}) over 5 s, one process after the other. Prints the threads that
woke more than 50 times a second or used more than 5 ms of CPU per second, and each process's total.
"""
import os
import subprocess
import sys
import tempfile
import time

cli = sys.argv[1] if len(sys.argv) > 1 else "build/release/apps/microcobot/microcobot"
domain = sys.argv[2] if len(sys.argv) > 2 else "87"
tick = os.sysconf("SC_CLK_TCK")


def serve(role, out):
    p = subprocess.Popen([cli, "serve", "--role", role, "--domain", domain, "--listen", "127.0.0.1:0",
                          "--out", out, "--duration", "30"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    p.stdout.readline()  # the console's URL: the platform is up
    return p


def snapshot(pid):
    threads = {}
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            status = open(f"/proc/{pid}/task/{tid}/status").read()
            wakes = int(next(l for l in status.splitlines() if l.startswith("voluntary_ctxt")).split()[1])
            stat = open(f"/proc/{pid}/task/{tid}/stat").read().rsplit(")", 1)[1].split()
            comm = open(f"/proc/{pid}/task/{tid}/comm").read().strip()
            threads[tid] = (wakes, int(stat[11]) + int(stat[12]), comm)  # utime + stime, ticks
        except (FileNotFoundError, ProcessLookupError):
            pass  # a thread that ended meanwhile
    return threads


with tempfile.TemporaryDirectory() as out:
    slave = serve("slave", os.path.join(out, "slave"))
    master = serve("master", os.path.join(out, "master"))
    try:
        time.sleep(3)
        for name, p in (("slave", slave), ("master", master)):
            a = snapshot(p.pid)
            time.sleep(5)
            b = snapshot(p.pid)
            total_w = total_c = 0.0
            for tid in sorted(b):
                if tid not in a:
                    continue
                w = (b[tid][0] - a[tid][0]) / 5
                c = (b[tid][1] - a[tid][1]) * 1000 / tick / 5
                total_w += w
                total_c += c
                if w > 50 or c > 5:
                    print(f"{name} thread {tid} {b[tid][2]:12s} wakes/s {w:7.0f}  CPU ms/s {c:6.1f}")
            print(f"{name} total: wakes/s {total_w:.0f}, CPU ms/s {total_c:.1f}")
    finally:
        for p in (slave, master):
            p.terminate()
            p.wait()
