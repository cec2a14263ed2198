"""tests/flake.py tells a flake (a result that changes between runs) from a defect (a test that fails every
run), from the JUnit reports pytest writes."""

from __future__ import annotations

import subprocess
import sys

from flake import compare, outcomes


def test_a_changed_result_is_a_flake_and_a_failure_every_run_is_a_defect():
    runs = [{"a": "passed", "b": "passed", "c": "failed", "d": "passed"},
            {"a": "passed", "b": "failed", "c": "failed"},
            {"a": "passed", "b": "passed", "c": "failed", "d": "passed"}]
    flaky, broken = compare(runs)
    assert flaky == {"b": ["passed", "failed", "passed"], "d": ["passed", "absent", "passed"]}
    assert broken == {"c": ["failed"] * 3}
    assert compare([{"a": "passed"}] * 3) == ({}, {})


def test_outcomes_are_read_from_the_report_pytest_writes(tmp_path):
    (tmp_path / "test_three.py").write_text(
        "import pytest\n"
        "def test_ok(): pass\n"
        "def test_bad(): assert False\n"
        "@pytest.mark.skip(reason='x')\n"
        "def test_skipped(): pass\n")
    junit = tmp_path / "r.xml"
    plugins = ["-p", "no:cacheprovider", "-p", "no:xvfb", "-p", "no:napari", "-p", "no:npe2"]
    subprocess.run([sys.executable, "-m", "pytest", "-q", *plugins, f"--junitxml={junit}", "-o", "addopts=",
                    "test_three.py"], cwd=tmp_path, capture_output=True)
    assert outcomes(junit) == {"test_three::test_ok": "passed", "test_three::test_bad": "failed",
                               "test_three::test_skipped": "skipped"}
