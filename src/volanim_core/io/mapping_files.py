"""Mapping files: which BVH joint drives each of our bones (``BONE BVH_JOINT`` per line, ``#`` comments),
read and written. Suggesting and checking a mapping is :mod:`volanim_core.motion.retarget`'s.
"""

from __future__ import annotations

from pathlib import Path

from volanim_core.rig.bones import BoneSkeleton


def read_mapping(path: str | Path) -> dict[str, str]:
    """A mapping file: ``BONE BVH_JOINT`` per line, ``#`` comments."""
    from volanim_core.io.text import read_records

    rec = read_records(path)
    out: dict[str, str] = {}
    for line, toks in rec.records:
        if len(toks) != 2:
            raise rec.error(line, f"expected 'BONE BVH_JOINT', got {len(toks)} tokens")
        if toks[0] in out:
            raise rec.error(line, f"bone {toks[0]!r} is mapped twice")
        out[toks[0]] = toks[1]
    return out


def format_mapping(mapping: dict[str, str], bones: BoneSkeleton, how: dict[str, str] | None = None) -> str:
    """The mapping file's text; ``how`` adds to each line, as a comment, what placed it."""
    how = how or {}
    lines = ["# volanim bone mapping: BONE BVH_JOINT (the BVH joint whose rotation drives the bone)"]
    lines += [f"{b.label} {mapping[b.label]}" + (f"  # {how[b.label]}" if b.label in how else "")
              for b in bones.bones if b.label in mapping]
    lines += [f"# {b.label} (unmapped: follows its parent)" for b in bones.bones if b.label not in mapping]
    return "\n".join(lines) + "\n"
