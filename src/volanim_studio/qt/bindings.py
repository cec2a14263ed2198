"""Two-way bindings between a widget and one setting (or any model property with an event).

    widget edited --> setter(value)       (a refused value: message, widget reset)
    model event   --> widget.setValue     (the widget's signals blocked: nothing loops)

``bind(widget, settings, "cube_size")`` covers combo boxes (by text), check
boxes, spin boxes and sliders (``scale`` maps slider steps to values).
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtWidgets import QAbstractSlider, QAbstractSpinBox, QCheckBox, QComboBox


def _accessors(widget, scale: float, to_value: Callable | None, to_widget: Callable | None):
    if isinstance(widget, QComboBox):
        read, show = to_value or str, to_widget or str
        return (widget.currentTextChanged, lambda: read(widget.currentText()),
                lambda v: widget.setCurrentText(show(v)))
    if isinstance(widget, QCheckBox):
        return widget.toggled, widget.isChecked, widget.setChecked
    if isinstance(widget, QAbstractSlider):
        return (widget.valueChanged, lambda: widget.value() * scale,
                lambda v: widget.setValue(int(round(v / scale))))
    if isinstance(widget, QAbstractSpinBox):
        return widget.valueChanged, widget.value, widget.setValue
    raise TypeError(f"cannot bind a {type(widget).__name__}")


def write_back(widget, setter: Callable) -> None:
    """Update a widget from the model without it telling the model again."""
    widget.blockSignals(True)
    try:
        setter()
    finally:
        widget.blockSignals(False)


def bind(widget, settings, name: str, *, scale: float = 1.0, to_value: Callable | None = None,
         to_widget: Callable | None = None, on_error: Callable[[str], None] | None = None) -> None:
    """Keep ``widget`` and ``settings.<name>`` equal in both directions.

    Combo boxes go by text: ``to_value(text)`` and ``to_widget(value)`` convert
    (default ``str``); sliders hold ``value / scale`` in integer steps.
    """
    changed, read, show = _accessors(widget, scale, to_value, to_widget)

    def edited(*_):
        try:
            setattr(settings, name, read())
        except ValueError as exc:
            if on_error is not None:
                on_error(str(exc))
            write_back(widget, lambda: show(getattr(settings, name)))

    changed.connect(edited)
    getattr(settings.events, name).connect(lambda value, **_: write_back(widget, lambda: show(value)))
    write_back(widget, lambda: show(getattr(settings, name)))
