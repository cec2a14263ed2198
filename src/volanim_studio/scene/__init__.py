"""The rendering layer: VTK actors that follow model events (no widgets, no edits).

    view.py ......... SceneView: hull, cloud, bones, joints, picking
    pose_layer.py ... posed bones and preview reconstructions
    overlays.py ..... the connect cube and the lasso outline
    projection.py ... world -> display pixels with the renderer's own matrices (picking)
"""
