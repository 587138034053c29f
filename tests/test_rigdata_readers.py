"""Rig file readers and writers: round trips, recognition, units, and one clear error per bad input."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from rigdata import conversion, files, units
from rigdata.readers import read, read_table, recognise
from rigdata.record import RigDataError

N, DT = 48, 1e-3
META = {"synthetic": "true", "generator": "tests/test_rigdata_readers.py",
        "settings": json.dumps({"rpm": 600, "angle_deg": 10.0}), "operator": "unit test"}


def rig_table(spaces: bool = True) -> tuple[dict, dict]:
    """Time, torques in volts and N m, speed in rpm, pulse counts: the raw signals of the rig."""
    t = np.arange(N) * DT
    sp = " " if spaces else "_"
    table = {"time": t,
             f"Torque{sp}In": 0.15 + 0.01 * np.sin(2 * math.pi * 25 * t),
             f"Torque{sp}Out": 1.45 + 0.1 * np.cos(2 * math.pi * 25 * t),
             f"Speed{sp}In": 600.0 + 3.0 * np.sin(2 * math.pi * 10 * t),
             f"Pulses{sp}Out": np.floor(600.0 / 60.0 * 60 * t + 7)}
    unit = dict(zip(table, ["s", "V", "N m" if spaces else "Nm", "rpm", "counts"], strict=True))
    return table, unit


def check_record(rec, table, spaces: bool = True) -> None:
    """The record holds the table's numbers converted to SI (2 ulp: one multiplication each)."""
    sp = " " if spaces else "_"
    assert_allclose(rec.time, table["time"], rtol=0, atol=1e-15)
    assert_allclose(rec.channels["torque_in"], table[f"Torque{sp}In"] / 0.1, rtol=1e-15)
    assert_array_equal(rec.channels["torque_out"], table[f"Torque{sp}Out"])
    assert_allclose(rec.channels["speed_in"], table[f"Speed{sp}In"] * 2 * math.pi / 60, rtol=1e-15)
    assert_allclose(rec.channels["angle_out"], table[f"Pulses{sp}Out"] * 2 * math.pi / 60, rtol=1e-15)
    assert rec.sources["angle_out"].quantum == pytest.approx(2 * math.pi / 60)
    assert rec.provenance["synthetic"] == {k: META[k] for k in ("synthetic", "generator", "settings")}
    assert json.loads(rec.provenance["synthetic"]["settings"]) == {"rpm": 600, "angle_deg": 10.0}
    assert len(rec.provenance["sha256"]) == 64


@pytest.mark.parametrize("kwargs", [
    {}, {"sep": ";", "decimal": ","}, {"sep": "\t"}, {"sep": "\t", "decimal": ",", "units_row": True},
    {"sep": ",", "units_row": True}, {"sep": " ", "units_row": True},
], ids=["comma-point", "semicolon-comma", "tab", "tab-comma-units-row", "comma-units-row", "blanks"])
def test_csv_round_trip(tmp_path, kwargs):
    """Delimited text reads back to the written values, units converted, metadata and label found."""
    spaces = kwargs.get("sep") != " "
    table, unit = rig_table(spaces)
    path = files.write_csv(tmp_path / "run.csv", table, unit, META, **kwargs)
    rec = read(path)
    check_record(rec, table, spaces)
    assert rec.provenance["format"] == "csv" and rec.provenance["reader"]["name"] == "pandas"
    assert rec.provenance["header"]["operator"] == "unit test"
    raw = read_table(path)
    assert_array_equal(raw.columns[raw.time], table["time"])


def test_csv_without_preamble(tmp_path):
    """Without a preamble the file starts with the header; no synthetic label then."""
    table, unit = rig_table()
    rec = read(files.write_csv(tmp_path / "run.csv", table, unit, META, preamble=False))
    assert "synthetic" not in rec.provenance and rec.provenance["header"] == {}


@pytest.mark.parametrize("decimal, segments, x_columns", [
    (",", 1, "One"), (",", 3, "One"), (".", 1, "No"), (",", 3, "No"),
], ids=["comma-1", "comma-3", "point-no-x", "comma-3-no-x"])
def test_lvm_round_trip(tmp_path, decimal, segments, x_columns):
    """LVM with decimal comma, several segments joined, X_Columns No (time from X0 and Delta_X)."""
    table, unit = rig_table()
    path = files.write_lvm(tmp_path / "run.lvm", table, unit, META, decimal=decimal, segments=segments,
                           x_columns=x_columns)
    rec = read(path)
    check_record(rec, table)
    assert rec.provenance["reader"]["name"] == "lvm_read"
    assert rec.provenance["header"]["Decimal_Separator"] == decimal
    assert (f"{segments} LVM segments joined" in rec.provenance["notes"]) == (segments > 1)
    assert list(tmp_path.iterdir()) == [path]  # lvm_read's pickle cache is never written


def test_lvm_layout(tmp_path):
    """The writer's LVM has the LabVIEW layout: header, per-segment headers, X_Value line."""
    table, unit = rig_table()
    text = files.write_lvm(tmp_path / "run.lvm", table, unit, META, segments=2).read_bytes().decode()
    lines = text.split("\r\n")
    assert lines[0] == "LabVIEW Measurement\t" and "Decimal_Separator\t," in lines
    assert text.count("***End_of_Header***") == 3
    assert lines.count("X_Value\tTorque In\tTorque Out\tSpeed In\tPulses Out\tComment") == 2
    for tag in ("Channels", "Samples", "Date", "Time", "X_Dimension", "X0", "Delta_X", "Y_Unit_Label"):
        assert sum(line.startswith(tag + "\t") for line in lines) >= 2


def test_tdms_round_trip(tmp_path):
    """TDMS: channels in group Rig with unit_string and waveform timing, metadata as properties."""
    table, unit = rig_table()
    path = files.write_tdms(tmp_path / "run.tdms", table, unit, META)
    rec = read(path)
    check_record(rec, table)
    assert rec.provenance["reader"]["name"] == "npTDMS"
    raw = read_table(path)
    assert raw.sampling["Torque In"] == pytest.approx((0.0, DT))
    assert raw.units == unit


def test_tdms_time_from_waveform(tmp_path):
    """Without a time channel the time comes from wf_start_offset and wf_increment."""
    table, unit = rig_table()
    table["time"] = table["time"] + 2.0
    path = files.write_tdms(tmp_path / "run.tdms", table, unit, {})
    rec = read(path, mapping={"time": None})
    assert_allclose(rec.time, table["time"], atol=1e-12)
    assert "sampling of column" in rec.provenance["time"]["source"]


def test_writers_are_atomic(tmp_path, monkeypatch):
    """A writer that fails leaves the old file untouched and no temporary file behind."""
    table, unit = rig_table()
    target = tmp_path / "run.csv"
    target.write_text("old")

    def broken(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(files, "_numbers", broken)
    with pytest.raises(OSError, match="disk full"):
        files.write_csv(target, table, unit, META)
    assert target.read_text() == "old" and list(tmp_path.iterdir()) == [target]


def test_units_in_headers_and_preamble(tmp_path):
    """Units in every header form, decimal comma, preamble lines of all kinds kept as metadata."""
    path = tmp_path / "bench.txt"
    path.write_text("Rig run 12, warm shafts\n"
                    "# Operator: A. Smith\n"
                    "Date = 2024-03-01 10:00:00\n"
                    "Torque range;100 N m\n"
                    "\n"
                    "t (ms);Torque In [N·m];torque_out (mNm);speed_out / rpm;Speed In {1/min}\n"
                    "0,0;1,5;1480;600;600\n1,0;1,5;1490;601;600\n2,0;1,6;1500;600;602\n"
                    "3,0;1,5;1490;599;600\n", encoding="utf-8")
    rec = read(path)
    assert_allclose(rec.time, [0.0, 1e-3, 2e-3, 3e-3], atol=1e-15)
    assert_allclose(rec.channels["torque_out"], [1.48, 1.49, 1.5, 1.49], rtol=1e-15)
    assert_allclose(rec.channels["speed_in"][2], 602 * 2 * math.pi / 60, rtol=1e-15)
    assert rec.provenance["header"] == {"Operator": "A. Smith", "Date": "2024-03-01 10:00:00",
                                        "Torque range": "100 N m"}
    assert rec.sources["torque_in"].unit == "N·m"


def test_time_from_header_sample_rate(tmp_path):
    """Without a time column the header's sample rate gives the time axis."""
    path = tmp_path / "rate.csv"
    path.write_text("sample_rate: 2 kHz\nT1 [Nm],T2 [Nm],n1 [rpm],n2 [rpm]\n"
                    + "1,1,600,600\n" * 5)
    rec = read(path)
    assert_allclose(rec.time, np.arange(5) * 5e-4)
    assert "sample_rate" in rec.provenance["time"]["source"]


def test_time_without_unit_is_assumed_seconds(tmp_path):
    """A time column that states no unit is taken as seconds, and the record says so."""
    path = tmp_path / "t.csv"
    path.write_text("time,torque_in [Nm],torque_out [Nm],speed_in [rpm],speed_out [rpm]\n"
                    + "".join(f"{k * 0.01},1,1,600,600\n" for k in range(5)))
    rec = read(path)
    assert rec.dt == pytest.approx(0.01)
    assert rec.provenance["assumptions"] == ["time column 'time' states no unit: assumed s"]
    assert read(path, units={"time": "ms"}).dt == pytest.approx(1e-5)


@pytest.mark.parametrize("header, channel", [
    ("torque_in", "torque_in"), ("Torque In [N m]", "torque_in"), ("T_in", "torque_in"),
    ("Trq1", "torque_in"), ("Torque 2", "torque_out"), ("TorqueOut", "torque_out"),
    ("Drive torque", "torque_in"), ("Brake torque (Nm)", "torque_out"), ("Load [N m]", "torque_out"),
    ("Motor speed", "speed_in"), ("omega_out", "speed_out"), ("n1 / rpm", "speed_in"),
    ("rpm_out", "speed_out"), ("Pulses In", "angle_in"), ("Encoder 2 [counts]", "angle_out"),
    ("angle_out [deg]", "angle_out"), ("Encoder speed in [rpm]", "speed_in"),
    ("Time [s]", "time"), ("t", "time"), ("X_Value", "time"), ("time_ms", "time"),
    ("Torque", None), ("Temperature 1", None), ("Torque in out", None), ("Comment", None),
])
def test_recognise(header, channel):
    """Header names map to record channels when exactly one kind and one side are named."""
    assert recognise(header) == channel


def test_mapping_and_units_argument(tmp_path):
    """An explicit mapping picks odd column names; `units` supplies units the file lacks."""
    path = tmp_path / "odd.csv"
    path.write_text("time [s],A,B,C,D,E\n" + "".join(f"{k * 1e-3},0.1,1.2,600,{k},9\n" for k in range(6)))
    rec = read(path, mapping={"torque_in": "a", "torque_out": "B", "speed_in": "C", "angle_out": "D"},
               units={"torque_in": "V", "B": "N m", "speed_in": "rpm", "angle_out": "pulses"},
               pulses_per_rev=120)
    assert_allclose(rec.channels["torque_in"], 1.0)
    assert rec.sources["angle_out"].quantum == pytest.approx(2 * math.pi / 120)
    assert rec.sources["torque_in"].conversion == "V / 0.1 V/(N m)"
    assert_allclose(rec.channels["angle_out"], np.arange(6) * 2 * math.pi / 120)


def test_mapping_resolves_ambiguity_and_drops(tmp_path):
    """Mapping one channel settles a clash; None leaves a recognised channel out."""
    path = tmp_path / "two.csv"
    path.write_text("time [s],Torque In [N m],T_in [N m],Torque Out [N m],Speed In [rpm],Speed Out [rpm],"
                    "Angle Out [deg]\n" + "".join(f"{k * 1e-3},1,2,1,600,600,{k}\n" for k in range(5)))
    rec = read(path, mapping={"torque_in": "T_in", "angle_out": None})
    assert_allclose(rec.channels["torque_in"], 2.0)
    assert "angle_out" not in rec.channels


def test_counter_wrap_in_file_is_recorded(tmp_path):
    """A pulse counter that wraps in the file is unwrapped, and the provenance says so."""
    counts = (np.arange(65530, 65540) % 65536).astype(int)
    path = tmp_path / "wrap.csv"
    path.write_text("time [s],T1 [Nm],T2 [Nm],Counts In [counts],Speed Out [rpm]\n"
                    + "".join(f"{k * 1e-3},1,1,{c},600\n" for k, c in enumerate(counts)))
    rec = read(path)
    assert_allclose(rec.channels["angle_in"], np.arange(65530, 65540) * 2 * math.pi / 60, rtol=1e-15)
    note = "angle_in ('Counts In [counts]'): counter wrapped at 2^16"
    assert any(note in n for n in rec.provenance["notes"])


def test_unused_text_column_and_quotes(tmp_path):
    """A text column nobody maps is harmless; quoted headers and numbers are read."""
    path = tmp_path / "quoted.csv"
    path.write_text('"Time [s]","Torque In [N m]","Torque Out [N m]","n_in [rpm]","n_out [rpm]","Note"\n'
                    + "".join(f'"{k * 1e-3}","1.5","1.4","600","600","ok {k}"\n' for k in range(5)))
    rec = read(path)
    assert_allclose(rec.channels["torque_out"], 1.4)
    assert rec.time.size == 5
    assert read_table(path).text_cells["Note"].count == 5


def test_unit_table_is_consistent():
    """Every spelling leads back to its own entry (no two entries share a spelling); Nm is torque."""
    for symbol, (quantity, factor, others) in units._TABLE.items():
        for spelling in (symbol, *others):
            found = units.lookup(spelling.upper())
            assert (found.symbol, found.quantity, found.factor) == (symbol, quantity, factor), spelling
    assert units.lookup(" n m ").quantity == units.lookup("Nm").quantity == "torque"


@pytest.mark.parametrize("spelling, kind, si, expected", [
    ("rpm", "speed", 60.0, 2 * math.pi), ("U/min", "speed", 30.0, math.pi),
    ("rev/s", "speed", 1.0, 2 * math.pi), ("deg/s", "speed", 180.0, math.pi),
    ("pulses/s", "speed", 60.0, 2 * math.pi),
    ("V", "torque", 0.25, 2.5), ("mV", "torque", 250.0, 2.5), ("N cm", "torque", 150.0, 1.5),
    ("mN m", "torque", 1500.0, 1.5), ("kNm", "torque", 0.002, 2.0), ("counts", "angle", 30.0, math.pi),
    ("°", "angle", 90.0, math.pi / 2), ("ms", "time", 5.0, 0.005), ("µs", "time", 5.0, 5e-6),
])
def test_conversions(spelling, kind, si, expected):
    """Units to SI at the paper's 0.1 V/(N m) and 60 pulses per revolution."""
    unit = units.parse_unit(spelling, kind=kind)
    assert conversion.to_si(np.array([si]), unit).values[0] == pytest.approx(expected, rel=1e-14)


def test_counter_wrap_and_reset_are_undone():
    """A 16-bit counter wrap is undone exactly; a reset is bridged by the local step."""
    counts = np.arange(65530, 65540, dtype=float)
    counts[counts >= 65536] -= 65536
    out, notes = conversion.unwrap_counter(counts)
    assert_array_equal(out, np.arange(65530, 65540))
    assert len(notes) == 1 and "wrapped at 2^16" in notes[0]
    reset = np.array([500, 502, 504, 506, 0, 2, 4, 6], dtype=float)
    out, notes = conversion.unwrap_counter(reset)
    assert_array_equal(out, [500, 502, 504, 506, 508, 510, 512, 514])
    assert len(notes) == 1 and "reset" in notes[0]


@pytest.mark.parametrize("header, name, unit", [
    ("Torque In [N m]", "Torque In", "N m"), ("torque_in (Nm)", "torque_in", "Nm"),
    ("speed_out / rpm", "speed_out", "rpm"), ("Speed In {rpm}", "Speed In", "rpm"),
    ("Speed In / 1/min", "Speed In", "1/min"), ("Torque In", "Torque In", None), ("x []", "x", None),
])
def test_split_header(header, name, unit):
    """Unit annotations in brackets, parentheses, braces or after a slash."""
    assert units.split_header(header) == (name, unit)


GOOD = ("# rig: test bench\n"
        "time [s],Torque In [N m],Torque Out [N m],Speed In [rpm],Speed Out [rpm]\n"
        "0.000,1.00,0.98,600,600\n"
        "0.001,1.01,0.99,600,601\n"
        "0.002,1.02,1.00,601,600\n"
        "0.003,1.03,1.01,600,600\n"
        "0.004,1.04,1.02,600,599\n")


def edit(old: str, new: str) -> str:
    assert old in GOOD
    return GOOD.replace(old, new)


LVM = ("LabVIEW Measurement\t\nWriter_Version\t2\nReader_Version\t2\nSeparator\tTab\nDecimal_Separator\t,\n"
       "Multi_Headings\tNo\nX_Columns\tOne\nTime_Pref\tRelative\nDate\t2024/03/01\nTime\t10:00:00\n"
       "***End_of_Header***\t\n")
SEGMENT = ("\t\nChannels\t4\t\t\t\t\nSamples\t{n}\t{n}\t{n}\t{n}\t\nY_Unit_Label\tN m\tN m\trpm\trpm\t\n"
           "X_Dimension\tTime\tTime\tTime\tTime\t\nX0\t{x0}\t{x0}\t{x0}\t{x0}\t\n"
           "Delta_X\t{dx}\t{dx}\t{dx}\t{dx}\t\n***End_of_Header***\t\t\t\t\t\n"
           "X_Value\tTorque In\tTorque Out\tSpeed In\tSpeed Out\tComment\n")


def lvm_segment(x0: float, dx: float, rows: list[str] | None = None, samples: int | None = None) -> str:
    """A segment of five rows from ``x0`` every ``dx`` (or the rows given), decimal comma."""
    rows = lvm_rows(x0, dx, 5) if rows is None else rows
    text = SEGMENT.format(n=samples or len(rows), x0=str(x0).replace(".", ","), dx=str(dx).replace(".", ","))
    return text + "".join(r + "\n" for r in rows)


def lvm_rows(x0: float, dx: float, n: int) -> list[str]:
    return [f"{x0 + k * dx:.4f}\t1,0\t0,9\t600\t600".replace(".", ",") for k in range(n)]


def tdms_bytes(tmp_path, increments=(DT, DT)) -> bytes:
    from nptdms import ChannelObject, GroupObject, RootObject, TdmsWriter

    path = tmp_path / "src.tdms"
    chans = [ChannelObject("Rig", name, np.ones(N), properties={"unit_string": u, "wf_increment": inc})
             for (name, u), inc in zip([("Torque In", "N m"), ("Torque Out", "N m"), ("Speed In", "rpm"),
                                        ("Speed Out", "rpm")], increments * 2, strict=True)]
    with TdmsWriter(str(path)) as w:
        w.write_segment([RootObject(), GroupObject("Rig"), *chans])
    data = path.read_bytes()
    path.unlink()
    return data


BAD = [
    # (id, file name, content, kwargs, pattern after the file name)
    ("missing-file", "nowhere.csv", None, {}, "file not found"),
    ("empty", "empty.csv", "", {}, "empty file"),
    ("blank", "blank.csv", "\n  \n", {}, "empty file"),
    ("binary", "garbage.csv", bytes(range(256)) * 4, {}, r"not a text file \(binary content"),
    ("truncated", "cut.csv", GOOD + "0.005,1.05,1.0", {},
     r"truncated: the last line \(8\) has 3 of 5 fields"),
    ("ragged-row", "ragged.csv", edit("0.002,1.02,1.00,601,600", "0.002,1.02,601,600"), {},
     "line 5 has 4 fields, the header has 5"),
    ("non-numeric", "text.csv", edit("0.003,1.03,1.01", "0.003,1.03,abc"), {},
     r"channel 'torque_out': non-numeric cell 'abc' at row 3 \(line 6\) in column 'Torque Out \[N m\]'"),
    ("nan-run", "nan.csv", edit("0.001,1.01", "0.001,NaN").replace("0.002,1.02", "0.002,nan"), {},
     r"channel 'torque_in': 2 non-finite values \(NaN or non-numeric\), the first at t = 0.001 s"),
    ("time-not-increasing", "back.csv", edit("0.003,", "0.001,"), {},
     "channel 'time': time does not increase at sample 3"),
    ("mixed-rates", "rates.csv", edit("0.003,", "0.0035,").replace("0.004,", "0.0045,"), {},
     "channel 'time': mixed sampling rates"),
    ("missing-channel", "miss.csv", GOOD.replace("Torque Out [N m]", "Torque [N m]"), {},
     r"channel 'torque_out': missing: no column recognised as torque_out; columns found: .*"
     r"--map torque_out="),
    ("ambiguous", "amb.csv", GOOD.replace("Speed Out [rpm]", "n_in [rpm]"), {},
     r"channel 'speed_in': ambiguous: columns \['Speed In \[rpm\]', 'n_in \[rpm\]'\] both match"),
    ("unknown-unit", "unit.csv", GOOD.replace("Speed In [rpm]", "Speed In [furlong/fortnight]"), {},
     r"channel 'speed_in': unknown unit 'furlong/fortnight' in column .*; accepted units are speed: rad/s"),
    ("wrong-quantity", "kind.csv", GOOD.replace("Torque In [N m]", "Torque In [rpm]"), {},
     r"channel 'torque_in': unit 'rpm' in column 'Torque In \[rpm\]' is a speed unit, a torque "
     r"channel needs"),
    ("hz-speed", "hz.csv", GOOD.replace("Speed In [rpm]", "Speed In [Hz]"), {},
     r"channel 'speed_in': unit 'Hz' in column .*is ambiguous for a speed"),
    ("no-unit", "nounit.csv", GOOD.replace("Speed Out [rpm]", "Speed Out"), {},
     r"channel 'speed_out': no unit: column 'Speed Out' states none; give it with --unit speed_out=UNIT "
     r"\(read\(\.\.\., units="),
    ("no-time", "notime.csv", GOOD.replace("time [s]", "stamp"), {},
     r"channel 'time': no time: no time column .*--map time=COLUMN"),
    ("no-header", "nohead.csv", GOOD.split("\n", 2)[2], {},
     r"no header line with column names above the data"),
    ("bad-mapping", "map.csv", GOOD, {"mapping": {"speed_out": "Speed 2"}},
     r"channel 'speed_out': mapped to column 'Speed 2', which the file does not have; columns found"),
    ("lvm-is-csv", "data.lvm", GOOD, {}, r"not a LabVIEW Measurement file: the first line is not"),
    ("csv-is-lvm", "data.csv", LVM + lvm_segment(0.0, 0.001), {},
     r"content is a LabVIEW Measurement \(LVM\) file but the extension '.csv' says csv; .*format='lvm'"),
    ("tdms-is-text", "data.tdms", GOOD, {}, r"not a TDMS file: it does not start with 'TDSm'"),
    ("lvm-mixed-rates", "rates.lvm", LVM + lvm_segment(0.0, 0.001) + lvm_segment(0.005, 0.002), {},
     r"channel 'Torque In': mixed sampling rates: Delta_X 0.002 s in segment 2"),
    ("lvm-gap", "gap.lvm", LVM + lvm_segment(0.0, 0.001) + lvm_segment(0.5, 0.001), {},
     r"segment 2 starts at t = 0.5 s, segment 1 ends at 0.004 s .*not contiguous"),
    ("lvm-non-numeric", "text.lvm",
     LVM + lvm_segment(0.0, 0.001, [r.replace("\t600\t600", "\t600\tx12") if i == 2 else r
                                    for i, r in enumerate(lvm_rows(0.0, 0.001, 5))]), {},
     r"channel 'speed_out': non-numeric cell 'x12' at row 2 \(line 23\) in column 'Speed Out'"),
    ("lvm-quoted-cell", "quote.lvm",
     LVM + lvm_segment(0.0, 0.001, [r + '"' if i == 2 else r for i, r in enumerate(lvm_rows(0.0, 0.001, 5))]),
     {}, r"channel 'speed_out': non-numeric cell '600\"' at row 2 \(line 23\) in column 'Speed Out'"),
    ("lvm-no-channels", "blank.lvm", LVM + lvm_segment(0.0, 0.001).replace(  # a blank line in the header
        "\t\nChannels", "X_Dimension\tTime\tTime\tTime\tTime\t\nChannels", 1).replace(
        "Y_Unit_Label\tN m\tN m\trpm\trpm\t\nX_Dimension\tTime\tTime\tTime\tTime\t\n",
        "Y_Unit_Label\tN m\tN m\trpm\trpm\t\n\t\n"), {},
     "segment 1 has no channels besides X_Value: its header is incomplete"),
    ("lvm-truncated", "cut.lvm", LVM + lvm_segment(0.0, 0.001)[:-9], {},
     r"truncated: the last line \(25\) has 3 of 5 fields and no line end"),
    ("lvm-samples", "short.lvm", LVM + lvm_segment(0.0, 0.001, samples=1000), {},
     "truncated: segment 1 has 5 rows, its header says Samples 1000"),
    ("tdms-truncated", "cut.tdms", lambda tmp: tdms_bytes(tmp)[:-100], {},
     "truncated or damaged TDMS file: npTDMS reports 'Last segment"),
    ("tdms-mixed-rates", "rates.tdms", lambda tmp: tdms_bytes(tmp, (DT, 2 * DT)), {},
     r"channel 'torque_out': mixed sampling rates: torque_out \('Torque Out'\) is sampled every 0.002 s"),
    # cut short anywhere, damaged headers: one line naming what is wrong, no library internals
    ("lvm-cut-in-segment-header", "cut.lvm", (LVM + lvm_segment(0.0, 0.001)).split("Y_Unit_Label")[0], {},
     r"truncated: header without data section \(the file ends at line 14, inside the header of segment 1\)$"),
    ("lvm-cut-in-file-header", "cut.lvm", LVM[:LVM.index("Separator") + len("Separator")], {},
     r"truncated: header without data section \(the file ends at line 4, inside the file header\)$"),
    ("lvm-cut-after-file-header", "cut.lvm", LVM, {},
     r"truncated: header without data section \(the file ends at line 11: nothing after the file header\)$"),
    ("lvm-cut-in-last-value", "cut.lvm", LVM + lvm_segment(0.0, 0.001)[:-3], {},
     r"truncated: the last line \(25\) has no line end \(its last value may be cut short\)"),
    ("lvm-cut-in-first-line", "cut.lvm", "LabVIEW Meas", {},
     r"truncated: 12 bytes, cut inside the 'LabVIEW Measurement' that starts an LVM file$"),
    ("lvm-blank-line-in-file-header", "blank.lvm",
     LVM.replace("Multi_Headings\tNo\n", "\n") + lvm_segment(0.0, 0.001), {},
     r"line 6: a blank line inside the file header \(before its \*\*\*End_of_Header\*\*\*\)$"),
    ("lvm-separator-without-value", "sep.lvm",
     LVM.replace("Separator\tTab", "Separator") + lvm_segment(0.0, 0.001), {},
     r"line 4: the Separator tag has no value$"),
    ("lvm-channels-not-a-number", "chan.lvm",
     LVM + lvm_segment(0.0, 0.001).replace("Channels\t4", "Channels\tfour"), {},
     r"line 13: the Channels value 'four' of segment 1 is not a whole number$"),
    ("lvm-segment-without-column-names", "empty.lvm", LVM + "\t\n" + lvm_segment(0.0, 0.001), {},
     r"line 13: segment 1 ends before its X_Value column-names line"),
    ("lvm-zero-delta-x", "zero.lvm", LVM + lvm_segment(0.0, 0.0), {},
     r"segment 1 has Delta_X 0 s: a sampling interval must be positive$"),
    ("tdms-cut-in-tag", "cut.tdms", b"TDS", {},
     r"truncated: 3 bytes, cut inside the 'TDSm' that starts a TDMS file$"),
    ("tdms-cut-in-lead-in", "cut.tdms", lambda tmp: tdms_bytes(tmp)[:20], {},
     r"truncated: 20 bytes, less than the 28-byte lead-in of a TDMS segment$"),
    ("tdms-damaged-object-header", "bad.tdms", lambda tmp: tdms_damaged(tdms_bytes(tmp), 43, 15), {},
     r"truncated or damaged TDMS file: npTDMS cannot read its structure \(NotImplementedError: "),
    ("csv-unbalanced-quote", "quote.csv", edit("0.002,1.02,1.00,601,600", '0.002,1.02,1.00,",600'), {},
     r"line 5 has an unbalanced double quote \('\"'\): a data row cannot be read from it$"),
    ("csv-short-units-row", "units.csv", GOOD.replace("Speed Out [rpm]\n", "Speed Out\n[rpm]\n"), {},
     r"no header line with column names above the data: line 3 \('\[rpm\]'\) has 1 fields, the data rows 5"),
]


def tdms_damaged(data: bytes, offset: int, value: int) -> bytes:
    """``data`` with the byte at ``offset`` set to ``value`` (one flipped byte)."""
    return data[:offset] + bytes([value]) + data[offset + 1:]


@pytest.mark.parametrize("name, content, kwargs, pattern", [case[1:] for case in BAD],
                         ids=[case[0] for case in BAD])
def test_bad_input(tmp_path, name, content, kwargs, pattern):
    """Each bad file gives one RigDataError whose message names the file and the problem."""
    path = tmp_path / name
    if callable(content):
        content = content(tmp_path)
    if isinstance(content, str):
        path.write_bytes(content.encode())
    elif content is not None:
        path.write_bytes(content)
    with pytest.raises(RigDataError, match=re.escape(str(path)) + ": " + pattern) as caught:
        read(path, **kwargs)
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize("text, decimal, expected", [
    ("2.5", ".", 2.5), (" 2.5 ", ".", 2.5), ("1,5", ",", 1.5), ("-3e-2", ".", -0.03),
    ("1_0", ".", None), ("1,5", ".", None), ("abc", ".", None), ("0x10", ".", None),
], ids=["point", "spaces", "comma-decimal", "exponent", "underscore", "comma-in-point-file", "text",
        "hex"])
def test_cell_value_accepts_only_what_a_rig_file_writes(text, decimal, expected):
    """A cell is a number only in the forms rig files write (``float`` alone would take
    ``1_0``); anything else is NaN, reported as a text cell, never a crash."""
    from rigdata.readers.table import cell_value

    value = cell_value(text, decimal)
    assert math.isnan(value) if expected is None else value == pytest.approx(expected)
