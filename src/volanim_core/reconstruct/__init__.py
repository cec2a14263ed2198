"""Re-growing a volume from a posed frame, and finding where a pose breaks it.

    plan.py ............ a frame checked and made ready: FramePlan (grid, centres, values, cut, slice lists)
    engine.py .......... reconstruct(): runs the plan, five modes, two metrics
    live.py ............ LiveFrame: frame after frame on one grid, redoing only the slices moved spheres reach
    _plan_kernels.py ... the plan's numba kernels; _kernels.py the fill and sample kernels (tested
                         against tests/naive.py); _clip_kernels.py what falls outside the grid
    sampling.py ........ sampled mode, grey or colour; neighbours.py the overdraw cut's neighbour lists
    breakage.py ........ cracks, stumps and torn-off pieces of a posed frame (_label_kernels.py: pieces
                         found on x-runs, nogil); scan.py many frames; bend.py how a bent joint keeps shape
    shape.py ........... a posed volume against its true shape: Dice, the largest wrong blobs, surface distance
"""

from volanim_core.reconstruct.engine import MODES, Reconstruction, grid_bounds, reconstruct
from volanim_core.reconstruct.live import LiveFrame

__all__ = ["MODES", "LiveFrame", "Reconstruction", "grid_bounds", "reconstruct"]
