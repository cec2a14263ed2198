"""Many frames at once: one output grid, resumable runs, local or Dask executors (issue: Sequences).

``frames.py`` (a FrameSpec per frame, from .trans/.tskel/BVH), ``effects.py``
(melt, teleport, crumble), ``store.py`` (OME-Zarr + manifest), ``task.py`` (the
one frame function), ``run.py`` (shared bounds, resume, local pool or Dask).
"""
