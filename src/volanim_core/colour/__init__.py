"""24-bit colour volumes: palettes, palette sorting, sampled reconstruction in colour (issue: Colour).

Planned modules: ``palette.py`` (build: k-means in CIELAB / median cut; apply:
nearest colour per voxel), ``sort.py`` (the thesis's orderings and ours),
``transfer.py`` (alpha maps: InterpolateAlpha, AlphaFactor, MergeMaps).
"""
