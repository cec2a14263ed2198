"""The Qt layer: a main window that composes panels and controllers, all talking through the model.

    main_window.py ........ MainWindow: the view, the panels, menus; owns the controllers
    files_controller.py ... open/save volumes, skeletons, bones, connectivity, projects
    preview_controller.py . live and full previews, compare, export, poses (.trans/.tskel)
    worker.py ............. JobRunner/Worker: background jobs with progress, Cancel, clean shutdown
    bindings.py ........... two-way widget <-> settings bindings (signals blocked on write-back)
    *_panel.py ............ one panel per file; threshold_dialog.py
"""
