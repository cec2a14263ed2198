"""Many frames at once: one output grid, resumable runs, local or Dask executors.

    frames.py ....... a FrameSpec per frame, from .trans/.tskel/BVH
    effects.py ...... melt, teleport, crumble (_heap_kernels.py: the heap a crumble falls into)
    task.py ......... the one frame function a worker runs
    run.py .......... shared bounds, resume, a local pool or Dask
    store.py ........ writes the OME-Zarr store and its manifest
    checked.py ...... reads it: the metadata checked once, each frame verified against its sha256
"""
