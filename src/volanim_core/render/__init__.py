"""Qt-free rendering knowledge, shared by the studio and the command line.

    bone_colours.py . bone colours (32 distinct, by root order), label tables, point colour maps
    volume_style.py . how each reconstruction mode's volume is drawn: label steps, VTK transfer functions
    surfaces.py ..... label-coloured surfaces: flying edges (the surface style), voxel faces (the live preview's;
                      its arrays made by ../voxel_faces.py)
    views.py ........ named views and follow cameras from boxes (no frames, no files)
    framing.py ...... place_camera: a render's camera from its inputs (a view of every body, given, follow)
    scene.py ........ RenderSettings, presets, the off-screen Renderer, cut-aways
    movie.py ........ many frames to pictures and a movie: inputs, one plotter per worker, resumable PNGs
    quicklook.py .... `volanim view` and the studio's View window
    skinned_body.py . the rest body's surface skinned to the bones, a clip as its animation: `export-gltf`
    slices.py, slice_view.py  `view --slices`

pyvista and VTK are imported inside the functions that need them, so importing
this package costs nothing.
"""
