"""volanim studio: the desktop application (PySide6 + pyvista/pyvistaqt).

    model/ ....... the Qt-free document: the single source of truth, with undo and events
    scene/ ....... VTK actors that follow the model's events
    qt/ .......... the window, panels, dialogs and controllers; they only talk to the model
    tasks.py ..... the long jobs (previews, scans, movies), Qt-free; qt/worker.py runs them
    shortcuts.py . the keyboard and mouse shortcuts: the table F1 shows and the docs site prints
    app.py ....... ``volanim-studio``: arguments, the application, the window

The ``studio-layers`` contract (pyproject.toml) keeps qt above scene above model.
"""
