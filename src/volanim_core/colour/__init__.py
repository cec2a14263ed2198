"""24-bit colour volumes: palettes that render smoothly (the thesis's Visible Human tools).

    colour volume [x, y, z, 3] --slabs.sample_colours--> distinct colours + counts
        --palette.build_palette--> <= 255 colours --slabs.apply_palette--> 8-bit index volume
    palette --sort.sort_palette--> order (+ remap table) --alpha.merge_maps--> .tf for the renderer

``space`` holds the colour science (CIELAB, CIEDE2000, linear light). Sampled
reconstruction straight on RGB lives in ``reconstruct/sampling.py``.
"""
