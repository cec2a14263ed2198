"""The settings model: one validated property and one event each (plain events, no Qt)."""

from __future__ import annotations

import math

import pytest

from volanim_studio.model.settings import SETTINGS, Settings


def test_every_setting_has_its_default_and_its_event():
    s = Settings()
    for name, spec in SETTINGS.items():
        assert getattr(s, name) == spec.default
        assert hasattr(s.events, name)


def test_a_change_emits_once_and_an_equal_value_not_at_all():
    s = Settings()
    seen = []
    s.events.point_size.connect(lambda value, **_: seen.append(value))
    s.point_size = 9
    s.point_size = 9.0
    assert seen == [9.0] and s.point_size == 9.0


@pytest.mark.parametrize("name, bad", [("colour_by", "purple"), ("point_size", 0), ("point_size", math.nan),
                                       ("hull_opacity", 2), ("preview_kernel", 2), ("lasso_depth", "deep"),
                                       ("clip_axis", 3), ("spheres", "yes"), ("cube_size", "big"),
                                       ("preview_padding", 2.5), ("current_frame", True), ("spheres", 5)])
def test_bad_values_are_refused_with_the_name_and_value(name, bad):
    s = Settings()
    with pytest.raises(ValueError, match=name):
        setattr(s, name, bad)
    assert getattr(s, name) == SETTINGS[name].default


def test_update_applies_what_is_valid_and_reports_the_rest():
    s = Settings()
    refused = s.update({"cube_size": 20, "preview_mode": "weird", "nonsense": 1})
    assert s.cube_size == 20 and s.preview_mode == "bone"
    assert len(refused) == 2 and any("nonsense" in r for r in refused)


def test_the_studio_offers_exactly_the_core_s_modes_and_attachment_methods():
    """One list each (#68): a mode or method the core adds shows in the studio's menus, a name the core drops
    cannot linger there."""
    from volanim_core.modes import MODES
    from volanim_core.rig.attach import METHODS
    from volanim_studio.model.settings import AUTO_METHODS, PREVIEW_MODES, SETTINGS

    assert sorted(PREVIEW_MODES) == sorted(MODES) and sorted(AUTO_METHODS) == sorted(METHODS)
    assert PREVIEW_MODES[0] == SETTINGS["preview_mode"].default and AUTO_METHODS[0] == SETTINGS["auto_method"].default
