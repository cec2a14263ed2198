"""volanim studio: the desktop application (PySide6 + pyvista/pyvistaqt)."""
