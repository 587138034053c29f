"""Binary rig formats (MATLAB .mat v5 and v7.3, Parquet, Excel, ASAM MDF 4 and 3), each written by the
program that writes it in practice, and tables handed in by a caller's own loader: the same measured
efficiency as the CSV of the same synthetic record."""

from __future__ import annotations

import json
import math
import sys

import numpy as np
import pandas as pd
import pytest

import rigdata
from rigdata import files, synthetic
from rigdata.readers import read, read_frame, read_table
from rigdata.record import RigDataError

h5py = pytest.importorskip("h5py")
scipy_io = pytest.importorskip("scipy.io")
asammdf = pytest.importorskip("asammdf")
pytest.importorskip("pyarrow")
pytest.importorskip("openpyxl")


@pytest.fixture(scope="module")
def recording():
    """A synthetic record's columns (``Time``, ``Torque In`` ...), units and labelling metadata."""
    settings = synthetic.RigSettings(offsets=(0.0, 0.0), drifts=(0.0, 0.0))  # near its truth
    table, units, used = synthetic.measure(synthetic.true_signals(settings), settings, None)
    return table, units, synthetic.metadata(used), used["true_efficiency"]


@pytest.fixture(scope="module")
def csv_efficiency(recording, tmp_path_factory):
    """The measurement of the CSV of the record: the reference every format must reproduce."""
    table, units, meta, _ = recording
    path = files.write_csv(tmp_path_factory.mktemp("csv") / "run.csv", table, units, meta)
    m = rigdata.measure(path, 15.0, monte_carlo=0)
    assert abs(m.efficiency - recording[3]) < m.u  # 0.970998 +- 0.40 against 0.971364
    return m


def ident(name: str) -> str:
    """A MATLAB-valid variable name for a column (``Torque In`` -> ``Torque_In``)."""
    return name.replace(" ", "_")


def write_mat5(path, table, units, meta):
    """scipy.io.savemat: a struct ``rig`` of channel vectors, a ``units`` struct, text variables."""
    rig = {ident(k): v for k, v in table.items()}
    scipy_io.savemat(path, {"rig": rig, "units": {ident(k): u for k, u in units.items()}, **meta})


def write_mat73(path, table, units, meta):
    """h5py, as MATLAB's ``-v7.3`` (HDF5) stores it: datasets with a ``units`` attribute, text attributes."""
    with h5py.File(path, "w") as f:
        for key, value in meta.items():
            f.attrs[key] = value
        group = f.create_group("rig")
        for name, values in table.items():
            group.create_dataset(ident(name), data=values[:, None]).attrs["units"] = units[name]


def write_parquet(path, table, units, meta):
    """pandas.to_parquet with ``[unit]`` in the column names and the metadata in ``DataFrame.attrs``."""
    frame = pd.DataFrame({f"{k} [{units[k]}]": v for k, v in table.items()})
    frame.attrs.update(meta)
    frame.to_parquet(path)


def write_xlsx(path, table, units, meta):
    """pandas.to_excel: the data sheet with a units row under the header, metadata in a second sheet."""
    frame = pd.DataFrame(table)
    with pd.ExcelWriter(path, engine="openpyxl") as writer:
        pd.DataFrame([units]).to_excel(writer, sheet_name="data", index=False)
        frame.to_excel(writer, sheet_name="data", index=False, header=False, startrow=2)
        pd.Series(meta).to_excel(writer, sheet_name="metadata", header=False)


def write_mdf(path, table, units, meta, version="4.10"):
    """asammdf MDF(version) append + save: one group of channels with units, metadata in the header."""
    mdf = asammdf.MDF(version=version)
    t = table["Time"]
    mdf.append([asammdf.Signal(v, t, name=k, unit=units[k]) for k, v in table.items() if k != "Time"])
    mdf.header.comment = "\n".join(f"{k}: {v}" for k, v in meta.items())
    mdf.save(path, overwrite=True)
    mdf.close()


WRITERS = {"mat5.mat": write_mat5, "mat73.mat": write_mat73, "run.parquet": write_parquet,
           "run.xlsx": write_xlsx, "run.mf4": write_mdf,
           "run.mdf": lambda *a: write_mdf(*a, version="3.30")}
FORMAT = {"mat5.mat": ("mat", "scipy.io"), "mat73.mat": ("mat", "h5py"),
          "run.parquet": ("parquet", "pyarrow"), "run.xlsx": ("xlsx", "openpyxl"),
          "run.mf4": ("mdf", "asammdf"), "run.mdf": ("mdf", "asammdf")}


@pytest.mark.parametrize("name", list(WRITERS))
def test_binary_format_measures_like_csv(name, recording, csv_efficiency, tmp_path):
    """Each format, named only by content (extension .bin), gives the CSV's channels, units, synthetic
    label and measured efficiency."""
    table, units, meta, _ = recording
    path = tmp_path / name
    WRITERS[name](path, table, units, meta)
    anonymous = path.rename(tmp_path / "recording.bin")
    rec = read(anonymous)
    fmt, reader = FORMAT[name]
    assert rec.provenance["format"] == fmt and rec.provenance["reader"]["name"] == reader
    assert {s.unit for s in rec.sources.values()} == {units[c] for c in table if c != "Time"}
    assert json.loads(rec.provenance["synthetic"]["settings"]) == json.loads(meta["settings"])
    m = rigdata.measure(rec, 15.0, monte_carlo=0)
    assert abs(m.efficiency - csv_efficiency.efficiency) <= 1e-12 * csv_efficiency.efficiency
    assert m.u == pytest.approx(csv_efficiency.u, rel=1e-9)


def test_read_frame_from_own_loader(recording, csv_efficiency):
    """A DataFrame from the caller's loader (units by argument, sample rate in metadata, no time column)
    measures like the CSV."""
    table, units, meta, _ = recording
    frame = pd.DataFrame({k: v for k, v in table.items() if k != "Time"})
    rate = float((table["Time"].size - 1) / (table["Time"][-1] - table["Time"][0]))
    rec = read_frame(frame, units=units, metadata={**meta, "sample_rate": f"{rate!r} Hz"})
    assert rec.provenance["format"] == "frame" and rec.provenance["synthetic"]
    m = rigdata.measure(rec, 15.0, monte_carlo=0)
    assert m.efficiency == pytest.approx(csv_efficiency.efficiency, rel=1e-12)
    with pytest.raises(RigDataError, match=r"expected a pandas.DataFrame .* got list"):
        read_frame([1, 2, 3])


def test_mat_flattening_and_notes(tmp_path):
    """Top-level vectors are columns by name; a matrix and a vector of another length are noted, not
    read; scalars are metadata."""
    t = np.arange(10) * 0.01
    scipy_io.savemat(tmp_path / "v.mat", {"time": t, "torque_in": t * 2, "other": np.ones(3),
                                          "matrix": np.ones((10, 2)), "rate": 100.0})
    raw = read_table(tmp_path / "v.mat")
    assert list(raw.columns) == ["time", "torque_in"] and raw.time == "time"
    assert raw.metadata["rate"] == "100.0"
    assert any("other" in n for n in raw.notes) and any("matrix" in n for n in raw.notes)


def test_mat_without_vectors_names_the_way_out(tmp_path):
    scipy_io.savemat(tmp_path / "t.mat", {"note": "hello"})
    with pytest.raises(RigDataError, match=r"no 1-D numeric variables .*table2struct"):
        read_table(tmp_path / "t.mat")


@pytest.mark.parametrize(("module", "name", "writer"), [
    ("asammdf", "run.mf4", write_mdf), ("pyarrow", "run.parquet", write_parquet),
    ("openpyxl", "run.xlsx", write_xlsx), ("h5py", "mat73.mat", write_mat73)])
def test_missing_optional_dependency_is_one_line_with_install(module, name, writer, recording, tmp_path,
                                                              monkeypatch):
    table, units, meta, _ = recording
    writer(tmp_path / name, table, units, meta)
    monkeypatch.setitem(sys.modules, module, None)
    with pytest.raises(RigDataError) as info:
        read_table(tmp_path / name)
    message = str(info.value)
    assert "\n" not in message and module in message and 'pip install "cardan-exudyn[rig]"' in message


def test_content_contradicting_format_and_legacy_xls(recording, tmp_path):
    table, units, meta, _ = recording
    write_parquet(tmp_path / "run.parquet", table, units, meta)
    with pytest.raises(RigDataError, match=r"content is a Parquet file but the format says mdf; pass "
                                           r"format='parquet'"):
        read_table(tmp_path / "run.parquet", format="mdf")
    (tmp_path / "fake.mf4").write_bytes(b"not an MDF file at all")
    with pytest.raises(RigDataError, match=r"not an ASAM MDF file: the extension says mdf"):
        read_table(tmp_path / "fake.mf4")
    (tmp_path / "old.xls").write_bytes(b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1" + bytes(600))
    with pytest.raises(RigDataError, match=r"legacy Excel .xls .* save it as .xlsx"):
        read_table(tmp_path / "old.xls")


def test_mdf_channels_on_own_uniform_rasters(tmp_path):
    """Channels in two groups of the same rate but separate time arrays read through their timing."""
    t = np.arange(200) * 1e-3
    mdf = asammdf.MDF(version="4.10")
    mdf.append([asammdf.Signal(np.full(t.size, 1.5), t, name="Torque In", unit="N m")])
    mdf.append([asammdf.Signal(np.full(t.size - 1, 1.4), t[:-1] + 0.0, name="Torque Out", unit="N m")])
    mdf.save(tmp_path / "two.mf4", overwrite=True)
    raw = read_table(tmp_path / "two.mf4")
    assert raw.time is None and raw.sampling["Torque In"] == pytest.approx((0.0, 1e-3))
    assert raw.units == {"Torque In": "N m", "Torque Out": "N m"}
    assert math.isclose(raw.sampling["Torque Out"][1], 1e-3)


def test_cli_inspect_lists_what_the_file_holds(recording, tmp_path, capsys):
    """``cardan rig inspect`` on an MDF file: format, reader and every column with its unit."""
    from cardan_exudyn.cli import main

    table, units, meta, _ = recording
    write_mdf(tmp_path / "run.mf4", table, units, meta)
    assert main(["rig", "inspect", str(tmp_path / "run.mf4"), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["format"] == "mdf" and info["reader"].startswith("asammdf ")
    assert info["columns"]["Torque In"] == {"unit": "V", "samples": table["Time"].size}
    assert info["columns"]["time"]["unit"] == "s"
    assert main(["rig", "inspect", str(tmp_path / "run.mf4")]) == 0
    out = capsys.readouterr().out
    assert "5 columns in the file:" in out and f"'Torque Out' [V], {table['Time'].size} samples" in out
