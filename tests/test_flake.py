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


def test_every_dask_cluster_a_test_starts_listens_on_a_free_port():
    """Two xdist workers each starting a LocalCluster at once: dashboard_address=None still meant Dask's default
    port 8787, and the second cluster failed ("Port 8787 is already in use") when they overlapped. A cluster a
    test starts asks for a free loopback port ("127.0.0.1:0")."""
    import re
    from pathlib import Path

    found = []
    for path in Path(__file__).parent.rglob("*.py"):
        text = path.read_text(encoding="utf-8")
        for m in re.finditer(r"LocalCluster\((.*?)\) as", text, flags=re.S):
            found.append((path.name, 'dashboard_address="127.0.0.1:0"' in m[1]))
        # and a cluster file a test starts (--cluster-config): the misspelt-kwargs case started a LocalCluster
        # on 8787 and, beside a benchmark's cluster, failed with "Port 8787 is already in use" (stop 100)
        for m in re.finditer(r'class: LocalCluster\\n(?:"\s*")?kwargs: \{(.*?)\}', text):  # one string or two
            found.append((path.name, re.search(r"dashboard_address: .?127\.0\.0\.1:0", m[1]) is not None))
    assert len(found) >= 4 and all(ok for _, ok in found), found
