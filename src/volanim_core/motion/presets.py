"""BVH naming schemes: which joint name means which body part, scheme by scheme.

    clip's joint names -> each preset scores how many of them it explains -> the best one names parts
                          {"L_UPPERARM": joint, "SPINE": joint, ...}

Why presets and not one table of synonyms: the same name means different
parts in different schemes. ``LeftShoulder`` is the clavicle for Mixamo, CMU,
LAFAN and Rokoko, but the upper arm for Biovision/MocapBank (whose clavicle is
``LeftCollar``); ``LeftLeg`` is the shin for Mixamo, the whole leg elsewhere.
A clip is read in the one scheme that explains most of its names.

Parts are our bone parts (``UPPERARM``), sided as our labels are (``L_UPPERARM``).
A part names the BVH joint at the bone's *proximal* end: the joint whose
rotation turns that bone (``LeftArm`` turns the upper arm).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

SIDED = ("CLAVICLE", "UPPERARM", "FOREARM", "HAND", "THIGH", "SHIN", "FOOT", "TOE")
MIDDLE = ("SPINE", "NECK", "HEAD")
ALIASES = {"CALF": "SHIN", "SHOULDER": "CLAVICLE", "ARM": "UPPERARM", "LOWERARM": "FOREARM", "UPPERLEG": "THIGH",
           "LEG": "SHIN", "ANKLE": "FOOT", "WRIST": "HAND", "ELBOW": "FOREARM", "KNEE": "SHIN", "CHEST": "SPINE"}


@dataclass(frozen=True)
class Preset:
    name: str
    sides: tuple[str, str]  # how the scheme writes left and right ({S} in the names)
    parts: dict[str, tuple[str, ...]]  # part -> candidate names, first found wins

    def names_for(self, part: str, side: str | None) -> list[str]:
        s = {"L": self.sides[0], "R": self.sides[1]}.get(side or "", "")
        return [n.replace("{S}", s).lower() for n in self.parts.get(part, ())]


_MIXAMO = {"SPINE": ("Spine", "LowerBack", "Spine1"), "NECK": ("Neck", "Neck1"), "HEAD": ("Head",),
           "CLAVICLE": ("{S}Shoulder",), "UPPERARM": ("{S}Arm",), "FOREARM": ("{S}ForeArm",),
           "HAND": ("{S}Hand",), "THIGH": ("{S}UpLeg",), "SHIN": ("{S}Leg",), "FOOT": ("{S}Foot",),
           "TOE": ("{S}ToeBase", "{S}Toe")}
# not "face" for the head: in Blender's rigs it is a short bone pointing forward from the head
_BLENDER = {"SPINE": ("spine", "spine.001"), "NECK": ("neck", "spine.004"), "HEAD": ("head", "spine.006"),
            "CLAVICLE": ("shoulder{S}",), "UPPERARM": ("upper_arm{S}", "upperarm{S}"),
            "FOREARM": ("forearm{S}", "lowerarm{S}"), "HAND": ("hand{S}",), "THIGH": ("thigh{S}",),
            "SHIN": ("shin{S}", "calf{S}"), "FOOT": ("foot{S}",), "TOE": ("toe{S}",)}

PRESETS = (
    Preset("Mixamo / CMU / LAFAN", ("Left", "Right"), _MIXAMO),
    Preset("Biovision / MocapBank", ("Left", "Right"), {
        "SPINE": ("Chest", "Spine"), "NECK": ("Neck",), "HEAD": ("Head",), "CLAVICLE": ("{S}Collar",),
        "UPPERARM": ("{S}Shoulder", "{S}UpArm"), "FOREARM": ("{S}Elbow", "{S}LowArm"),
        "HAND": ("{S}Wrist", "{S}Hand"), "THIGH": ("{S}Hip", "{S}UpLeg"), "SHIN": ("{S}Knee", "{S}LowLeg"),
        "FOOT": ("{S}Ankle", "{S}Foot"), "TOE": ("{S}Toe",)}),
    Preset("Rokoko", ("Left", "Right"), {**_MIXAMO, "THIGH": ("{S}Thigh",), "SHIN": ("{S}Shin",),
                                         "TOE": ("{S}Toe",)}),
    Preset("Blender .L/.R", (".L", ".R"), _BLENDER),
    Preset("Blender _L/_R", ("_L", "_R"), _BLENDER),
    Preset("Unreal mannequin", ("_l", "_r"), {
        "SPINE": ("spine_01",), "NECK": ("neck_01",), "HEAD": ("head",), "CLAVICLE": ("clavicle{S}",),
        "UPPERARM": ("upperarm{S}",), "FOREARM": ("lowerarm{S}",), "HAND": ("hand{S}",), "THIGH": ("thigh{S}",),
        "SHIN": ("calf{S}",), "FOOT": ("foot{S}",), "TOE": ("ball{S}",)}),
    # 3ds Max's biped, "Bip01 L UpperArm" or "Bip01_L_UpperArm" (Bip001, Bip02: see plain)
    Preset("3ds Max biped (Bip01)", ("L_", "R_"), {
        "SPINE": ("Spine", "Spine1"), "NECK": ("Neck",), "HEAD": ("Head",), "CLAVICLE": ("{S}Clavicle",),
        "UPPERARM": ("{S}UpperArm",), "FOREARM": ("{S}Forearm",), "HAND": ("{S}Hand",), "THIGH": ("{S}Thigh",),
        "SHIN": ("{S}Calf",), "FOOT": ("{S}Foot",), "TOE": ("{S}Toe0", "{S}Toe")}),
    # VRM's humanoid bones (VRM animations, .vrma), as Unity's Humanoid names them
    Preset("VRM / Unity humanoid", ("Left", "Right"), {
        "SPINE": ("spine", "chest", "upperChest"), "NECK": ("neck",), "HEAD": ("head",),
        "CLAVICLE": ("{S}Shoulder",), "UPPERARM": ("{S}UpperArm",), "FOREARM": ("{S}LowerArm",),
        "HAND": ("{S}Hand",), "THIGH": ("{S}UpperLeg",), "SHIN": ("{S}LowerLeg",), "FOOT": ("{S}Foot",),
        "TOE": ("{S}Toes",)}),
    Preset("volanim L_/R_", ("L_", "R_"), {
        **{p: ("{S}" + p,) for p in SIDED}, "SPINE": ("SPINE",), "NECK": ("NECK",), "HEAD": ("HEAD",)}),
)


def plain(name: str) -> str:
    """``mixamorig:LeftArm`` -> ``leftarm``: the name without a namespace, lower case; a 3ds Max biped's
    ``Bip01 L UpperArm`` (``Bip001_L_UpperArm``) -> ``l_upperarm``: no biped prefix, spaces as ``_``."""
    name = re.sub(r"^.*[:|]", "", name).lower()
    return re.sub(r"^bip0*\d+[ _]+", "", name).replace(" ", "_")


def part_of(label: str) -> tuple[str | None, str]:
    """Our bone label -> (side, part): ``L_UPPERARM`` -> ("L", "UPPERARM"); ``L_CALF`` -> ("L", "SHIN")."""
    m = re.fullmatch(r"(?:([LR])_)?(\w+?)", label.upper())
    side, part = (m.group(1), m.group(2)) if m else (None, label.upper())
    return side, ALIASES.get(part, part)


def part_key(side: str | None, part: str) -> str:
    return f"{side}_{part}" if side else part


def preset_parts(preset: Preset, names: list[str]) -> dict[str, int]:
    """Part key (``L_UPPERARM``) -> joint index, for every part the preset finds a name for."""
    where = {plain(n): j for j, n in enumerate(names)}
    out = {}
    for part in MIDDLE + SIDED:
        for side in ("L", "R") if part in SIDED else (None,):
            for candidate in preset.names_for(part, side):
                if candidate in where and where[candidate] not in out.values():
                    out[part_key(side, part)] = where[candidate]
                    break
    return out


def best_preset(names: list[str]) -> tuple[Preset, dict[str, int]]:
    """The preset explaining most of the clip's names (the first listed on a tie), and its parts."""
    scored = [(len(parts), -k, p, parts) for k, p in enumerate(PRESETS) for parts in [preset_parts(p, names)]]
    _, _, preset, parts = max(scored, key=lambda s: (s[0], s[1]))
    return preset, parts
