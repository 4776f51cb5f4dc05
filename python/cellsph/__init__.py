"""cellsph for Python: the exact fixed-radius neighbour search (Cell Indexing) and the SPH simulator.

    import numpy as np, cellsph
    points = np.random.default_rng(1).random((100_000, 3))
    offsets, indices = cellsph.neighbors(points, radius=0.02)   # CSR: rows sorted ascending

    sim = cellsph.Simulation(cellsph.Scene.load("dam-break-2d"), threads=2)
    sim.run_until(0.1)
    x = sim.positions                                            # (n, 2) copy in id order

See docs/python.md for the tour and the exact contracts.
"""

from __future__ import annotations

import csv
import os
import re
from typing import Any, Dict, Iterator, Optional, Tuple, Union

import numpy as np

from ._cellsph import (
    __version__,
    NeighborSearch,
    Scene,
    Simulation,
    SimulationError,
    count_neighbors,
    max_threads,
    methods,
    neighbors,
    scenes,
)

__all__ = [
    "NeighborSearch",
    "Scene",
    "Simulation",
    "SimulationError",
    "count_neighbors",
    "max_threads",
    "methods",
    "neighbor_matrix",
    "neighbors",
    "read_frames",
    "scenes",
    "to_csr",
]

PathLike = Union[str, "os.PathLike[str]"]


def to_csr(offsets: np.ndarray, indices: np.ndarray, data: Optional[np.ndarray] = None):
    """The CSR arrays of neighbors() as a scipy.sparse.csr_matrix of shape (n, n).

    `data` defaults to ones (the adjacency pattern); pass the distances of
    neighbors(..., return_distances=True) for a distance matrix. Needs SciPy (Debian: python3-scipy).
    SciPy converts the index arrays to its own index dtype (a copy).
    """
    import scipy.sparse  # optional dependency: imported only here

    n = len(offsets) - 1
    if data is None:
        data = np.ones(len(indices), dtype=np.float64)
    return scipy.sparse.csr_matrix((data, indices, offsets), shape=(n, n))


def neighbor_matrix(points, radius: Optional[float] = None, h=None, **kwargs):
    """scipy.sparse.csr_matrix of the distance of every neighbour pair (row i: the neighbours of i).

    Same arguments as neighbors(); entry (i, j) is |x_i - x_j| in the points' dtype (a pair of equal
    points is stored, with distance 0). Needs SciPy.
    """
    offsets, indices, dist = neighbors(points, radius=radius, h=h, return_distances=True, **kwargs)
    return to_csr(offsets, indices, dist)


# ------------------------------------------------------------------------------------------------
# Reading a run's output folder (frames.csv and the frame files it names).

# Integer fields of the particle field list (src/cellsph/solver/particles.hpp); every other is a float.
_INT_FIELDS = {"phase": np.int32, "level": np.int32, "tick": np.int64, "kind": np.uint8, "id": np.uint32}


def _read_index(folder: str):
    path = os.path.join(folder, "frames.csv")
    if not os.path.exists(path):
        raise ValueError(f"{path}: no frames.csv there (not a cellsph output folder)")
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows or rows[0][:2] != ["frame", "time"]:
        raise ValueError(f"{path}: header {rows[0] if rows else '(empty file)'} does not start with frame,time")
    header = rows[0]
    out = []
    for k, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise ValueError(f"{path}: row {k} has {len(row)} columns, the header {len(header)}")
        out.append((int(row[0]), float(row[1]), dict(zip(header[2:], row[2:]))))
    return path, header[2:], out


def _csv_frame(path: str, dtype) -> Dict[str, np.ndarray]:
    with open(path, newline="") as f:
        header = f.readline().strip().split(",")
    values = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2, dtype=np.float64)
    if values.shape[0] == 0:
        values = np.zeros((0, len(header)))
    if values.shape[1] != len(header):
        raise ValueError(f"{path}: {values.shape[1]} columns, the header names {len(header)}")
    out: Dict[str, np.ndarray] = {}
    k = 0
    while k < len(header):
        name = header[k]
        # Vectors: x,y[,z] (position), vx,vy[,vz] (velocity), NAME_x,NAME_y[,NAME_z].
        if name == "x":
            stem, comps = "position", ["x", "y", "z"]
        elif name == "vx":
            stem, comps = "velocity", ["vx", "vy", "vz"]
        elif name.endswith("_x"):
            stem, comps = name[:-2], [name[:-2] + "_" + c for c in "xyz"]
        else:
            stem, comps = name, None
        if comps is None:
            col = values[:, k]
            out[stem] = col.astype(_INT_FIELDS.get(stem, dtype))
            k += 1
        else:
            width = 3 if k + 2 < len(header) and header[k + 2] == comps[2] else 2
            out[stem] = values[:, k : k + width].astype(dtype)
            k += width
    return out


_VTU_TYPES = {
    "Float32": np.float32, "Float64": np.float64, "Int8": np.int8, "UInt8": np.uint8, "Int16": np.int16,
    "UInt16": np.uint16, "Int32": np.int32, "UInt32": np.uint32, "Int64": np.int64, "UInt64": np.uint64,
}


def _vtu_frame(path: str, _float_dtype=None) -> Dict[str, np.ndarray]:
    """A .vtu written by cellsph: raw appended data, UInt64 block headers, little endian."""
    with open(path, "rb") as f:
        blob = f.read()
    start = blob.find(b"<AppendedData")
    if start < 0:
        raise ValueError(f"{path}: no <AppendedData> (not a .vtu written by cellsph)")
    data = blob.index(b"_", start) + 1
    xml = blob[:start].decode()
    section = None
    out: Dict[str, np.ndarray] = {}
    for line in xml.splitlines():
        tag = line.strip()
        for s in ("FieldData", "PointData", "Points", "Cells"):
            if tag.startswith(f"<{s}"):
                section = s
        if not tag.startswith("<DataArray") or section not in ("PointData", "Points"):
            continue
        attrs = dict(re.findall(r'(\w+)="([^"]*)"', tag))
        dtype = np.dtype(_VTU_TYPES[attrs["type"]]).newbyteorder("<")
        pos = data + int(attrs["offset"])
        nbytes = int(np.frombuffer(blob, dtype="<u8", count=1, offset=pos)[0])
        arr = np.frombuffer(blob, dtype=dtype, count=nbytes // dtype.itemsize, offset=pos + 8).copy()
        comps = int(attrs.get("NumberOfComponents", "1"))
        name = "position" if section == "Points" else attrs["Name"]
        out[name] = arr.reshape(-1, comps) if comps > 1 else arr
    return out


def read_frames(
    folder: PathLike, format: Optional[str] = None, dtype=np.float64
) -> Iterator[Tuple[float, Dict[str, Any]]]:
    """Yields (time, fields) for every frame listed in FOLDER/frames.csv, in order.

    fields maps the particle field names of Simulation.fields() ("position", "velocity", "density",
    "pressure", "phase", "id", ...) to NumPy arrays, row k of every frame being the same particle.
    format: "csv" (default when the run wrote CSV) or "vtu". CSV frames hold the fluid particles; their
    numbers are the shortest text that reads back the run's values exactly in the run's precision, so
    float fields come as `dtype`: float64 (default) is exact for a double run, pass numpy.float32 for a
    "precision": "float" run; integer fields get their own dtypes. VTU frames hold every particle in the
    run's own dtypes (dtype is ignored), with vectors 3 wide (z = 0 in 2D), as ParaView reads them.
    """
    folder = os.fspath(folder)
    index_path, formats, rows = _read_index(folder)
    if format is None:
        format = "csv" if "csv" in formats else ("vtu" if "vtu" in formats else None)
    if format not in ("csv", "vtu") or format not in formats:
        raise ValueError(f"format: {format!r} is not among the frames of {index_path} ({', '.join(formats) or 'none'}; "
                         "read_frames reads csv and vtu)")
    reader = _csv_frame if format == "csv" else _vtu_frame
    for _frame, time, files in rows:
        yield time, reader(os.path.join(folder, files[format]), dtype)
