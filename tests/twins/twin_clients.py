"""Shared helpers of the twins' client tests: a `microcobot serve --emulate` process on
loopback port 0, the golden-transcript player (tests/data/gcs2/*.txt, syntax in their headers), and
the recording stand-in that relays a driver to a twin and keeps what the driver sent."""

import os
import re
import signal
import socket
import subprocess
import tempfile
import threading
import time


class Serve:
    """`microcobot serve` with the twins of `protocols` (by default GCS 2.0 and ANC300) on
    loopback, free ports; stop() ends it (SIGINT)."""

    def __init__(self, protocols=("gcs2", "anc300")):
        cli = os.environ.get("MC_CLI")
        if not cli:
            raise RuntimeError("MC_CLI not set (run through ctest)")
        self.out = tempfile.mkdtemp(prefix="mc_twin_")
        emulate = []
        for p in protocols:
            emulate += ["--emulate", f"{p}=127.0.0.1:0"]
        self.proc = subprocess.Popen(
            [cli, "serve", "--listen", "127.0.0.1:0", "--out", self.out] + emulate,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.url = self.proc.stdout.readline().strip()
        self.ports = {}
        for _ in protocols:
            words = self.proc.stdout.readline().split()
            assert len(words) == 3 and words[0] == "emulate", words
            self.ports[words[1]] = int(words[2].rsplit(":", 1)[1])

    def stop(self):
        self.proc.send_signal(signal.SIGINT)
        try:
            self.proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            raise
        assert self.proc.returncode == 0, self.proc.stderr.read()


class RawGcs:
    """A GCS 2.0 client over a plain socket (no library): LF lines, replies read until a line
    that does not end in a space."""

    def __init__(self, port):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=5)
        self.buf = b""

    def write(self, line):
        if line in ("#5", "#7", "#24"):
            self.sock.sendall(bytes([int(line[1:])]))
        else:
            self.sock.sendall(line.encode("latin-1") + b"\n")

    def read_line(self):
        while b"\n" not in self.buf:
            chunk = self.sock.recv(4096)
            if not chunk:
                raise EOFError("the twin closed the connection")
            self.buf += chunk
        line, self.buf = self.buf.split(b"\n", 1)
        return line.decode("latin-1")

    def close(self):
        self.sock.close()


def read_transcript(path):
    """The transcript's steps: ('send', line) | ('reply', [regex, ...]) | ('poll', query, regex)."""
    steps = []
    with open(path, encoding="utf-8") as f:
        for raw in f:
            line = raw.rstrip("\n")
            if not line or line.startswith("#"):
                continue
            kind, text = line[0], line[2:]
            if kind == ">":
                steps.append(("send", text))
            elif kind == "<":
                if steps and steps[-1][0] == "reply":
                    steps[-1][1].append(text)
                else:
                    steps.append(("reply", [text]))
            elif kind == "~":
                query, expected = text.split(" => ")
                steps.append(("poll", query, expected))
            else:
                raise ValueError(f"{path}: bad line {line!r}")
    return steps


def replay(path, write, read_line, timeout_s=10.0):
    """Plays a transcript through write(line) / read_line(); asserts every reply."""
    for step in read_transcript(path):
        if step[0] == "send":
            write(step[1])
        elif step[0] == "reply":
            expected = step[1]
            for k, pattern in enumerate(expected):
                got = read_line()
                last = k + 1 == len(expected)
                # Multi-line replies: every line but the last ends in a space (PI's GCS 2.0).
                assert got.endswith(" ") != last, (path, pattern, got)
                pattern = pattern.replace("\\xb1", "\xb1")
                assert re.fullmatch(pattern, got.rstrip(" ")), (path, pattern, got)
        else:
            _, query, pattern = step
            end = time.monotonic() + timeout_s
            while True:
                write(query)
                got = read_line()
                if re.fullmatch(pattern, got):
                    break
                assert time.monotonic() < end, (path, query, got)
                time.sleep(0.02)


def replay_over_pyvisa(port, path, timeout_s=10.0):
    """Plays a GCS transcript through pyvisa-py's TCPIP SOCKET resource on loopback `port`, the
    single-byte commands (#5, #7, #24) as raw bytes."""
    import pyvisa

    rm = pyvisa.ResourceManager("@py")
    inst = rm.open_resource(f"TCPIP::127.0.0.1::{port}::SOCKET",
                            read_termination="\n", write_termination="\n", timeout=5000)
    inst.encoding = "latin-1"  # #7 answers the byte 0xB1

    def write(line):
        if line in ("#5", "#7", "#24"):
            inst.write_raw(bytes([int(line[1:])]))
        else:
            inst.write(line)

    try:
        replay(path, write, inst.read, timeout_s=timeout_s)
    finally:
        inst.close()
        rm.close()


class RecordingStandIn:
    """Relays one client to `port` on loopback and keeps every byte the client sent."""

    def __init__(self, port):
        self.target = port
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self.sent = bytearray()
        self.lock = threading.Lock()
        self.threads = []
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self):
        while True:
            try:
                client, _ = self.listener.accept()
            except OSError:
                return
            upstream = socket.create_connection(("127.0.0.1", self.target))
            for src, dst, keep in ((client, upstream, True), (upstream, client, False)):
                t = threading.Thread(target=self._pump, args=(src, dst, keep), daemon=True)
                t.start()
                self.threads.append(t)

    def _pump(self, src, dst, keep):
        try:
            while True:
                chunk = src.recv(4096)
                if not chunk:
                    break
                if keep:
                    with self.lock:
                        self.sent += chunk
                dst.sendall(chunk)
        except OSError:
            pass
        finally:
            for s in (src, dst):
                try:
                    s.shutdown(socket.SHUT_RDWR)
                except OSError:
                    pass

    def lines(self, single_bytes=(5, 7, 24)):
        """What the client sent: its lines (LF-terminated, a CR before the LF dropped), and each of
        `single_bytes` sent between lines as #<byte> (GCS 2.0's #5, #7, #24)."""
        with self.lock:
            data = bytes(self.sent)
        out, line = [], bytearray()
        for b in data:
            if b in single_bytes and not line:
                out.append(f"#{b}")
            elif b == 10:
                out.append(line.decode("latin-1").removesuffix("\r"))
                line = bytearray()
            else:
                line.append(b)
        return out

    def close(self):
        self.listener.close()


def start_serve(args, config_text, out):
    """`microcobot serve` with `config_text` as its configuration and `args`; returns the process and
    the ports of its `--emulate` twins by protocol."""
    cli = os.environ.get("MC_CLI")
    if not cli:
        raise RuntimeError("MC_CLI not set (run through ctest)")
    config = os.path.join(out, "config.yaml")
    with open(config, "w", encoding="utf-8") as f:
        f.write(config_text)
    proc = subprocess.Popen([cli, "serve", "--listen", "127.0.0.1:0", "--out", out, "--config", config] + args,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    url = proc.stdout.readline()
    assert url.startswith("http"), (url, proc.stderr.read() if proc.poll() is not None else "")
    ports = {}
    for _ in [a for a in args if a == "--emulate"]:
        words = proc.stdout.readline().split()
        assert len(words) == 3 and words[0] == "emulate", words
        ports[words[1]] = int(words[2].rsplit(":", 1)[1])
    return proc, ports


def stop(proc):
    proc.send_signal(signal.SIGINT)
    try:
        proc.wait(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        raise
    assert proc.returncode == 0, proc.stderr.read()
