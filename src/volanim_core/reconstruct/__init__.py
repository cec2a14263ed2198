"""Re-growing a volume from a posed frame, and finding where a pose breaks it.

    engine.py ....... reconstruct(): spheres -> output grid, five modes, two metrics
    _kernels.py ..... the numba kernels behind it (tested against tests/naive.py)
    breakage.py ..... connected components, cracks and detached pieces of a posed frame
"""

from volanim_core.reconstruct.engine import MODES, Reconstruction, grid_bounds, reconstruct

__all__ = ["MODES", "Reconstruction", "grid_bounds", "reconstruct"]
