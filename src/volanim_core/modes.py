"""The reconstruction modes: how a posed volume's voxels get their values (and so their colours).

A plain name list at the bottom of the core's layers: ``io`` records a result's mode in
the files it writes, ``render`` picks colours by it, ``reconstruct`` makes the volumes.
"""

MODES = ("binary", "mottled", "bone", "sampled", "hotspot")
