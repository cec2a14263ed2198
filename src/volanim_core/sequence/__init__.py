"""Many frames at once: one output grid, resumable runs, local or Dask executors (issue: Sequences).

Planned modules: ``plan.py`` (shared bounds over all frames), ``run.py`` (a
manifest of finished frames, OME-Zarr output), ``executors.py`` (process pool,
``distributed``), ``effects.py`` (melt, crumble).
"""
