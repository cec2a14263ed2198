"""Fault cases for sequence stores (#38): a real two-frame store written by ``volanim_core.sequence.store``,
then one piece of its metadata or its data made hostile per case.

Read through ``worker.read_sequence`` (every finished frame, verified) and through ``volanim render``.
"""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

import numpy as np

from .cases import Case

STORE = "s.zarr"


def valid_store() -> dict[str, bytes]:
    """A 2-frame uint8 store of 6 x 5 x 4 voxels, each frame recorded with its checksum and region."""
    from volanim_core.sequence import store

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / STORE
        store.create(path, (4, 5, 6), 2, np.uint8, (1, 2, 3), {"key": "k" * 16, "mode": "bone", "frames": 2,
                                                               "numbers": [10, 11]}, fps=12.0)
        arr = store.open_frames(path, "r+")
        for i in range(2):
            zyx = np.zeros((4, 5, 6), np.uint8)
            zyx[1:3, 1 + i:4, 2:5] = i + 1
            arr[i] = zyx
            store.record(path, store.frame_record(i, 10 + i, zyx, filled=int(np.count_nonzero(zyx))))
        return {str(p.relative_to(tmp)): p.read_bytes() for p in sorted(Path(tmp).rglob("*")) if p.is_file()}


def _json(files, rel, change, raw: dict[str, bytes] | None = None) -> dict[str, bytes]:
    """``files`` with the JSON file ``rel`` changed; ``raw`` then replaces quoted placeholders by text JSON
    cannot make itself (NaN, a 401-digit number)."""
    out = dict(files)
    text = json.dumps(change(json.loads(out[rel]))).encode()
    for placeholder, value in (raw or {}).items():
        text = text.replace(f'"{placeholder}"'.encode(), value)
    out[rel] = text
    return out


def _attrs(change):
    def edit(group):
        change(group["attributes"])
        return group
    return edit


def _shard(files, index: int) -> str:
    return next(rel for rel in files if rel.startswith(f"{STORE}/0/c/{index}/"))


def store_cases() -> list[Case]:
    base = valid_store()
    plan, group, array, manifest = (f"{STORE}/volanim-plan.json", f"{STORE}/zarr.json", f"{STORE}/0/zarr.json",
                                    f"{STORE}/volanim-frames.jsonl")
    records = [json.loads(line) for line in base[manifest].decode().splitlines()]

    def with_records(change):
        out = dict(base)
        out[manifest] = "".join(json.dumps(change(dict(r))) + "\n" for r in records).encode()
        return out

    def set_shape(shape):
        return lambda a: {**a, "shape": shape}

    missing = dict(base)
    del missing[_shard(base, 1)]
    swapped = dict(base)
    swapped[_shard(base, 0)], swapped[_shard(base, 1)] = base[_shard(base, 1)], base[_shard(base, 0)]
    nested = dict(base)
    nested[plan] = b"[" * 100_000 + b"]" * 100_000
    variants = {
        "the plan is a list": _json(base, plan, lambda p: [p]),
        "the plan lacks frames": _json(base, plan, lambda p: {k: v for k, v in p.items() if k != "frames"}),
        "the plan lacks its key": _json(base, plan, lambda p: {k: v for k, v in p.items() if k != "key"}),
        "the plan claims 10^12 frames": _json(base, plan, lambda p: {**p, "frames": 10**12}),
        "the plan's frames are a 401-digit number": _json(base, plan, lambda p: {**p, "frames": "BIG"},
                                                          {"BIG": b"9" * 401}),
        "a bogus mode": _json(base, plan, lambda p: {**p, "mode": "fancy"}),
        "100 000 nested arrays": nested,
        "a record without sha256": with_records(lambda r: {k: v for k, v in r.items() if k != "sha256"}),
        "a record of another index": with_records(lambda r: {**r, "index": 7}),
        "attributes without volanim": _json(base, group, _attrs(lambda a: a.pop("volanim"))),
        "attributes without ome": _json(base, group, _attrs(lambda a: a.pop("ome"))),
        "an OME time scale of 0": _json(base, group, _attrs(lambda a: a["ome"]["multiscales"][0]["datasets"][0][
            "coordinateTransformations"][0]["scale"].__setitem__(0, 0))),
        "a two-value origin": _json(base, group, _attrs(lambda a: a["volanim"].__setitem__("origin_xyz", [1, 2]))),
        "a NaN origin": _json(base, group, _attrs(lambda a: a["volanim"].__setitem__("origin_xyz", ["N", 2, 3])),
                              {"N": b"NaN"}),
        "an array of 2 x 10^15 voxels": _json(base, array, set_shape([2, 10**5, 10**5, 10**5])),
        "a frame of 2^40 voxels": _json(base, array, set_shape([2, 2**14, 2**13, 2**13])),
        "a zero-size array": _json(base, array, set_shape([2, 0, 5, 6])),
        "the array and plan disagree on frames": _json(base, array, set_shape([3, 4, 5, 6])),
        "a frame recorded complete whose shard is gone": missing,
        "two frames' shards swapped": swapped,
    }
    cases = [Case(f"store: {name}", "read_sequence", files, STORE) for name, files in variants.items()]
    cases.append(Case("store: a valid store, every frame verified", "read_sequence", base, STORE, "accept",
                      "two_frames"))
    for name in ("the plan is a list", "an OME time scale of 0", "two frames' shards swapped"):
        cases.append(Case(f"render: {name}", "cli:render", variants[name], f"render {{d}}/{STORE} -o {{d}}/o.gif "
                          "--size 64x48 --workers 1"))
    # #87: a shared grid larger than memory is a full-size walk's (31.5 G voxels), not a fault: a movie reads
    # each frame's recorded region, which fits (reading the whole grid, as read_sequence does, is refused)
    cases.append(Case("render: a shared grid of 2^40 voxels, frames' regions small", "cli:render",
                      variants["a frame of 2^40 voxels"], f"render {{d}}/{STORE} -o {{d}}/o.gif --size 64x48 "
                      "--workers 1", "accept"))
    cases.append(Case("render: a valid store", "cli:render", base, f"render {{d}}/{STORE} -o {{d}}/o.gif "
                      "--size 64x48 --workers 1", "accept"))
    return cases

