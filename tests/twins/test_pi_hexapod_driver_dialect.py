"""The `pi-hexapod` driver speaks what PIPython speaks to a C-887. A recording stand-in (a TCP
relay that logs every byte the driver sends) sits between the driver's platform (one `microcobot
serve`, `parallel_positioner: {driver: pi-hexapod}`) and the hexapod twin (another `serve
--emulate gcs2-hexapod`); the driver connects, references, moves the platform on a vendor
client's `MOV` and is stopped. Every line it sent must be one PIPython sends: a command of the
golden transcript written from PIPython's sources (tests/data/gcs2_hexapod/pipython_connect.txt)
in the same argument form, or one of the few functions of PIPython's gcscommands.py the connect
sequence does not use (listed below with the function that sends it). The twin, which the same
transcript checks (test_gcs2_hexapod.py), answered each (ERR? 0 throughout)."""

import os
import re
import signal
import socket
import subprocess
import tempfile
import threading
import time

from twin_clients import RawGcs, read_transcript

DATA = os.path.join(os.path.dirname(__file__), "..", "data", "gcs2_hexapod")
AXES = "XYZUVW"
NUMBER = r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?"

# The driver's lines that the connect transcript lacks, each with the PIPython function
# (pipython/gcscommands.py) that sends the same form.
PIPYTHON_BEYOND_THE_TRANSCRIPT = {
    "SAI?": ("qSAI_ALL", r"ALL"),
    "KEN?": ("qKEN", r""),
    "SPI?": ("qSPI", r"R S T"),
    "VLS?": ("qVLS", r""),
    "VLS": ("VLS", NUMBER),
}


AXIS_LIST = r"[XYZUVW]( [XYZUVW])*"
AXIS_VALUES = r"[XYZUVW] %s( [XYZUVW] %s)*" % (NUMBER, NUMBER)


def form(mnemonic, args):
    """The arguments' form as a regular expression: none, a list of axes, {axis value} pairs (any
    of the six axes: PIPython's functions take a dict of them), or the words themselves."""
    words = args.split()
    if not words:
        return ""
    if all(w in AXES for w in words):
        return AXIS_LIST
    if len(words) % 2 == 0 and all(w in AXES for w in words[::2]) and \
            all(re.fullmatch(NUMBER, w) for w in words[1::2]):
        return AXIS_VALUES
    return " ".join(re.escape(w) for w in words)


def transcript_forms():
    """{mnemonic: set of argument regexes} of the lines PIPython sends in the transcript."""
    forms = {}
    for step in read_transcript(os.path.join(DATA, "pipython_connect.txt")):
        if step[0] in ("send", "poll"):
            line = step[1]
            mnemonic, _, args = line.partition(" ")
            forms.setdefault(mnemonic, set()).add(form(mnemonic, args))
    return forms


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

    def lines(self):
        """What the client sent: LF-terminated lines, the single bytes 5, 7 and 24 as #5, #7, #24."""
        with self.lock:
            data = bytes(self.sent)
        out, line = [], bytearray()
        for b in data:
            if b in (5, 7, 24) and not line:
                out.append(f"#{b}")
            elif b == 10:
                out.append(line.decode("latin-1"))
                line = bytearray()
            else:
                line.append(b)
        return out

    def close(self):
        self.listener.close()


def start_serve(args, config_text, out):
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


def ask(c, line, lines=1):
    c.write(line)
    return [c.read_line().rstrip(" ") for _ in range(lines)]


def test_the_drivers_lines_are_pipythons():
    twin, twin_ports = start_serve(["--emulate", "gcs2-hexapod=127.0.0.1:0"], "positioner: parallel\n",
                                   tempfile.mkdtemp(prefix="mc_twin_"))
    stand_in = RecordingStandIn(twin_ports["gcs2-hexapod"])
    platform = None
    try:
        # The platform on the driver, through the stand-in; its own twin lets a vendor client move it.
        platform, ports = start_serve(
            ["--emulate", "gcs2-hexapod=127.0.0.1:0"],
            "positioner: parallel\nparallel_positioner: {driver: pi-hexapod, connection: \"127.0.0.1:%d,timeout_s=1,stale_s=0.5\"}\n"
            % stand_in.port, tempfile.mkdtemp(prefix="mc_driver_"))
        client = RawGcs(ports["gcs2-hexapod"])
        try:
            client.write("FRF")
            assert ask(client, "ERR?") == ["0"]
            end = time.monotonic() + 60
            while ask(client, "FRF? X")[0] != "X=1":
                assert time.monotonic() < end, "the platform's twin never referenced"
                # A reference the platform held short (error 10: its protocol thread starved past
                # the heartbeat's 0.2 s, as under a sanitizer on a loaded machine) is asked again,
                # as a lab script would.
                if ask(client, "ERR?") == ["10"]:
                    client.write("FRF")
                time.sleep(0.05)
            move = "MOV X 0.02 Y -0.01 Z 0.005 W 0.05"
            client.write(move)
            assert ask(client, "ERR?") == ["0"]
            end = time.monotonic() + 60
            while ask(client, "ONT? X Y Z U V W", 6) != [f"{a}=1" for a in AXES]:
                assert time.monotonic() < end, "the move never ended on target"
                if ask(client, "ERR?") == ["10"]:  # held short, as the reference above
                    client.write(move)
                time.sleep(0.05)
        finally:
            client.close()
        stop(platform)  # the driver's safe state (#24) goes through the stand-in too
        platform = None
        lines = stand_in.lines()
    finally:
        if platform is not None:
            platform.kill()
        stand_in.close()
        stop(twin)

    sent_moves = [l for l in lines if l.startswith("MOV ")]
    assert sent_moves, f"the driver sent no MOV: {lines}"
    assert "#24" in lines, "the driver's safe state (#24, stop all) was not sent"
    forms = transcript_forms()
    foreign = []
    for line in lines:
        mnemonic, _, args = line.partition(" ")
        if any(re.fullmatch(f, args) for f in forms.get(mnemonic, ())):
            continue
        beyond = PIPYTHON_BEYOND_THE_TRANSCRIPT.get(mnemonic)
        if beyond and re.fullmatch(beyond[1], args):
            continue
        foreign.append(line)
    print(f"the driver sent {len(lines)} lines, {len(set(lines))} different; mnemonics: "
          f"{sorted({l.partition(' ')[0] for l in lines})}")
    assert not foreign, f"lines PIPython does not send in that form: {sorted(set(foreign))}"
