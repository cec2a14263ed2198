"""Re-growing a volume from a posed frame, and finding where a pose breaks it.

plan.py ............ a frame checked and made ready: FramePlan (grid, centres, values, cut, slice lists)
engine.py .......... reconstruct(): runs the plan, five modes, two metrics; result.py what it returns
owned.py ........... the default when the rig has an ownership: each rest voxel moved by the bone that
                     owns it, joints closed by balls (_owned_kernels.py, tested against tests/naive.py)
live.py ............ LiveFrame: frame after frame on one grid, redoing only the slices moved spheres reach
live_owned.py ...... LiveOwned: the owned body frame after frame on one grid, redoing only the box moved bones reach
_plan_kernels.py ... the plan's numba kernels; _kernels.py the fill and sample kernels (tested
                     against tests/naive.py); _clip_kernels.py what falls outside the grid
radii.py ........... sphere radii as the kernels compare them (squared, integer metric units)
sampling.py ........ sampled mode, grey or colour; neighbours.py the overdraw cut's neighbour lists
source_space.py .... where a sampled frame reads its source: the frame's grid against the source's
speedups.py ........ the optimisations as switches, to measure what each is worth (Fig 5.5)
breakage.py ........ cracks, stumps and torn-off pieces of a posed frame (_label_kernels.py: pieces
                     found on x-runs, nogil); cracks.py the sphere pairs that part; lumps.py flesh a
                     bone cannot carry, found without the true shape; torn.py which
                     pieces the pose tore off, and the specks it let go as the rest pose's lie
scan.py ............ many frames, worst first; whole.py one piece proved from the spheres alone
                     (_whole_kernels.py); lump_watch.py the frames that can carry a lump, found
                     from the rest pose's foreign voxels, then the report's own test on those
                     (bend.py: how a bent joint keeps shape)
checks.py .......... report() and scan(): the studio's verdicts for scripts
shape.py ........... a posed volume against its true shape: Dice, the largest wrong blobs, surface distance
displacement.py .... a frame's bones in physical space, for 3D Slicer and ITK: affines, a dense field
"""

from volanim_core.reconstruct.engine import MODES, Reconstruction, grid_bounds, reconstruct
from volanim_core.reconstruct.live import LiveFrame

__all__ = ["MODES", "LiveFrame", "Reconstruction", "grid_bounds", "reconstruct"]
