"""The whole identification (thesis §2.5.2) from numpy arrays as from files: `identify.all` and
`identify.breakaway` on a synthetic campaign (`microcobot identify synth`, the simulated axis with
sensor effects) read by numpy, against the same campaign read from its directory."""

import pathlib

import numpy as np
import pytest

from microcobot import identify


def load(path):
    """A campaign file as the dict of arrays a lab would hold: {'t' [s], 'u' [V], 'x' [m]}."""
    with open(path) as f:
        lines = [line for line in f if not line.startswith("#")]
    assert lines[0].strip() == "t_s,u_V,x_m", path
    a = np.loadtxt(lines[1:], delimiter=",", ndmin=2)
    return {"t": a[:, 0], "u": a[:, 1], "x": a[:, 2]}


def run_of(path):
    """A sawtooth run: its arrays and its drive, from the file name sawtooth_<A>V_<f>Hz_<dir>.csv."""
    amplitude, frequency, direction = path.stem.split("_")[1:]
    return dict(load(path), amplitude_V=float(amplitude[:-1]), frequency_Hz=float(frequency[:-2]),
                direction=direction)


@pytest.fixture(scope="module")
def campaign(tmp_path_factory, cli):
    d = tmp_path_factory.mktemp("campaign")
    rc, _, err = cli("identify", "synth", "--grid", "small", "--out", d, "--json")
    assert rc == 0, err
    runs = [run_of(p) for p in sorted(pathlib.Path(d).glob("sawtooth_*.csv"))]
    assert len(runs) == 24
    return d, runs


def test_all_from_arrays_equals_all_from_the_directory(campaign):
    d, runs = campaign
    from_dir = identify.all(d)
    from_arrays = identify.all({"pe_step": load(d / "pe_step.csv"), "step": load(d / "step.csv"),
                                "sine": load(d / "sine.csv"), "sawtooth": runs})
    assert from_arrays["params"] == from_dir["params"]
    assert from_arrays["friction"]["params"] == from_dir["friction"]["params"]
    # The physics: the default axis identified back (Table 2.8's asperities within 1 %).
    truth = from_dir["params"]["friction"]
    from microcobot import stickslip
    default = stickslip.Actuator().params["friction"]
    for k in ("rho0_a_N_m", "rho0_b_N_m"):
        assert truth[k] == pytest.approx(default[k], rel=0.02), k
    # Without the PE record the PE is kept from the base parameters, and the notes say so.
    no_pe = identify.all({"step": d / "step.csv", "sine": load(d / "sine.csv"), "sawtooth": runs})
    assert no_pe["pe"] is None
    assert any("no pe_step record" in n for n in no_pe["notes"])


def test_hysteresis_says_how_it_took_the_record(campaign):
    """The sine record starts at rest: both fits' residuals are returned and the smaller wins; cut
    at its second period's start (its lowest voltage, a steady loop) it is taken as a loop."""
    d, _ = campaign
    sine = load(d / "sine.csv")
    r = identify.hysteresis(sine["t"], sine["u"], sine["x"])
    assert r["from_rest"] is True and r["first_fitted"] == 0
    assert r["rms_from_rest_m"] < r["rms_steady_loop_m"]
    assert r["voltage_noise_V"] == pytest.approx(0.4, rel=0.15)  # synth's 1 % of 40 V
    k = len(sine["t"]) // 2  # two periods: the second starts here, at the lowest voltage
    loop = identify.hysteresis(sine["t"][k:] - sine["t"][k], sine["u"][k:], sine["x"][k:])
    assert loop["from_rest"] is False and loop["first_fitted"] > 0


def test_breakaway_from_arrays_equals_breakaway_from_the_directory(campaign):
    d, runs = campaign
    a = identify.breakaway(runs)
    b = identify.breakaway(d)
    assert a["table"] == b["table"]
    assert len(a["runs"]) == 24 and a["runs"][0]["name"] == "runs[0]"
    # 40 V never steps below 1 kHz: those cells lie below their columns' fitted ones.
    assert "forward 40 V 100 Hz" in a["extrapolated"] and a["filled"] == b["filled"]


@pytest.mark.parametrize(
    "records,message",
    [
        ({"step": {}, "sine": {}, "sawtooth": []}, "records.step: missing 't'"),
        ({"sine": {}, "sawtooth": []}, "records: missing 'step'"),
        ({"step": {}, "sine": {}, "sawtooth": [], "saw": []}, "records: unknown key 'saw'"),
        (42, "records: expected a directory or a dict"),
    ],
)
def test_bad_records_raise_value_error_naming_what(records, message):
    with pytest.raises(ValueError, match=message):
        identify.all(records)


def test_bad_runs_raise_value_error_naming_the_run(campaign):
    _, runs = campaign
    with pytest.raises(ValueError, match=r"runs: no run"):
        identify.breakaway([])
    bad = [dict(runs[0]), dict(runs[1])]
    del bad[1]["frequency_Hz"]
    with pytest.raises(ValueError, match=r"runs\[1\]: missing 'frequency_Hz'"):
        identify.breakaway(bad)
    bad = [dict(runs[0], amplitude_V=-5.0)]
    with pytest.raises(ValueError, match=r"runs\[0\].amplitude_V"):
        identify.breakaway(bad)
    bad = [dict(runs[0], direction="sideways")]
    with pytest.raises(ValueError, match="sideways"):
        identify.breakaway(bad)
    bad = [dict(runs[0], x=runs[0]["x"][:-1])]
    with pytest.raises(ValueError, match=r"runs\[0\]: t, u and x must have the same length"):
        identify.breakaway(bad)
