"""A rig file's bytes, its format (extension or the caller's word, checked against the first bytes) and
text.
"""

from __future__ import annotations

from pathlib import Path

from rigdata.readers.binary import BINARY_FORMATS, BINARY_NAMES, EXTENSIONS, binary_format
from rigdata.record import RigDataError

__all__ = ["FORMAT_ALIASES", "file_bytes", "content_format", "choose_format", "decode"]

#: Format names a caller may give -> the reader they select.
FORMAT_ALIASES = {"auto": "auto", "csv": "csv", "text": "csv", "txt": "csv", "tsv": "csv", "dat": "csv",
                  "lvm": "lvm", "tdms": "tdms", "mat": "mat", "hdf5": "mat", "parquet": "parquet",
                  "xlsx": "xlsx", "excel": "xlsx", "mdf": "mdf", "mf4": "mdf"}


def file_bytes(path: Path) -> bytes:
    """The file's bytes; a missing, unreadable or empty file is an error."""
    if not path.exists():
        raise RigDataError("file not found", file=path)
    if path.is_dir():
        raise RigDataError("is a directory, not a file", file=path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise RigDataError(f"cannot read the file: {exc.strerror or exc}", file=path) from exc
    if not data.strip():
        raise RigDataError("empty file" if not data else "empty file (only blank space)", file=path)
    return data


MAGIC = {"tdms": b"TDSm", "lvm": b"LabVIEW Measurement"}
"""How a file of each binary-tagged format starts."""


def _cut_in_magic(fmt: str, head: bytes) -> bool:
    """Whether ``head``, a whole file, is a proper prefix of the format's MAGIC (cut inside it)."""
    start = head.lstrip(b"\xef\xbb\xbf").strip() if fmt == "lvm" else head
    return bool(start) and len(start) < len(MAGIC[fmt]) and MAGIC[fmt].startswith(start)


def content_format(head: bytes) -> str | None:
    """Format the first bytes show: "tdms", "lvm", or None (text of some other kind)."""
    if head.startswith(MAGIC["tdms"]):
        return "tdms"
    text = head.lstrip(b"\xef\xbb\xbf")
    if text.startswith(b"\xff\xfe") or text.startswith(b"\xfe\xff"):
        text = text.decode("utf-16", errors="ignore").encode()
    return "lvm" if text.lstrip().startswith(MAGIC["lvm"]) else None


def _binary_choice(path: Path, wanted: str, data: bytes) -> str | None:
    """The binary format to read, None for the text and TDMS readers; RigDataError when content and
    ``wanted`` (a format or ``"auto"``) disagree.
    """
    found = binary_format(data)
    if found == "xls":
        raise RigDataError("content is a legacy Excel .xls workbook (OLE), which is not read; save it as "
                           ".xlsx", file=path)
    if wanted == "auto":
        if found is not None:
            return found
        wanted = EXTENSIONS.get(path.suffix.lower(), "auto")
        said = "extension"
    else:
        said = "format"
    if found is not None and found != wanted:
        raise RigDataError(f"content is {BINARY_NAMES[found]} but the format says {wanted}; pass "
                           f"format={found!r}", file=path)
    if wanted not in BINARY_FORMATS or found == wanted or wanted == "mat":  # MAT v4 has no signature
        return found or (wanted if wanted == "mat" else None)
    raise RigDataError(f"not {BINARY_NAMES[wanted]}: the {said} says {wanted} but the content does not "
                       f"start like one ({len(data)} bytes, first {data[:16]!r})", file=path)


def choose_format(path: Path, format: str, data: bytes) -> str:
    """Format to read (``"csv"``, ``"lvm"``, ``"tdms"`` or a binary one) from ``format`` (``"auto"``:
    the content for a binary format, else the extension), checked against ``data``; RigDataError on
    contradiction or a file cut inside its tag.
    """
    suffix = path.suffix.lower()
    if suffix == ".tdms_index":
        raise RigDataError("is a TDMS index file; read the .tdms file next to it", file=path)
    wanted = FORMAT_ALIASES[format]
    binary = _binary_choice(path, wanted, data)
    if binary is not None:
        return binary
    head = data[:64]
    said = "format" if wanted != "auto" else f"extension {path.suffix or '(none)'!r}"
    if wanted == "auto":
        wanted = {".lvm": "lvm", ".tdms": "tdms"}.get(suffix, "csv")
    found = content_format(head)
    if found is not None and found != wanted:
        name = {"tdms": "a TDMS file", "lvm": "a LabVIEW Measurement (LVM) file"}[found]
        raise RigDataError(f"content is {name} but the {said} says {wanted}; rename the file or pass "
                           f"format={found!r}", file=path)
    if wanted in ("tdms", "lvm") and found != wanted and _cut_in_magic(wanted, head):
        raise RigDataError(f"truncated: {len(head)} bytes, cut inside the {MAGIC[wanted].decode()!r} that "
                           f"starts a{'' if wanted == 'tdms' else 'n'} {wanted.upper()} file", file=path)
    if wanted == "tdms" and found != "tdms":
        raise RigDataError(f"not a TDMS file: it does not start with 'TDSm' (the {said} says TDMS; "
                           f"{len(head)} bytes read: {head[:16]!r})", file=path)
    if wanted == "lvm" and found != "lvm":
        raise RigDataError(f"not a LabVIEW Measurement file: the first line is not 'LabVIEW Measurement' "
                           f"(the {said} says LVM; for delimited text pass format='csv')", file=path)
    return wanted


def decode(data: bytes, path: Path) -> str:
    """Text of ``data``: UTF-8 (BOM or not), UTF-16 with BOM, else Latin-1; RigDataError if binary."""
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        try:
            return data.decode("utf-16")
        except UnicodeDecodeError as exc:
            raise RigDataError(f"unreadable UTF-16 text: {exc}", file=path) from exc
    head = data[:8192]
    controls = sum(head.count(bytes([b])) for b in range(32) if b not in (9, 10, 12, 13, 26))
    if b"\x00" in head or controls > 0.02 * len(head):
        raise RigDataError(f"not a text file (binary content: {head[:16]!r}...); expected delimited "
                           f"text, LVM, TDMS, MATLAB .mat, Parquet, Excel .xlsx or ASAM MDF", file=path)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        return data.decode("latin-1")
