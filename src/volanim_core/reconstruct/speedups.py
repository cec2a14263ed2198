"""The reconstruction's optimisations as switches, to measure what each is worth (the thesis's Fig 5.5:
``benchmarks/thesis_tables.py speedups``). Each changes the time and never the result:
tests/core/reconstruct/test_speedups.py compares every combination with all of them on, voxel for voxel.
Threads are the ``threads`` argument; the algorithm itself (exact runs per row, a slice-sized stencil,
sampling after the owners are settled) is measured against the thesis's cube scan instead.
"""

from __future__ import annotations

from dataclasses import dataclass, fields


@dataclass(frozen=True)
class Speedups:
    """Which optimisations :func:`~volanim_core.reconstruct.engine.reconstruct` uses (all by default)."""

    cut: bool = True  # a sphere skips voxels a larger neighbour provably wins (Voronoi half-spaces)
    box_sweep: bool = True  # a sphere without planes sweeps its disc's x-box: no run ends per row
    prefetch: bool = True  # each sphere's centre and radius fetched a few spheres ahead

    @classmethod
    def names(cls) -> list[str]:
        return [f.name for f in fields(cls)]


ALL = Speedups()
