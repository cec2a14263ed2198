"""24-bit colour volumes: palettes that render smoothly (the thesis's Visible Human tools).

    colour volume [x, y, z, 3] --slabs.sample_colours--> distinct colours + counts
        --palette.build_palette--> <= 255 colours --slabs.apply_palette--> 8-bit index volume
    palette --sort.sort_palette--> order (+ remap table) --alpha.merge_maps--> .tf for the renderer

    space.py ..... colour science on uint8 sRGB: CIELAB, CIEDE2000, linear light
    palette.py ... at most 255 colours for a colour volume, and voxels mapped to them
    slabs.py ..... colour volumes a slab of z-slices at a time (larger than memory)
    sort.py ...... palette orderings, so interpolated indices show smooth colour (_tour_kernels.py)
    alpha.py ..... alpha maps and transfer functions for index volumes (InterpolateAlpha, MergeMaps)
    indexed.py ... a colour volume as one byte a voxel, its palette beside it

Sampled reconstruction straight on RGB lives in ``reconstruct/sampling.py``.
"""
