"""The fault corpus, run in a memory-capped worker and as real ``volanim`` processes.

Prints the table (tried / clean / crash / hang / memory / silent per reader and
CLI command) and fails on anything that is not clean. Cases: the hand-written
corpus (``cases.hand_written``; the scan readers' in ``scan_cases.scan_cases``), every hostile
number in every text format, and mutations drawn by hypothesis.
"""

from __future__ import annotations

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from .cases import HOSTILE_NUMBERS, hand_written, mutated
from .run import run_corpus, table
from .scan_cases import scan_cases

KINDS = ("mskel", "bones", "connect", "tskel", "camera", "tf", "palette", "alpha")
MUTATIONS = st.lists(st.tuples(st.sampled_from(KINDS), st.integers(0, 40), st.sampled_from(HOSTILE_NUMBERS)),
                     min_size=40, max_size=40, unique=True)


@settings(max_examples=1, derandomize=True, deadline=None, database=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow,
                                 HealthCheck.data_too_large])
@given(drawn=MUTATIONS)
def test_fault_corpus_has_no_crash_hang_memory_blowup_or_silent_acceptance(tmp_path_factory, capsys, drawn):
    sweep = [mutated(kind, k, value) for kind in KINDS for k, value in enumerate(HOSTILE_NUMBERS)]
    cases = hand_written() + scan_cases() + sweep + [mutated(*m) for m in drawn]
    rows = run_corpus(cases, tmp_path_factory.mktemp("faults"))
    report = table(rows)
    with capsys.disabled():
        print("\n" + report)
    assert all(outcome == "clean" for _, outcome, _ in rows), report
    assert len(rows) >= 150
