"""MATLAB .mat rig files: v4 to v7.2 through scipy.io, v7.3 (HDF5) through h5py. Equal-length 1-D
variables become columns, structs are flattened by field name, a ``units`` struct (or a dataset's
``units`` attribute) gives units, text and scalars become metadata.
"""

from __future__ import annotations

import io
from collections import Counter
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import scipy
import scipy.io

from rigdata.readers.binary import HDF5, require
from rigdata.readers.frame import frame_table
from rigdata.readers.table import RawTable
from rigdata.record import RigDataError

__all__ = ["read_mat", "flatten"]

#: Struct or variable names whose string fields are units of the columns of the same name.
UNIT_NAMES = {"units", "unit", "einheiten"}


def _load_scipy(path: Path, data: bytes) -> dict[str, Any]:
    """Variables of a v4-v7.2 file as nested dicts, arrays and strings."""
    try:
        loaded = scipy.io.loadmat(io.BytesIO(data), simplify_cells=True)
    except (ValueError, TypeError, OSError, NotImplementedError) as exc:
        raise RigDataError(f"not a readable MATLAB .mat file: scipy.io cannot read it ({exc})",
                           file=path) from exc
    return {k: v for k, v in loaded.items() if not k.startswith("__")}


def _h5_value(node: Any, h5py: Any) -> Any:
    """An HDF5 node as a dict (group), text (MATLAB char or HDF5 string) or array."""
    if isinstance(node, h5py.Group):
        return {k: _h5_value(v, h5py) for k, v in node.items() if not k.startswith("#")}
    value = node[()]
    cls = node.attrs.get("MATLAB_class", b"")
    cls = cls.decode() if isinstance(cls, bytes) else str(cls)
    if cls == "char":
        return "".join(map(chr, np.asarray(value).ravel()))
    if isinstance(value, bytes):
        return value.decode(errors="replace")
    if isinstance(value, np.ndarray) and value.dtype.kind in "OS":
        items = [v.decode(errors="replace") if isinstance(v, bytes) else str(v) for v in value.ravel()]
        return items[0] if len(items) == 1 else np.asarray(items, dtype=object)
    unit = node.attrs.get("units", node.attrs.get("unit"))
    array = np.asarray(value)
    return (array, unit.decode() if isinstance(unit, bytes) else str(unit)) if unit is not None else array


def _load_h5(path: Path, data: bytes) -> tuple[dict[str, Any], dict[str, str], Any]:
    """Variables of a v7.3 (HDF5) file as nested dicts, the file's attributes, and h5py."""
    h5py = require("h5py", "MATLAB v7.3 (HDF5) files", path)
    try:
        with h5py.File(io.BytesIO(data), "r") as f:
            tree = {k: _h5_value(v, h5py) for k, v in f.items() if not k.startswith("#")}
            attrs = {str(k): (v.decode(errors="replace") if isinstance(v, bytes) else str(v))
                     for k, v in f.attrs.items() if not str(k).startswith("MATLAB")}
    except (OSError, ValueError, KeyError) as exc:
        raise RigDataError(f"damaged HDF5 (MATLAB v7.3) file: h5py cannot read it ({exc})",
                           file=path) from exc
    return tree, attrs, h5py


def _walk(tree: Mapping[str, Any], prefix: str, out: dict[str, list]) -> None:
    """Leaves of ``tree`` into ``out``: ``arrays`` (path, array, unit), ``text`` (path, str), ``units``."""
    for name, value in tree.items():
        where = f"{prefix}{name}"
        if isinstance(value, Mapping):
            if name.lower() in UNIT_NAMES and all(isinstance(v, str) for v in value.values()):
                out["units"] += list(value.items())
            else:
                _walk(value, f"{where}.", out)
        elif isinstance(value, str):
            out["text"].append((where, value))
        elif isinstance(value, tuple):
            out["arrays"].append((where, np.squeeze(value[0]), value[1]))
        elif (isinstance(value, np.ndarray) and value.dtype.kind in "biuf") or np.isscalar(value):
            out["arrays"].append((where, np.squeeze(np.asarray(value)), None))
        else:
            out["skipped"].append(f"{where} ({type(value).__name__})")


def _leaf(path: str, paths: list[str]) -> str:
    """The field name of ``path`` when no other path ends in it, else the dotted path."""
    name = path.rsplit(".", 1)[-1]
    return name if sum(p.rsplit(".", 1)[-1] == name for p in paths) == 1 else path


def flatten(tree: Mapping[str, Any]) -> tuple[dict[str, np.ndarray], dict[str, str], dict[str, str],
                                                list[str]]:
    """Columns (the most common length among 1-D arrays), units, metadata and notes of a variable tree."""
    out: dict[str, list] = {"arrays": [], "text": [], "units": [], "skipped": []}
    _walk(tree, "", out)
    vectors = [(p, a, u) for p, a, u in out["arrays"] if a.ndim == 1 and a.size > 1]
    if not vectors:
        return {}, {}, {p: s for p, s in out["text"]}, []
    length = Counter(a.size for _, a, _ in vectors).most_common(1)[0][0]
    kept = [(p, a, u) for p, a, u in vectors if a.size == length]
    paths = [p for p, _, _ in kept]
    columns = {_leaf(p, paths): a for p, a, _ in kept}
    units = {**{_leaf(p, paths): u for p, _, u in kept if u}, **dict(out["units"])}
    meta = {**{p: s for p, s in out["text"]},
            **{p: str(a.item()) for p, a, _ in out["arrays"] if a.ndim == 0}}
    notes = [f"not a column: {p} (shape {a.shape})" for p, a, _ in out["arrays"]
             if a.ndim > 1 or (a.ndim == 1 and a.size not in (1, length))]
    return columns, units, meta, notes + [f"not a column: {s}" for s in out["skipped"]]


def read_mat(path: Path, data: bytes, sha: str) -> RawTable:
    """RawTable of MATLAB file ``path`` from ``data`` and ``sha``; RigDataError if no equal-length 1-D
    variables, the file is damaged, or h5py is missing for v7.3.
    """
    if data.startswith(HDF5) or data[512:520] == HDF5:
        tree, attrs, h5py = _load_h5(path, data)
        reader = {"name": "h5py", "version": h5py.__version__}
    else:
        tree = _load_scipy(path, data)
        attrs = {}
        reader = {"name": "scipy.io", "version": scipy.__version__}
    columns, units, meta, notes = flatten(tree)
    if not columns:
        raise RigDataError(f"no 1-D numeric variables of equal length (the channels); variables: "
                           f"{list(tree)}. MATLAB table objects cannot be read outside MATLAB: save "
                           f"table2struct(T, 'ToScalar', true) or the columns as vectors", file=path)
    return frame_table(columns, str(path), "mat", units=units, metadata={**attrs, **meta}, reader=reader,
                       sha=sha, notes=tuple(notes))
