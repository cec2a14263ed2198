"""The fault corpus, run in a memory-capped worker and as real ``volanim`` processes.

One test per case, named by its target and case (``test_case[read_sequence: store: two frames' shards
swapped]``), so a failure names what broke; the corpus runs once (the worker reads cases in batches)
and ``test_the_table`` prints the table (tried / clean / crash / hang / memory / silent per reader and
command). Cases: the hand-written corpus (``cases.hand_written``), the scan readers'
(``scan_cases``), the sequence stores' (``store_cases``), the second round's (``round2_cases``:
meshes, project values, BVH values, .tskel, transfer functions), every hostile number in every text
format, and 40 mutations drawn with a fixed seed.
"""

from __future__ import annotations

import random

import pytest

from .cases import HOSTILE_NUMBERS, hand_written, mutated
from .round2_cases import round2_cases
from .round3_cases import round3_cases
from .round4_cases import round4_cases
from .round5_cases import round5_cases
from .run import run_corpus, table
from .scan_cases import scan_cases
from .store_cases import store_cases

KINDS = ("mskel", "bones", "connect", "tskel", "camera", "tf", "palette", "alpha")


def corpus():
    sweep = [mutated(kind, k, value) for kind in KINDS for k, value in enumerate(HOSTILE_NUMBERS)]
    draw = random.Random(2026)
    drawn = {(draw.choice(KINDS), draw.randrange(41), draw.choice(HOSTILE_NUMBERS)) for _ in range(60)}
    cases = hand_written() + scan_cases() + store_cases() + round2_cases() + round3_cases() + round4_cases() + \
        round5_cases() + sweep + [mutated(*m) for m in sorted(drawn)]
    seen, unique = set(), []
    for c in cases:  # a drawn mutation may repeat a swept one
        key = (c.target, c.name)
        if key not in seen:
            seen.add(key)
            unique.append(c)
    return unique


CASES = corpus()


@pytest.fixture(scope="module")
def outcomes(tmp_path_factory):
    rows = run_corpus(CASES, tmp_path_factory.mktemp("faults"))
    return {(case.target, case.name): (outcome, detail) for case, outcome, detail in rows}, rows


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES, ids=[f"{c.target}: {c.name}" for c in CASES])
def test_case(outcomes, case):
    outcome, detail = outcomes[0][(case.target, case.name)]
    assert outcome == "clean", f"{outcome}: {detail}"


@pytest.mark.slow
def test_the_table(outcomes, capsys):
    with capsys.disabled():
        print("\n" + table(outcomes[1]))
    assert len(outcomes[1]) >= 250
