"""Colour volumes a slab of z-slices at a time, so a volume larger than memory can be
sampled and mapped to its palette (the thesis mapped the Visible Human slice by slice).

    ColourSlabs.open(path) --slab(z0, z1)--> [x, y, z, 3] uint8
    sample_colours(slabs) --> distinct colours + counts of a spread of slices
    apply_palette(slabs, palette, out) --> 8-bit index volume, written as it goes

Raw RGB ``.vol``/``.VOL`` files are memory-mapped and slice folders read one image
at a time; other formats (``.vti``, ``.nrrd``) are read whole, as their readers do.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from volanim_core.colour.palette import NearestColour, unique_colours
from volanim_core.errors import FormatError
from volanim_core.geometry import IDENTITY, Geometry
from volanim_core.io import raw_volumes, volume_files
from volanim_core.io.atomic import atomic_open
from volanim_core.progress import CancelFn, ProgressFn, Reporter
from volanim_core.volume import is_colour

SLAB_VOXELS = 1 << 22  # voxels a slab holds (12 MiB of RGB): memory stays flat whatever the volume


@dataclass
class ColourSlabs:
    """A colour volume read by z-slabs: ``shape`` is ``(X, Y, Z)``."""

    path: Path
    shape: tuple[int, int, int]
    _array: np.ndarray | None = None  # memory-mapped or loaded [x, y, z, 3]
    _files: list = field(default_factory=list)  # slice images, for a folder
    geometry: Geometry = IDENTITY  # where the voxels are: the index volume keeps it

    @classmethod
    def open(cls, path, dims=None) -> ColourSlabs:
        path = Path(path)
        if path.is_dir():
            files = volume_files.slice_files(path)
            first = volume_files.read_slice(files[0], colour=None)
            if first.ndim != 3:
                raise FormatError(files[0], "is a grey image; the palette tools need colour (RGB) slices")
            return cls(path, (first.shape[0], first.shape[1], len(files)), None, files)
        geometry = IDENTITY
        if path.suffix.lower() == ".vol":
            vol = raw_volumes.read_raw(path, dims, mmap=True)
        else:
            vol, geometry, _ = volume_files.read_scan(path, dims=dims, colour=True)
        if not is_colour(vol):
            raise FormatError(path, "is a grey volume (one value a voxel); the palette tools need colour "
                                    "(RGB: 3 bytes a voxel, RGB slices, or a 3-component .vti/.nrrd)")
        return cls(path, tuple(int(n) for n in vol.shape[:3]), vol, geometry=geometry)

    @property
    def depth(self) -> int:
        """Slices a slab holds."""
        return max(1, SLAB_VOXELS // max(1, self.shape[0] * self.shape[1]))

    def slab(self, z0: int, z1: int) -> np.ndarray:
        if self._array is not None:
            return np.asarray(self._array[:, :, z0:z1])
        expect = self.shape[:2]
        return np.stack([volume_files.read_slice(f, colour=True, expect=expect) for f in self._files[z0:z1]],
                        axis=2)

    def slabs(self, report=None):
        """``(z0, z1, slab)`` over the whole volume."""
        nz = self.shape[2]
        for z0 in range(0, nz, self.depth):
            z1 = min(nz, z0 + self.depth)
            yield z0, z1, self.slab(z0, z1)
            if report is not None:
                report(z1, nz)


def sample_colours(slabs: ColourSlabs, max_voxels: int = 1 << 23, *,
                   progress: ProgressFn | None = None, cancel: CancelFn | None = None):
    """Distinct colours and counts of a sample: evenly spread slices, up to ``max_voxels``
    voxels (the thesis's collage of slices). A volume that small is taken whole."""
    report = Reporter(progress, cancel)
    nx, ny, nz = slabs.shape
    n_slices = int(min(nz, max(1, max_voxels // max(1, nx * ny))))
    picks = np.unique(np.linspace(0, nz - 1, n_slices).round().astype(int))
    step = max(1, int(np.ceil(np.sqrt(nx * ny / max(1, max_voxels)))))  # a huge slice: every step-th voxel
    parts = []
    for k, z in enumerate(picks):
        parts.append(np.asarray(slabs.slab(int(z), int(z) + 1)[::step, ::step, 0]).reshape(-1, 3))
        report(k + 1, len(picks))
    return unique_colours(np.concatenate(parts))


def apply_palette(slabs: ColourSlabs, palette: np.ndarray, output, *, progress: ProgressFn | None = None,
                  cancel: CancelFn | None = None) -> tuple[Path, np.ndarray]:
    """Map every voxel to its nearest palette index and write the 8-bit index volume.

    ``.vol``/``.VOL`` output is written a slab at a time (memory stays flat); ``.vti`` and
    ``.nrrd`` hold the index volume (1 byte a voxel) until written. Returns the path written
    and the count of voxels per index.
    """
    report = Reporter(progress, cancel)
    mapper = NearestColour(palette)
    counts = np.zeros(256, np.int64)
    output = raw_volumes.raw_name_for(output, slabs.shape)
    report(0, slabs.shape[2])
    if Path(output).suffix.lower() == ".vol":
        size = math.prod(slabs.shape[:3]) + (raw_volumes.HEADER_BYTES if Path(output).suffix == ".VOL" else 0)
        with atomic_open(output, "wb", size=size) as fh:
            if Path(output).suffix == ".VOL":
                fh.write(raw_volumes.header_bytes(slabs.shape))
            for _, _, slab in slabs.slabs(report):
                index = mapper(slab)
                counts += np.bincount(index.ravel(), minlength=256)
                fh.write(np.ascontiguousarray(index.transpose(2, 1, 0)).tobytes())  # x fastest
        return Path(output), counts
    out = np.empty(slabs.shape, np.uint8, order="F")
    for z0, z1, slab in slabs.slabs(report):
        out[:, :, z0:z1] = mapper(slab)
    counts += np.bincount(out.ravel(order="K"), minlength=256)
    volume_files.write_volume(output, out, slabs.geometry)
    return Path(output), counts
