"""Closing a pyvistaqt ``QtInteractor`` without leaving a stale Qt wrapper behind.

The interactor keeps a Python wrapper of its GL context's surface (a ``QSurface``).
QSurface is not a QObject, so PySide cannot see Qt delete it with the widget, and
while the interactor object lives (until the next garbage collection) PySide maps
that freed address to the old wrapper: an object Qt later allocates at the same
address comes back into Python as that QSurface. A CI run's next main window got
one from ``menuBar().addMenu("&Pose")`` ("'QSurface' object has no attribute
'addAction'"). Dropping the interactor's references at close frees the wrapper
while the address is still the surface's.
"""

from __future__ import annotations


def close_interactor(plotter) -> None:
    """``plotter.close()``, then drop its references to the GL context and surface."""
    plotter.close()
    forget = getattr(plotter, "_forget_context", None)  # pyvistaqt >= 0.13 (its rwi.py)
    if forget is not None:
        forget()
