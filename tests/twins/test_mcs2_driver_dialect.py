"""The `smaract-mcs2` driver speaks what public MCS2 clients speak. A recording stand-in (a TCP
relay that keeps every byte the driver sends) sits between the driver's platform (one `microcobot
serve`, `devices: {driver: smaract-mcs2}`, Z on a channel without sensor stepped open loop) and the
MCS2 twin (another `serve --emulate mcs2`, channel 2 built without a sensor); the driver connects,
references, moves the platform on a vendor client's GCS `MOV`s and is stopped. Every command it
sent (one per CR LF line) must be one that the EPICS motorSmarAct driver or kamzik3 sends, in the
same form: a command of their golden transcripts (tests/data/mcs2/*.txt, each written from its
client's public source and named in its header) with the channel index free and each number of the
same kind (an integer where they write an integer), or the one line listed below with its reason.
The twin, which the same transcripts check (test_mcs2_pyvisa.py), answered them all."""

import os
import re
import tempfile
import time

from twin_clients import RawGcs, RecordingStandIn, start_serve, stop

DATA = os.path.join(os.path.dirname(__file__), "..", "data", "mcs2")
INTEGER = r"-?\d+"
DECIMAL = r"-?\d+\.\d+"

# What the driver sends that neither client does, with the reason it is safe on a real MCS2.
BEYOND_THE_TRANSCRIPTS = {
    "*IDN?": "SCPI's identification query, which the MCS2 answers as every SCPI device: the driver "
             "refuses anything but an MCS2 on the port by it, where both clients trust the port given",
}


def form(line):
    """A command's form: the channel or module index after CHAN, MOD, MOVE, REF, CAL, STOP made
    <n>, each argument an integer or a decimal pattern (or itself)."""
    command, _, args = line.partition(" ")
    command = re.sub(r"^:(CHAN|MOD|MOVE|REF|CAL|STOP)\d+", r":\1<n>", command)
    words = []
    for w in args.split():
        if re.fullmatch(INTEGER, w):
            words.append(INTEGER)
        elif re.fullmatch(DECIMAL, w):
            words.append(DECIMAL)
        else:
            words.append(re.escape(w))
    return command, " ".join(words)


def transcript_forms():
    """{command: set of argument patterns} the transcripts send (`>` lines, `~` polls, and the line
    a `#! append` directive adds after each command)."""
    forms = {}
    for name in sorted(os.listdir(DATA)):
        if not name.endswith(".txt"):
            continue
        with open(os.path.join(DATA, name), encoding="utf-8") as f:
            for raw in f:
                line = raw.rstrip("\n")
                if line.startswith("#! append "):
                    sent = line[len("#! append "):]
                elif line.startswith("> "):
                    sent = line[2:]
                elif line.startswith("~ "):
                    sent = line[2:].split(" => ")[0]
                else:
                    continue
                command, args = form(sent)
                forms.setdefault(command, set()).add(args)
    return forms


def ask(c, line, lines=1):
    c.write(line)
    return [c.read_line().rstrip(" ") for _ in range(lines)]


def wait(client, query, expected, redo, what):
    """Asks `query` until it reads `expected`; a command the platform held short (GCS error 10:
    its protocol thread starved past the heartbeat's 0.2 s under a sanitizer on a loaded machine)
    is sent again, as a lab script would."""
    end = time.monotonic() + 60
    while ask(client, query, len(expected)) != expected:
        assert time.monotonic() < end, what
        if ask(client, "ERR?") == ["10"]:
            client.write(redo)
        time.sleep(0.05)


def test_the_drivers_commands_are_the_public_clients():
    twin, twin_ports = start_serve(["--emulate", "mcs2=127.0.0.1:0,no_sensor=2"], "",
                                   tempfile.mkdtemp(prefix="mc_twin_"))
    stand_in = RecordingStandIn(twin_ports["mcs2"])
    platform = None
    try:
        # The platform on the driver, through the stand-in; its own GCS twin lets a vendor client
        # move it.
        platform, ports = start_serve(
            ["--emulate", "gcs2=127.0.0.1:0"],
            "devices: {driver: smaract-mcs2, connection: \"127.0.0.1:%d,velocity_mm_s=1,sensorless=step,"
            "timeout_s=1,stale_s=0.5\"}\n" % stand_in.port, tempfile.mkdtemp(prefix="mc_driver_"))
        client = RawGcs(ports["gcs2"])
        try:
            reference = "FRF 1 2"
            client.write("SVO 1 1")
            client.write("SVO 2 1")
            client.write(reference)
            assert ask(client, "ERR?") == ["0"]
            wait(client, "FRF? 1 2", ["1=1", "2=1"], reference, "the platform never referenced")
            move = "MOV 1 0.02 2 -0.01"
            client.write(move)
            assert ask(client, "ERR?") == ["0"]
            wait(client, "ONT? 1 2", ["1=1", "2=1"], move, "the move never ended on target")
        finally:
            client.close()
        stop(platform)  # the driver's safe state (:STOP on each channel) goes through the stand-in too
        platform = None
        lines = stand_in.lines(single_bytes=())
    finally:
        if platform is not None:
            platform.kill()
        stand_in.close()
        stop(twin)

    commands = [c for line in lines for c in line.split(";")]
    assert any(c.startswith(":MOVE") for c in commands), f"the driver sent no :MOVE: {lines}"
    assert any(c.startswith(":STOP") for c in commands), "the driver's safe state (:STOP) was not sent"
    assert any(re.fullmatch(r":CHAN2:MMOD 4", c) for c in commands), "channel 2 was not put in step mode"
    forms = transcript_forms()
    foreign = []
    for c in commands:
        command, args = form(c)
        if args in forms.get(command, ()):
            continue
        if c in BEYOND_THE_TRANSCRIPTS:
            continue
        foreign.append(c)
    print(f"the driver sent {len(commands)} commands, {len(set(commands))} different; forms: "
          f"{sorted({form(c)[0] for c in commands})}")
    assert not foreign, f"commands no public client sends in that form: {sorted(set(foreign))}"
