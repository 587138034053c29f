"""Vendor exports of one synthetic record (asammdf CSV, HBM catman, DEWESoft, German headers, absolute
timestamps), each written the way its program writes it: recognised without ``--map`` and measuring the
plain CSV's efficiency."""

from __future__ import annotations

import datetime as dt

import numpy as np
import pytest

import rigdata
from rigdata import files, synthetic
from rigdata.readers import read, read_table, recognise
from rigdata.record import RigDataError

RATE = 5000.0
#: Column of the synthetic record -> German name (catman, German headers).
GERMAN = {"Torque In": "Drehmoment_An", "Torque Out": "Drehmoment_Ab", "Speed In": "Drehzahl_An",
          "Speed Out": "Drehzahl_Ab"}
#: Column of the synthetic record -> DEWESoft name (hardware channel / channel name).
DEWESOFT = {"Torque In": "AI 1/Torque_In", "Torque Out": "AI 2/Torque_Out", "Speed In": "CNT 0/Speed_In",
            "Speed Out": "CNT 1/Speed_Out"}


@pytest.fixture(scope="module")
def recording():
    """A synthetic record at 5 kHz with speed channels in rpm: columns, units, metadata."""
    settings = synthetic.RigSettings(offsets=(0.0, 0.0), drifts=(0.0, 0.0), speed_channel="rpm", rate=RATE)
    table, units, used = synthetic.measure(synthetic.true_signals(settings), settings, None)
    return table, units, synthetic.metadata(used)


@pytest.fixture(scope="module")
def plain(recording, tmp_path_factory):
    """The measurement of the plain CSV of the record: the reference every export must reproduce."""
    path = files.write_csv(tmp_path_factory.mktemp("csv") / "run.csv", *recording)
    return rigdata.measure(path, 15.0, monte_carlo=0)


def numbers(values, decimal=".") -> list[str]:
    """Cells as a program writes them: shortest round-trip repr, ``decimal`` mark."""
    return [repr(float(v)).replace(".", decimal) for v in values]


def rows(columns: list[list[str]], sep: str) -> str:
    return "".join(sep.join(cells) + "\n" for cells in zip(*columns, strict=True))


def write_asammdf_csv(path, table, units, meta):
    """asammdf: the MDF4 of the record exported with ``MDF.export(fmt="csv", add_units=True)``."""
    asammdf = pytest.importorskip("asammdf")
    mdf = asammdf.MDF(version="4.10")
    mdf.append([asammdf.Signal(v, table["Time"], name=k, unit=units[k])
                for k, v in table.items() if k != "Time"])
    mdf.export(fmt="csv", filename=path, single_time_base=True, add_units=True)
    mdf.close()


def write_catman(path, table, units, meta, time_column=True):
    """HBM catman ASCII export: German header lines, tab, decimal comma, a units row, Windows-1252; the
    time channel ``Zeit  1 - Standardmessrate`` (or only the header's ``Messrate``)."""
    head = ["catman AP ASCII-Export", "Datei: C:\\Messungen\\Prüfstand_Lauf12.BIN",
            f"Messrate: {RATE:g} Hz", "Anzahl Kanäle: 5", ""]
    names = (["Zeit  1 - Standardmessrate"] if time_column else []) + [GERMAN[k] for k in GERMAN]
    unit_row = (["s"] if time_column else []) + ["V", "V", "1/min", "1/min"]
    cols = ([numbers(table["Time"], ",")] if time_column else []) + [numbers(table[k], ",") for k in GERMAN]
    text = "\n".join(head) + "\n" + "\t".join(names) + "\n" + "\t".join(unit_row) + "\n" + rows(cols, "\t")
    path.write_bytes(text.encode("cp1252"))


def write_dewesoft(path, table, units, meta):
    """DEWESoft text export: info lines, ``;``, ``hardware channel/name [unit]`` headers."""
    head = ["Dewesoft X data export", "Start time: 12.03.2025 14:02:11", f"Sample rate: {RATE:g} Hz", ""]
    names = ["Time [s]"] + [f"{DEWESOFT[k]} [{units[k]}]" for k in DEWESOFT]
    cols = [numbers(table["Time"])] + [numbers(table[k]) for k in DEWESOFT]
    path.write_text("\n".join(head) + "\n" + ";".join(names) + "\n" + rows(cols, ";"), encoding="utf-8")


def write_german(path, table, units, meta):
    """A German spreadsheet export: ``;``, decimal comma, ``Zeit [s]``, ``Drehmoment_An [V]`` ...;
    ``1/min`` for rpm."""
    german_units = {"s": "s", "V": "V", "rpm": "1/min"}
    names = ["Zeit [s]"] + [f"{GERMAN[k]} [{german_units[units[k]]}]" for k in GERMAN]
    cols = [numbers(table["Time"], ",")] + [numbers(table[k], ",") for k in GERMAN]
    path.write_text(";".join(names) + "\n" + rows(cols, ";"), encoding="utf-8")


def write_timestamps(path, table, units, meta):
    """A logger writing absolute timestamps (``2025-03-12 14:02:11.000000``) instead of seconds."""
    start = dt.datetime(2025, 3, 12, 14, 2, 11)
    stamps = [(start + dt.timedelta(microseconds=round(t * 1e6))).strftime("%Y-%m-%d %H:%M:%S.%f")
              for t in table["Time"]]
    names = ["Timestamp"] + [f"{k} [{units[k]}]" for k in GERMAN]
    path.write_text(",".join(names) + "\n" + rows([stamps] + [numbers(table[k]) for k in GERMAN], ","),
                    encoding="utf-8")


WRITERS = {"asammdf.csv": write_asammdf_csv, "catman.txt": write_catman,
           "catman_rate.txt": lambda *a: write_catman(*a, time_column=False),
           "dewesoft.csv": write_dewesoft, "german.csv": write_german, "stamps.csv": write_timestamps}
#: The column each export's channels must come from.
SOURCES = {"asammdf.csv": "Speed Out", "catman.txt": "Drehzahl_Ab", "catman_rate.txt": "Drehzahl_Ab",
           "dewesoft.csv": "CNT 1/Speed_Out [rpm]", "german.csv": "Drehzahl_Ab [1/min]",
           "stamps.csv": "Speed Out [rpm]"}


@pytest.mark.parametrize("name", list(WRITERS))
def test_vendor_export_recognised_without_map(name, recording, plain, tmp_path):
    """Each export: channels recognised (the output speed from its own column), the time axis of the
    record, the plain CSV's efficiency and uncertainty."""
    WRITERS[name](tmp_path / name, *recording)
    rec = read(tmp_path / name)
    assert rec.sources["speed_out"].column == SOURCES[name]
    np.testing.assert_allclose(rec.time, recording[0]["Time"], rtol=0, atol=1e-12)  # 1 ps: float parsing
    m = rigdata.measure(rec, 15.0, monte_carlo=0)
    assert abs(m.efficiency - plain.efficiency) <= 1e-12 * plain.efficiency
    assert m.u == pytest.approx(plain.u, rel=1e-9)


def test_catman_rate_header_gives_time(recording, tmp_path):
    write_catman(tmp_path / "c.txt", *recording, time_column=False)
    rec = read(tmp_path / "c.txt")
    assert rec.provenance["time"]["source"] == "header 'Messrate' = 5000 Hz"


def test_absolute_timestamps_noted(recording, tmp_path):
    write_timestamps(tmp_path / "s.csv", *recording)
    raw = read_table(tmp_path / "s.csv")
    assert raw.time == "Timestamp" and raw.units["Timestamp"] == "s" and not raw.text_cells
    assert any("absolute timestamps from 2025-03-12 14:02:11" in n for n in raw.notes)


@pytest.mark.parametrize("header, channel", [
    ("timestamps", "time"), ("Zeit  1 - Standardmessrate", "time"), ("Zeit [s]", "time"),
    ("Drehmoment_An", "torque_in"), ("Drehmoment_Ab", "torque_out"), ("Drehzahl_An", "speed_in"),
    ("Drehzahl Ab [1/min]", "speed_out"), ("Drehmoment Abtrieb", "torque_out"),
    ("CNT 1/Speed_Out", "speed_out"), ("CNT 0/Speed_In", "speed_in"), ("AI 2/Torque_In", "torque_in"),
    ("AI 1/Torque", None), ("Coppia ingresso", "torque_in"), ("Velocità uscita", "speed_out"),
    ("Couple entrée", "torque_in"), ("Vitesse sortie", "speed_out"), ("Tempo", "time"), ("Temps", "time"),
    ("Trq1", "torque_in"), ("n2", "speed_out"),
])
def test_recognise_vendor_and_language_names(header, channel):
    """Vendor time names, German/Italian/French words; a hardware channel number is never a side."""
    assert recognise(header) == channel


def test_missing_units_reported_at_once(recording, tmp_path):
    """Every channel without a unit in one message, with the options that give them."""
    table, units, meta = recording
    path = tmp_path / "bare.csv"
    names = list(GERMAN)
    path.write_text("time," + ",".join(names) + "\n"
                    + rows([numbers(table["Time"])] + [numbers(table[k]) for k in names], ","))
    with pytest.raises(RigDataError) as info:
        read(path)
    message = str(info.value)
    assert "\n" not in message
    for ch in ("torque_in", "torque_out", "speed_in", "speed_out"):
        assert f"--unit {ch}=UNIT" in message
    assert read(path, units={"torque_in": "V", "torque_out": "V", "speed_in": "rpm",
                             "speed_out": "rpm"}).time.size == table["Time"].size


def test_help_lists_time_among_map_channels(capsys):
    from cardan_exudyn.cli import main

    for command in ("measure", "validate", "inspect"):
        with pytest.raises(SystemExit):
            main(["rig", command, "--help"])
        help_text = " ".join(capsys.readouterr().out.split())
        assert "time, torque_in, torque_out" in help_text, command


def test_timestamp_forms():
    """ISO 8601 (blank or T) and German DD.MM.YYYY with a decimal comma; a mixed column is not time."""
    from rigdata.readers.timestamps import timestamp_seconds

    iso = timestamp_seconds(["2025-03-12 14:02:11.000000", "2025-03-12T14:02:11.5", "2025-03-12 14:02:13"])
    np.testing.assert_array_equal(iso[0], [0.0, 0.5, 2.0])
    german = timestamp_seconds(["12.03.2025 23:59:59,750", "13.03.2025 00:00:00,000"])
    np.testing.assert_array_equal(german[0], [0.0, 0.25])
    assert timestamp_seconds(["2025-03-12 14:02:11", "ok"]) is None
