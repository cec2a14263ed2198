"""Fixtures the command-line tests share."""

from __future__ import annotations

import pytest

from volanim_core.cli import main
from volanim_core.samples import write_sample


@pytest.fixture(scope="session")
def skeletonized_mannequin(tmp_path_factory):
    """A folder with the mannequin sample (volume, bones) and ``m.mskel``, its skeleton by ``volanim
    skeletonize``; tests write their own files beside them under names of their own."""
    d = tmp_path_factory.mktemp("mannequin")
    write_sample("mannequin", d)
    assert main(["skeletonize", str(d / "mannequin.VOL"), "-o", str(d / "m.mskel")]) == 0
    return d
