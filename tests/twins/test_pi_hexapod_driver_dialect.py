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
import tempfile
import time

from twin_clients import RawGcs, RecordingStandIn, read_transcript, start_serve, stop

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
