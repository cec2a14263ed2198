"""No studio Qt class may hide a Qt method behind an attribute of its own.

``ThresholdDialog.metric = QComboBox()`` shadowed ``QPaintDevice.metric()``:
Qt called the combo box, printed ``TypeError: 'QComboBox' object is not
callable`` and grabbing the dialog segfaulted. The check reads every
``self.NAME = ...`` in every class of the studio that derives from a Qt
class, and every method it defines, and refuses names the Qt base already has.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil

import volanim_studio


def _studio_qt_classes():
    from PySide6.QtCore import QObject

    for info in pkgutil.walk_packages(volanim_studio.__path__, "volanim_studio."):
        module = importlib.import_module(info.name)
        for _, cls in inspect.getmembers(module, inspect.isclass):
            if cls.__module__ == module.__name__ and issubclass(cls, QObject):
                yield cls


def _qt_base(cls):
    return next(c for c in cls.__mro__ if c.__module__.startswith("PySide6"))


def _names_defined(cls) -> set[str]:
    tree = ast.parse(inspect.getsource(cls))
    names = set()
    for node in ast.walk(tree):
        targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(
            node, ast.AnnAssign | ast.AugAssign) else []
        for t in targets:
            for el in (t.elts if isinstance(t, ast.Tuple) else [t]):
                if isinstance(el, ast.Attribute) and isinstance(el.value, ast.Name) and el.value.id == "self":
                    names.add(el.attr)
    names |= {k for k in vars(cls) if not k.startswith("__") and k != "staticMetaObject"}  # PySide adds that
    return names


def test_the_check_finds_the_classes_it_must_check():
    names = {c.__name__ for c in _studio_qt_classes()}
    assert {"MainWindow", "ThresholdDialog", "ReconstructPanel"} <= names


def test_no_attribute_or_method_shadows_a_qt_member():
    bad = []
    for cls in _studio_qt_classes():
        base = _qt_base(cls)
        for name in sorted(_names_defined(cls)):
            if not hasattr(base, name):
                continue
            own = vars(cls).get(name)
            if inspect.isfunction(own) and callable(getattr(base, name)):
                continue  # a method override (closeEvent, run, ...): meant
            bad.append(f"{cls.__module__}.{cls.__name__}.{name} hides {base.__name__}.{name}")
    assert not bad, "\n".join(bad)
