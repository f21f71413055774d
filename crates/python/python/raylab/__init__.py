"""raylab from Python: render, trace and bench from a notebook, NumPy arrays in and out.

>>> import raylab, numpy as np
>>> img = raylab.render("scenes/bunny.toml", spp=4, width=160, height=120)   # (H, W, 3) float32
>>> hits = raylab.trace("bunny.obj", origins, directions, accel="bvh")       # dict of arrays
>>> s = raylab.build(vertices, indices, accel="kdtree"); s.stats["sah_cost"]
>>> report = raylab.bench(["scenes/bunny.toml"], accels=["bvh", "kdtree"])   # the JSON schema's dict

Everything heavy runs in Rust with the GIL released, in parallel over all cores (or
``threads=N``); long jobs honour Ctrl-C. Errors about input files raise
:class:`RaylabError` (a ``ValueError``) carrying raylab's ``file:line: field: message``.
See docs/python.md.
"""

from __future__ import annotations

import os
from typing import Dict, Optional, Union

import numpy as np

from ._native import (
    RaylabError,
    Scene,
    Structure,
    __version__,
    accels,
    bench,
    build,
    compare,
    converge,
    load_mesh,
    render,
    trace,
)

__all__ = [
    "RaylabError",
    "Scene",
    "Structure",
    "__version__",
    "accels",
    "bench",
    "build",
    "compare",
    "converge",
    "load_mesh",
    "read_rays",
    "render",
    "trace",
    "write_rays",
]

# The ray-file format of `raylab trace` and `raylab bench --dump-rays` (docs/bench.md):
# little endian, a u64 count, then count records of 8 float32: ox oy oz tmin dx dy dz tmax.
_RAY_RECORD = np.dtype("<f4")


def read_rays(path: Union[str, os.PathLike]) -> Dict[str, np.ndarray]:
    """Reads a ray file into ``{"origins": (N, 3), "directions": (N, 3), "tmin": (N,), "tmax": (N,)}``
    float32 arrays, ready for :func:`trace` (the (N, 3) arrays are strided views of the file's
    records, so ``trace`` converts them once; use ``np.ascontiguousarray`` to keep a copy)."""
    data = np.fromfile(path, dtype=np.uint8)
    if data.size < 8:
        raise RaylabError(f"{os.fspath(path)}: too short for a ray file ({data.size} bytes; the header alone is 8)")
    count = int(data[:8].view("<u8")[0])
    body = data[8:]
    if count * 32 != body.size:
        raise RaylabError(f"{os.fspath(path)}: the header says {count} rays ({count * 32} bytes) but {body.size} bytes follow")
    rec = body.view(_RAY_RECORD).reshape(count, 8)
    return {"origins": rec[:, 0:3], "directions": rec[:, 4:7], "tmin": rec[:, 3], "tmax": rec[:, 7]}


def write_rays(
    path: Union[str, os.PathLike],
    origins: np.ndarray,
    directions: np.ndarray,
    tmin: Optional[Union[float, np.ndarray]] = None,
    tmax: Optional[Union[float, np.ndarray]] = None,
) -> None:
    """Writes rays as a ray file that ``raylab trace --rays`` reads (``tmin`` defaults to 0,
    ``tmax`` to infinity, as in :func:`trace`)."""
    o = np.asarray(origins, dtype=np.float32)
    d = np.asarray(directions, dtype=np.float32)
    if o.ndim != 2 or o.shape[1] != 3 or d.shape != o.shape:
        raise ValueError(f"origins and directions: expected two float arrays of shape (N, 3), got {o.shape} and {d.shape}")
    n = o.shape[0]
    rec = np.empty((n, 8), dtype=_RAY_RECORD)
    rec[:, 0:3] = o
    rec[:, 3] = 0.0 if tmin is None else np.broadcast_to(np.asarray(tmin, dtype=np.float32), (n,))
    rec[:, 4:7] = d
    rec[:, 7] = np.inf if tmax is None else np.broadcast_to(np.asarray(tmax, dtype=np.float32), (n,))
    with open(path, "wb") as f:
        f.write(np.uint64(n).astype("<u8").tobytes())
        f.write(rec.tobytes())
