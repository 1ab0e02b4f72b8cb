"""Measurement tables (restitution.fit.reading): the two layouts parse to the numbers written in them,
with units in the header only when SI, comments and blank lines skipped; each bad file is a one-line
DataError naming the file and the fault; write_times reads back to the same floats.

Every table is written here from numbers chosen here; the expected values are those numbers."""
import wave

import numpy as np
import pytest

from restitution.fit.datasets import DataError, ImpactTimes, ReboundPairs, check_drop_speeds
from restitution.fit.reading import read_csv, read_data, write_times

V_IN = [2.5, 1.75, 0.5, 3.125]  # [m/s]
V_OUT = [2.0, 1.5, 0.25, 2.0]  # [m/s]
SIGMA = [0.01, 0.02, 0.005, 0.04]  # [m/s]
T = [0.125, 0.6, 0.98, 1.25]  # [s]


def table(tmp_path, text, name="data.csv"):
    """The file ``name`` in ``tmp_path`` holding ``text`` (written as is, no newline translated)."""
    path = tmp_path / name
    path.write_bytes(text.encode("utf-8"))
    return path


def rows(*columns):
    """The lines of a table body, one per row of ``columns``."""
    return "".join(",".join(repr(value) for value in row) + "\n" for row in zip(*columns))


def test_rebound_pairs(tmp_path):
    pairs = read_csv(table(tmp_path, "v_in,v_out\n" + rows(V_IN, V_OUT)))
    assert isinstance(pairs, ReboundPairs) and pairs.sigma is None
    assert pairs.v_in.tolist() == V_IN and pairs.v_out.tolist() == V_OUT
    assert pairs.source == str(tmp_path / "data.csv")


def test_rebound_pairs_with_sigma_in_any_order_with_comments_units_and_blank_lines(tmp_path):
    text = ("\ufeff# drop tests, 2024-05-02\n\n"  # a byte order mark, as spreadsheets write
            " sigma [m/s] , v_out (m/s),V_IN [ m/s ]   # the speeds\r\n" +
            rows(SIGMA, V_OUT, V_IN).replace("\n", "  # a shot\r\n", 1) + "\n# end\n")
    pairs = read_csv(table(tmp_path, text))
    assert (pairs.v_in.tolist(), pairs.v_out.tolist(), pairs.sigma.tolist()) == (V_IN, V_OUT, SIGMA)


def test_impact_times(tmp_path):
    for header in ("t_impact", "t_impact [s]", "t_impact (s)"):
        times = read_csv(table(tmp_path, f"{header}\n" + rows(T), "times.txt"))
        assert isinstance(times, ImpactTimes) and times.t.tolist() == T


def test_read_data_takes_tables_by_their_suffix(tmp_path):
    assert read_data(table(tmp_path, "t_impact\n" + rows(T), "t.CSV")).t.tolist() == T
    assert read_data(table(tmp_path, "v_in,v_out\n" + rows(V_IN, V_OUT), "p.txt")).v_out.tolist() == V_OUT


def test_read_data_takes_a_wav_file_as_a_recording(tmp_path):
    path = tmp_path / "silence.wav"
    with wave.open(str(path), "wb") as wav:
        wav.setnchannels(1)
        wav.setsampwidth(2)
        wav.setframerate(44100)
        wav.writeframes(bytes(2 * 44100))
    message = fault(read_data, path)  # read by restitution.fit.recording: no click in a second of silence
    assert "no detectable impacts" in message


def fault(read, path):
    """The message of the DataError ``read(path)`` raises, checked to be one line naming the file."""
    with pytest.raises(DataError) as caught:
        read(path)
    message = str(caught.value)
    assert "\n" not in message and "\r" not in message
    assert str(path) in message, message
    return message


BAD_TABLES = {
    "missing column": ("v_in\n" + rows(V_IN), ["missing column v_out", "'v_in'", "t_impact", "sigma"]),
    "no known column": ("time,speed\n1,2\n", ["missing columns", "'time,speed'", "v_in,v_out", "t_impact"]),
    "no header": (rows(V_IN, V_OUT), ["the header is missing"]),
    "unknown column": ("v_in,v_out,drop\n1,0.5,3\n", ["unknown column 'drop'", "v_in,v_out"]),
    "mixed layouts": ("t_impact,v_in,v_out\n1,2,1\n", ["t_impact cannot share a table"]),
    "column twice": ("v_in,v_out,v_in\n1,0.5,1\n", ["'v_in' appears twice"]),
    "empty": ("# nothing yet\n\n", ["no header and no data"]),
    "two pairs": ("v_in,v_out\n" + rows(V_IN[:2], V_OUT[:2]), ["2 pairs", "at least 3"]),
    "two times": ("t_impact\n" + rows(T[:2]), ["2 impact times", "at least 3"]),
    "nan": ("v_in,v_out\n1,0.5\n2,nan\n3,1\n", ["v_out", "row 2", "not a finite number"]),
    "infinite time": ("t_impact\n1\ninf\n3\n", ["t_impact", "row 2", "not a finite number"]),
    "negative speed": ("v_in,v_out\n1,0.5\n2,-1\n3,1\n", ["v_out = -1 m/s", "row 2"]),
    "zero approach speed": ("v_in,v_out\n1,0.5\n0,0\n3,1\n", ["v_in = 0 m/s", "row 2"]),
    "faster rebound": ("v_in,v_out\n1,0.5\n2,2.5\n3,1\n", ["row 2", "v_out = 2.5 m/s > v_in = 2 m/s"]),
    "bad sigma": ("v_in,v_out,sigma\n1,0.5,0.1\n2,1,0\n3,1,0.1\n", ["sigma", "positive"]),
    "times not increasing": ("t_impact\n0.5\n1\n1\n", ["does not increase", "row 3"]),
    "speed in km/h": ("v_in [km/h],v_out\n1,0.5\n", ["'v_in [km/h]'", "unit 'km/h'", "m/s"]),
    "time in ms": ("t_impact (ms)\n1\n2\n3\n", ["unit 'ms'", "in s"]),
    "text in a cell": ("v_in,v_out\n1,0.5\n\n# a comment\n2,fast\n3,1\n", ["line 5 (row 2), column v_out", "'fast'"]),
    "empty cell": ("v_in,v_out\n1,0.5\n,1\n3,1\n", ["line 3 (row 2), column v_in", "''"]),
    "decimal comma": ("v_in,v_out\n1,0,5\n", ["line 2 has 3 cells, the header 2", "decimal comma"]),
    "short row": ("v_in,v_out,sigma\n1,0.5\n", ["line 2 has 2 cells, the header 3"]),
    # float() takes these, as 10, 1.5 and 1: a table holds plain decimal or scientific numbers only
    "digit separator": ("v_in,v_out\n1_0,0.5\n2,1\n3,1\n", ["line 2 (row 1), column v_in", "'1_0'", "not a number"]),
    "other script's digits": ("t_impact\n0.1\n\u0661.\u0665\n3\n", ["line 3 (row 2), column t_impact",
                                                                       "not a number"]),
    "padded exponent": ("v_in,v_out\n1e0_0,0.5\n2,1\n3,1\n", ["'1e0_0'", "not a number"]),
    # physically absurd: beyond the model's largest speed (10 km/s), times whose differences overflow
    "speed near 1e300": ("v_in,v_out\n1e300,1e299\n2e300,1e299\n3e300,1e299\n", ["v_in = 1e+300 m/s", "row 1",
                                                                                     "10000 m/s"]),
    "sigma near 1e-300": ("v_in,v_out,sigma\n1,0.5,0.1\n2,1,1e-300\n3,1,0.1\n", ["sigma = 1e-300 m/s", "row 2",
                                                                                 "1e-09 m/s"]),
    "sigma near 1e300": ("v_in,v_out,sigma\n1,0.5,1e300\n2,1,0.1\n3,1,0.1\n", ["sigma = 1e+300 m/s", "row 1"]),
    "times near 1e308": ("t_impact\n1e308\n1.5e308\n1.7e308\n", ["t_impact = 1e+308 s", "row 1"]),
    "times spanning 3e308": ("t_impact\n-1.7e308\n0\n1.7e308\n", ["t_impact = -1.7e+308 s", "row 1"]),
}


@pytest.mark.parametrize("name", BAD_TABLES)
def test_each_bad_table_is_one_line_naming_the_fault(tmp_path, name):
    text, words = BAD_TABLES[name]
    message = fault(read_data, table(tmp_path, text))
    for word in words:
        assert word in message, message


def test_files_that_cannot_be_read(tmp_path):
    assert "no such file" in fault(read_data, tmp_path / "missing.csv").lower()
    (tmp_path / "folder.csv").mkdir()
    assert "directory" in fault(read_data, tmp_path / "folder.csv").lower()
    latin = tmp_path / "latin.csv"
    latin.write_bytes("v_in,v_out # vitesses mesurées\n".encode("latin-1"))
    assert "not UTF-8" in fault(read_data, latin)
    for name in ("data.xlsx", "data"):
        message = fault(read_data, table(tmp_path, "v_in,v_out\n" + rows(V_IN, V_OUT), name))
        assert ("'.xlsx'" if "." in name else "no suffix") in message and ".csv" in message and ".wav" in message


def test_write_times_reads_back_to_the_same_floats(tmp_path):
    rng = np.random.default_rng(9)
    t = np.cumsum(rng.uniform(1e-3, 0.5, 40)) + rng.uniform(0.0, 1e-9)  # full 53-bit mantissas
    path = tmp_path / "times.csv"
    times = ImpactTimes(t, source="drop one\nwith a newline.wav")
    assert write_times(path, times) == path
    back = read_data(path)
    assert isinstance(back, ImpactTimes) and np.array_equal(back.t, t)
    assert "with a newline.wav" in path.read_text().splitlines()[1]  # the origin, in one comment line
    write_times(path, ImpactTimes(t[:3]))  # over the old file, whole
    assert np.array_equal(read_csv(path).t, t[:3])


def test_plain_numbers_in_every_notation_are_read_and_nothing_else(tmp_path):
    """Signs, a bare or leading decimal point, exponents in either case are read; the same table with one
    digit separator (float() read 2_5 as 25, a silent misread) is refused naming the cell."""
    text = "v_in,v_out\n+2.5,2.\n1.75E0,.15e1\n5e-1,0.25\n3.125,+2e+0\n"
    pairs = read_csv(table(tmp_path, text))
    assert pairs.v_in.tolist() == [2.5, 1.75, 0.5, 3.125] and pairs.v_out.tolist() == [2.0, 1.5, 0.25, 2.0]
    message = fault(read_csv, table(tmp_path, text.replace("+2.5", "2_5"), "separator.csv"))
    assert "line 2 (row 1), column v_in: '2_5' is not a number" in message, message


def test_a_drop_whose_intervals_imply_a_rebound_beyond_the_domain_is_refused():
    """Impacts 3000 s apart under g = 9.80665 m/s2: a rebound at 14710 m/s (g dt / 2), beyond the model's
    10 km/s; 2000 s apart (9807 m/s) is inside."""
    check_drop_speeds(ImpactTimes([0.0, 2000.0, 3000.0]), 9.80665)
    with pytest.raises(DataError, match=r"rows 1 and 2 are 3000 s apart: a rebound at 14710 m/s"):
        check_drop_speeds(ImpactTimes([0.0, 3000.0, 4000.0], source="far.csv"), 9.80665)
    with pytest.raises(DataError, match="rebound at inf m/s"):  # g dt overflows
        check_drop_speeds(ImpactTimes([0.0, 1e14, 2e14]), 1e300)
