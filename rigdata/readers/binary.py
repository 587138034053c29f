"""Binary rig formats told by their first bytes (MATLAB, HDF5, Parquet, Excel, MDF), and the optional
libraries that read them.
"""

from __future__ import annotations

import importlib
import io
import zipfile
from pathlib import Path
from types import ModuleType

from rigdata.record import RigDataError

__all__ = ["BINARY_FORMATS", "BINARY_NAMES", "EXTENSIONS", "INSTALL", "binary_format", "require"]

#: Formats read by an optional library, by the name a caller gives.
BINARY_FORMATS = ("mat", "parquet", "xlsx", "mdf")
#: What each format is, for messages.
BINARY_NAMES = {"mat": "a MATLAB .mat file", "parquet": "a Parquet file", "xlsx": "an Excel .xlsx workbook",
                "mdf": "an ASAM MDF file", "xls": "a legacy Excel .xls workbook (OLE)"}
#: Extension -> format.
EXTENSIONS = {".mat": "mat", ".h5": "mat", ".hdf5": "mat", ".parquet": "parquet", ".pq": "parquet",
              ".xlsx": "xlsx", ".xlsm": "xlsx", ".mf4": "mdf", ".mdf": "mdf", ".mf3": "mdf"}
#: The command that installs every optional rig reader.
INSTALL = 'pip install "cardan-exudyn[rig]"'

HDF5 = b"\x89HDF\r\n\x1a\n"
"""The HDF5 signature: at byte 0, or 512 behind a MATLAB v7.3 user block."""
OLE = b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1"


def _is_xlsx(data: bytes) -> bool:
    """Whether ``data`` is a zip archive holding an ``xl/`` folder."""
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as archive:
            return any(name.startswith("xl/") for name in archive.namelist())
    except (zipfile.BadZipFile, OSError, ValueError):
        return False


def binary_format(data: bytes) -> str | None:
    """Format of ``data`` by its first bytes: one of :data:`BINARY_FORMATS`, ``"xls"``, or None."""
    if data.startswith(b"MATLAB 5.0 MAT-file") or data.startswith(HDF5) or data[512:520] == HDF5:
        return "mat"
    if data.startswith(b"PAR1"):
        return "parquet"
    if data.startswith(b"MDF     "):
        return "mdf"
    if data.startswith(b"PK\x03\x04") and _is_xlsx(data):
        return "xlsx"
    return "xls" if data.startswith(OLE) else None


def require(module: str, what: str, path: Path) -> ModuleType:
    """Module ``module`` imported; RigDataError naming it and :data:`INSTALL` when it is missing."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise RigDataError(f"reading {what} needs the optional package {module}: {INSTALL}",
                           file=path) from None
