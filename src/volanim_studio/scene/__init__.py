"""The rendering layer: VTK actors that follow model events (no widgets, no edits).

view.py ......... SceneView: the point cloud and picking; composes the layers below
frame_watch.py .. each draw's time, and calls made once the next frame is drawn
hull_layer.py ... the translucent hull with its clipping plane
bones_layer.py .. the rest pose's bones, their joints and the selected bones' halo
names_layer.py .. joint names (label_layout.py: where each goes, none over another), the name under
                  the cursor, the bone being built
pose_layer.py ... posed bones and preview reconstructions
xray_layer.py ... actors drawn over everything (the posed bones through the preview)
overlays.py ..... the connect cube and the lasso outline
projection.py ... world -> display pixels with the renderer's own matrices (picking)
camera_moves.py . the plotter's camera: named views, framing, saved state
"""
