"""volscissors: Intelligent Scissors (minimum-cost paths) for medical volumes, from Python.

Conventions (the same as the `volscissors` command line):
  * ``Volume.array`` is a zero-copy NumPy view in ``[z, y, x]`` order (SimpleITK's convention);
  * spacing, origin, voxel indices and world points are ``(x, y, z)`` everywhere; indices are
    0-based, world points are LPS millimetres, lengths are physical (mm);
  * long calls release the GIL, take ``progress=callable(fraction, stage)`` and are cancelled by
    an exception raised from that callback or by Ctrl-C (KeyboardInterrupt);
  * errors: ``OSError`` for files, ``ValueError`` for bad arguments (``DataError`` for unusable
    data, ``UnreachableError`` for a target the root cannot reach), ``Cancelled``.

Example::

    import volscissors as vs
    ct = vs.read("chest_cta.nii.gz")
    tree = vs.trace(ct, root=(46, 59, 150), auto_terminals=6, cost="intensity",
                    polarity="dark", window=(-1000, -950), smooth_mm=0)
    tree.save("airways.swc")
"""

import errno as _errno
import os as _os

from ._core import (  # noqa: F401  (the public API)
    VESSELNESS_MAX_PERCENTILE,
    Cancelled,
    Contour,
    DataError,
    LiveWire,
    Mesh,
    Path,
    Tree,
    UnreachableError,
    Volume,
    __version__,
    cost,
    cut,
    isosurface,
    livewire,
    percentile,
    percentile_sample_stride,
    render,
    surface,
    trace,
    vesselness,
    vesselness_cost,
    vesselness_halo,
    vesselness_structure_scale,
)
from ._core import read as _read
from ._core import write as _write

__all__ = [
    "Cancelled",
    "Contour",
    "DataError",
    "LiveWire",
    "Mesh",
    "Path",
    "Tree",
    "UnreachableError",
    "Volume",
    "cost",
    "cut",
    "isosurface",
    "livewire",
    "percentile",
    "read",
    "render",
    "surface",
    "trace",
    "vesselness",
    "write",
]


def read(path, orientation=""):
    """Reads a volume (NIfTI, NRRD, MetaImage, VTK, DICOM folder, PNG/TIFF, OME-Zarr folder) into a Volume.

    FileNotFoundError when the path does not exist, OSError when it cannot be read.
    """
    path = _os.fspath(path)
    if not _os.path.exists(path):
        raise FileNotFoundError(_errno.ENOENT, "no such file or directory", path)
    return _read(path, orientation)


def write(volume, path):
    """Writes a Volume by extension (.nii, .nii.gz, .nrrd, .nhdr, .mha, .mhd; .zarr: OME-Zarr with a pyramid), keeping the voxel
    type, spacing, origin and direction. Atomic: never a partial file. OSError on failure."""
    _write(volume, _os.fspath(path))
