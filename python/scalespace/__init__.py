"""scalespace: multi-scale analysis of 3D point clouds, on NumPy arrays.

Every function takes positions as an (N, 3) array (read in place when it is C-contiguous
float64, else converted once) and returns NumPy arrays that own their memory. Long calls release
the GIL, take ``progress=callable(fraction, stage)`` (return False to cancel: raises
:class:`Cancelled`) and stop cleanly on Ctrl-C (KeyboardInterrupt). Bad arguments raise
:class:`OptionError` (a ValueError) or ValueError/TypeError with the library's wording; bad files
raise :class:`FileError` (an OSError). The inputs are copied into the library's arrays, whose
memory the module keeps for the next call of a similar size (the last call's, up to 256 MB):
:func:`release_buffers` frees it.

    import scalespace as ss
    cloud = ss.read("scan.ply")
    curv = ss.curvature(cloud.points, cloud.normals, scale_k=40)
    planes = ss.planes(cloud.points, scales=30)
    pipes = ss.cylinders(cloud.points, cloud.normals)
    uv = ss.parametrize(cloud.points, cloud.normals)["uv"]
"""
import warnings
from dataclasses import dataclass, field
from typing import Dict, Mapping, Optional

import numpy as np

from ._scalespace import (  # noqa: F401
    Cancelled,
    Cylinders,
    Error,
    FileError,
    OptionError,
    Planes,
    Stack,
    __version__,
    compute_stack,
    curvature,
    cylinders,
    distortion,
    estimate_normals,
    features,
    lines,
    open_stack,
    parametrize,
    planes,
    read_mesh,
    read_planes,
    release_buffers,
    render,
    retain_freed_memory,
)
from . import _scalespace

__all__ = [
    "Cloud", "read", "write", "estimate_normals", "curvature", "compute_stack", "open_stack",
    "Stack", "planes", "read_planes", "read_mesh", "Planes", "render", "lines", "features", "cylinders",
    "Cylinders", "parametrize", "distortion", "Error", "retain_freed_memory", "release_buffers",
    "OptionError", "FileError", "Cancelled", "__version__",
]


@dataclass
class Cloud:
    """A point cloud as arrays: what :func:`read` returns and :func:`write` takes.

    points: (N, 3) float64, absolute coordinates. normals: (N, 3) float64 or None.
    attributes: name -> (N,) array in the dtype the file stores (uint8 colours, float32, ...).
    format: the file's format as read ("ply (binary_little_endian)", ...).
    dropped: points skipped for NaN/Inf coordinates (read with drop_invalid=True).
    viewpoint: (x, y, z) where the points were seen from, when the file says so (a PCD's
    VIEWPOINT), else None: ``estimate_normals(points, viewpoint=cloud.viewpoint)`` orients each
    part of a scan to face it, as the CLI does.
    """

    points: np.ndarray
    normals: Optional[np.ndarray] = None
    attributes: Dict[str, np.ndarray] = field(default_factory=dict)
    format: str = ""
    dropped: int = 0
    viewpoint: Optional[tuple] = None

    def __len__(self) -> int:
        return len(self.points)


def read(path: str, *, drop_invalid: bool = False, sample: int = 0, seed: int = 1) -> Cloud:
    """Reads a cloud: PLY, XYZ/TXT/CSV/PTS, PWN (CGAL's points with normals), OFF/OBJ (vertices, or ``sample`` points drawn by
    area with interpolated normals), LAS 1.0-1.4, PCD. Points with NaN/Inf coordinates raise
    FileError unless ``drop_invalid``. An empty file reads as an empty cloud. A file whose normals
    are all zero or NaN/Inf (a placeholder from a writer without normals) reads as one without
    normals (``normals`` None), with a warning."""
    d = _scalespace._read(str(path), drop_invalid=drop_invalid, sample=sample, seed=seed)
    if d["unusable_normals_dropped"]:
        warnings.warn(f"{path}: every normal in the file is zero or NaN/Inf: read without normals",
                      stacklevel=2)
    return Cloud(d["points"], d["normals"], dict(d["attributes"]), d["format"], d["dropped"],
                 d["viewpoint"])


def write(path: str, points, normals=None, attributes: Optional[Mapping[str, np.ndarray]] = None,
          *, ascii: bool = False) -> None:
    """Writes a cloud (by extension: .ply .xyz .txt .csv .pts .pwn .las .pcd), atomically.

    ``points`` may be a :class:`Cloud` (then normals and attributes come from it). Attribute
    dtypes are kept (int8..uint32, float32, float64; bool as uint8). ascii: PLY/PCD as text.
    .pwn (CGAL's points with normals) holds positions and normals only: it needs normals and
    does not write the attributes."""
    if isinstance(points, Cloud):
        cloud = points
        points = cloud.points
        normals = cloud.normals if normals is None else normals
        attributes = cloud.attributes if attributes is None else attributes
    _scalespace._write(str(path), points, normals,
                       None if attributes is None else dict(attributes), ascii=ascii)
