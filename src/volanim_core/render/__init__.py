"""Qt-free rendering knowledge, shared by the studio and the command line.

    colours.py ...... bone colours (32 distinct, by root order), point colour maps
    transfer.py ..... transfer functions per reconstruction mode, label steps on VTK volumes
    surfaces.py ..... label-coloured isosurfaces (the fast live-preview look)

pyvista and VTK are imported inside the functions that need them, so importing
this package costs nothing.
"""
