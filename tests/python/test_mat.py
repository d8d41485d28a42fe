""".mat files through matio: written files read by scipy.io (an independent reader), scipy's files
read by the library, identification and dsp from .mat, and one-line errors for bad files."""

import json

import numpy as np
import pytest
import scipy.io

from microcobot import dsp, identify, platform, stickslip

from conftest import cli_error


def test_write_mat_round_trip_through_scipy(tmp_path):
    f = tmp_path / "a.mat"
    rng = np.random.default_rng(1)
    m = rng.standard_normal((3, 4))
    platform.write_mat(f, {"t_s": np.arange(5.0), "m": m, "g": 9.81})
    d = scipy.io.loadmat(f)
    np.testing.assert_array_equal(d["t_s"], np.arange(5.0).reshape(5, 1))  # vectors are columns
    np.testing.assert_array_equal(d["m"], m)
    assert d["g"].shape == (1, 1) and d["g"][0, 0] == 9.81
    back = platform.read_mat(f)
    np.testing.assert_array_equal(back["m"], m)
    np.testing.assert_array_equal(back["t_s"], np.arange(5.0).reshape(5, 1))
    # A file scipy wrote (row vectors, int32, single) reads as doubles.
    g = tmp_path / "s.mat"
    scipy.io.savemat(g, {"x": np.arange(4.0), "k": np.int32(7), "y": np.float32([[1.5, 2.5]])})
    r = platform.read_mat(g)
    np.testing.assert_array_equal(r["x"], [[0.0, 1.0, 2.0, 3.0]])
    assert r["k"][0, 0] == 7.0 and r["y"].dtype == np.float64
    with pytest.raises(ValueError, match="non-finite"):
        platform.write_mat(tmp_path / "n.mat", {"x": np.array([1.0, np.nan])})
    with pytest.raises(ValueError, match="not a MATLAB identifier"):
        platform.write_mat(tmp_path / "n.mat", {"1x": np.zeros(2)})
    assert not (tmp_path / "n.mat").exists()


def test_cli_simulate_format_mat(tmp_path, cli):
    rc, _, err = cli("stickslip", "simulate", "--amplitude", 60, "--frequency", 500, "--duration", 0.01,
                     "--format", "mat", "--out", tmp_path / "m", "--json")
    assert rc == 0, err
    d = scipy.io.loadmat(tmp_path / "m" / "results.mat")
    r = stickslip.simulate(amplitude_V=60.0, frequency_Hz=500.0, duration_s=0.01)
    for k in ("t_s", "u_V", "x1_m", "x2_m"):
        np.testing.assert_array_equal(d[k][:, 0], r[k])
    assert d["final_position_m"][0, 0] == r["x2_m"][-1]
    assert not (tmp_path / "m" / "trajectory.csv").exists()
    # Without --out the format would have nowhere to go: a usage error (exit 2), one line.
    rc, _, err = cli("stickslip", "simulate", "--duration", 0.001, "--format", "mat")
    assert rc == 2 and "--out" in cli_error(err)


def test_cli_control_trajectory_format_mat_equals_its_csv(tmp_path, cli):
    # The same run twice (deterministic): results.mat holds the CSV's columns and the summary.
    args = ("control", "trajectory", "--profile", "trapezoid", "--distance", 20e-6, "--json")
    rc, out, err = cli(*args, "--out", tmp_path / "csv")
    assert rc == 0, err
    rc, out_mat, err = cli(*args, "--format", "mat", "--out", tmp_path / "mat")
    assert rc == 0, err
    assert out == out_mat
    d = scipy.io.loadmat(tmp_path / "mat" / "results.mat")
    csv = np.genfromtxt(tmp_path / "csv" / "trajectory.csv", delimiter=",", names=True, comments="#")
    assert len(csv) > 100
    for k in csv.dtype.names:
        np.testing.assert_allclose(d[k][:, 0], csv[k], rtol=1e-15, atol=0, err_msg=k)
    summary = json.loads(out)
    assert d["rms_error_m"][0, 0] == summary["rms_error_m"]
    assert d["baseline_hybrid_rms_error_m"][0, 0] == summary["baseline"]["hybrid"]["rms_error_m"]
    assert not (tmp_path / "mat" / "trajectory.csv").exists()


@pytest.fixture(scope="module")
def sine_record(tmp_path_factory):
    """A slider response to a 40 V / 50 Hz sine (scanning mode), the input of identify hysteresis."""
    r = stickslip.simulate(wave="sine", amplitude_V=40.0, frequency_Hz=50.0, duration_s=0.06, record_every=4)
    d = tmp_path_factory.mktemp("rec")
    scipy.io.savemat(d / "sine.mat", {"t": r["t_s"], "u": r["u_V"], "x": r["x2_m"]})
    with open(d / "sine.csv", "w") as f:
        f.write("t_s,u_V,x_m\n")
        for row in zip(r["t_s"], r["u_V"], r["x2_m"]):
            f.write(",".join(repr(float(v)) for v in row) + "\n")
    return d, r


def test_identify_from_mat_equals_csv_and_arrays(sine_record, cli, tmp_path):
    d, r = sine_record
    rc, out_mat, err = cli("identify", "hysteresis", "--in", d / "sine.mat", "--json")
    assert rc == 0, err
    rc, out_csv, err = cli("identify", "hysteresis", "--in", d / "sine.csv", "--json")
    assert rc == 0, err
    jm, jc = json.loads(out_mat), json.loads(out_csv)
    jm.pop("params_files"), jc.pop("params_files")
    assert jm == jc
    from_arrays = identify.hysteresis(r["t_s"], r["u_V"], r["x2_m"])
    from_file = identify.hysteresis(d / "sine.mat")
    assert from_arrays["static_gain_m_V"] == from_file["static_gain_m_V"] == jm["static_gain_m_V"]
    # The identified loop reproduces the record (thesis §2.5.2.2: a few % of the stroke).
    assert from_arrays["rms_fraction"] < 0.05
    # --format mat writes the summary's numbers.
    rc, _, err = cli("identify", "hysteresis", "--in", d / "sine.mat", "--format", "mat", "--out", tmp_path / "o")
    assert rc == 0, err
    m = scipy.io.loadmat(tmp_path / "o" / "results.mat")
    assert m["static_gain_m_V"][0, 0] == pytest.approx(jm["static_gain_m_V"], rel=1e-12)


def test_dsp_welch_reads_mat(sine_record, cli):
    d, _ = sine_record
    a = cli("dsp", "welch", "--in", d / "sine.mat", "--column", "x", "--fs", 25000, "--nperseg", 256, "--json")
    b = cli("dsp", "welch", "--in", d / "sine.csv", "--column", "x_m", "--fs", 25000, "--nperseg", 256, "--json")
    assert a[0] == 0 and b[0] == 0, a[2] + b[2]
    ja, jb = json.loads(a[1]), json.loads(b[1])
    assert ja == jb and len(ja["psd"]) == 129
    # The module's welch on the same samples gives the CLI's numbers.
    x = scipy.io.loadmat(d / "sine.mat")["x"].ravel()
    f, p = dsp.welch(x, fs=25000.0, nperseg=256)
    np.testing.assert_array_equal(p, ja["psd"])


@pytest.mark.parametrize(
    "content,message",
    [
        ({"t": np.arange(100.0), "u": np.zeros(100)}, "variable 'x': missing (have: t, u)"),
        ({"t": np.arange(100.0), "u": np.zeros((4, 25)), "x": np.zeros(100)}, "variable 'u': expected a vector"),
        ({"t": np.arange(100.0), "u": np.zeros(100), "x": np.r_[np.zeros(17), np.nan, np.zeros(82)]},
         "variable 'x': non-finite value nan at index 17"),
        ({"t": np.arange(100.0), "u": np.zeros(99), "x": np.zeros(100)}, "variable 'u': length 99, expected 100"),
        ({"t": np.arange(100.0), "u": np.zeros(100), "x": np.array(["a"])}, "variable 'x': expected"),
    ],
)
def test_bad_mat_files_give_one_line_errors(tmp_path, cli, content, message):
    f = tmp_path / "bad.mat"
    scipy.io.savemat(f, content)
    rc, _, err = cli("identify", "hysteresis", "--in", f)
    assert rc == 3
    line = cli_error(err)
    assert line.startswith(str(f) + ": ") and message in line
    with pytest.raises(ValueError) as e:
        identify.record(f)
    assert str(e.value) == line


def test_not_a_mat_file(tmp_path, cli):
    f = tmp_path / "x.mat"
    f.write_text("t,u,x\n1,2,3\n")
    rc, _, err = cli("identify", "hysteresis", "--in", f)
    assert rc == 3 and "not a MATLAB .mat file" in cli_error(err)
    rc, _, err = cli("identify", "hysteresis", "--in", tmp_path / "missing.mat")
    assert rc == 3 and "no such file" in cli_error(err)


def test_dsp_butter_writes_scipys_sos_as_csv_and_mat(tmp_path, cli):
    import scipy.signal

    args = ("dsp", "butter", "--order", 4, "--fc", 200, "--fs", 10000, "--json")
    rc, out, err = cli(*args, "--out", tmp_path / "csv")
    assert rc == 0, err
    rc, out_mat, err = cli(*args, "--format", "mat", "--out", tmp_path / "mat")
    assert rc == 0, err
    assert out == out_mat
    ref = scipy.signal.butter(4, 200, fs=10000, output="sos")
    csv = np.genfromtxt(tmp_path / "csv" / "sos.csv", delimiter=",", names=True, comments="#")
    np.testing.assert_allclose(np.column_stack([csv[k] for k in ("b0", "b1", "b2", "a0", "a1", "a2")]), ref,
                               rtol=1e-9, atol=1e-15)
    d = scipy.io.loadmat(tmp_path / "mat" / "results.mat")
    assert d["sos"].shape == (2, 6)  # sections x coefficients, scipy's layout
    np.testing.assert_allclose(d["sos"], ref, rtol=1e-9, atol=1e-15)
    np.testing.assert_array_equal(d["b0"][:, 0], d["sos"][:, 0])
    assert not (tmp_path / "mat" / "sos.csv").exists()


def test_dsp_commands_write_what_they_print(tmp_path, cli):
    rc, out, err = cli("dsp", "mls", "--bits", 5, "--json", "--format", "mat", "--out", tmp_path / "m")
    assert rc == 0, err
    np.testing.assert_array_equal(scipy.io.loadmat(tmp_path / "m" / "results.mat")["seq"][:, 0],
                                  json.loads(out)["seq"])
    # An FRF of a known system, fitted back: tf.csv holds num (padded) and den, highest power first.
    f = np.linspace(1.0, 2000.0, 400)
    s = 2j * np.pi * f
    h = 1.0 / (s**2 / (2 * np.pi * 300.0) ** 2 + s / (2 * np.pi * 300.0 * 5.0) + 1.0)
    frf = tmp_path / "frf.csv"
    np.savetxt(frf, np.column_stack([f, h.real, h.imag]), delimiter=",", header="f_Hz,re,im", comments="")
    rc, out, err = cli("dsp", "tffit", "--in", frf, "--nz", 0, "--np", 2, "--json", "--out", tmp_path / "t")
    assert rc == 0, err
    j = json.loads(out)
    tf = np.genfromtxt(tmp_path / "t" / "tf.csv", delimiter=",", names=True, comments="#")
    np.testing.assert_array_equal(tf["power"], [2, 1, 0])
    np.testing.assert_array_equal(tf["den"], j["den"])
    np.testing.assert_array_equal(tf["num"], [0.0, 0.0] + j["num"])
    np.testing.assert_allclose(np.polyval(tf["num"], s) / np.polyval(tf["den"], s), h, rtol=1e-6)


@pytest.mark.parametrize(
    "command,csv_names",
    [
        (("haptics", "identify"), {"frf_lf.csv": "lf_", "frf_hf.csv": "hf_"}),
        (("tweezers", "robotic"), {"robotic.csv": ""}),
    ],
)
def test_device_commands_format_mat_equals_their_csv(tmp_path, cli, command, csv_names):
    rc, out, err = cli(*command, "--json", "--out", tmp_path / "csv")
    assert rc == 0, err
    rc, out_mat, err = cli(*command, "--json", "--format", "mat", "--out", tmp_path / "mat")
    assert rc == 0, err
    assert out == out_mat
    d = scipy.io.loadmat(tmp_path / "mat" / "results.mat")
    columns = set()
    for name, prefix in csv_names.items():
        csv = np.genfromtxt(tmp_path / "csv" / name, delimiter=",", names=True, comments="#")
        for k in csv.dtype.names:
            np.testing.assert_allclose(d[prefix + k][:, 0], csv[k], rtol=1e-15, atol=0, err_msg=k)
            columns.add(prefix + k)
        assert not (tmp_path / "mat" / name).exists()
    for k, v in json.loads(out).items():
        # A summary number under a column's name (tweezers robotic's final finger_force_N) is
        # left to the column (docs/cli.md).
        if isinstance(v, (int, float)) and not isinstance(v, bool) and k not in columns:
            assert d[k].shape == (1, 1) and d[k][0, 0] == v, k
    assert (tmp_path / "mat" / "index.html").exists()  # the report as usual
