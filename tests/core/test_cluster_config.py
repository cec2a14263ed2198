"""``--cluster-config``: the clusters docs/tutorials/cluster.md documents are built from the files it shows
(``volanim samples cluster``'s): dask-jobqueue's job scripts written, dask-kubernetes' DaskCluster resource
made, no job started; a LocalCluster file runs a sequence that equals one worker's, its dashboard said and
served; bad files say which file, which key and what to write."""

from __future__ import annotations

import json
import re
import urllib.request

import numpy as np
import pytest
import yaml

from paths import ASSETS, REPO, WALK
from volanim_core.cli import main
from volanim_core.cluster_config import read_cluster_spec, started_cluster
from volanim_core.errors import FormatError

PAGE = REPO / "docs" / "tutorials" / "cluster.md"


def documented(kind: str, tmp_path):
    """``cluster-KIND.yaml`` as ``volanim samples cluster`` writes it; the page shows the same cluster."""
    assert main(["samples", "cluster", "-o", str(tmp_path)]) == 0
    path = tmp_path / f"cluster-{kind}.yaml"
    blocks = [yaml.safe_load(b) for b in re.findall(r"```yaml\n(.*?)```", PAGE.read_text(encoding="utf-8"), re.S)]
    assert yaml.safe_load(path.read_text(encoding="utf-8")) in blocks, f"the page shows {path.name}"
    return path


@pytest.mark.parametrize("kind, header", [("slurm", "#SBATCH"), ("pbs", "#PBS")])
def test_the_documented_job_queue_clusters_are_built_and_write_their_job_scripts(tmp_path, kind, header):
    """The cluster object itself is made (its scheduler starts on this machine, as on a login node); n_workers
    is set to 0 here so no job is submitted (there is no queue on this machine)."""
    spec = read_cluster_spec(documented(kind, tmp_path))
    kwargs = {**spec.kwargs, "n_workers": 0, "scheduler_options": {"host": "127.0.0.1", "dashboard_address": ":0"}}
    with spec.cluster_class()(*spec.args, **kwargs) as cluster:
        script = cluster.job_script()
    assert header in script and "distributed.cli.dask_worker" in script
    assert "source ~/volanim/.venv/bin/activate" in script  # what every worker needs, from the page
    assert "--nworkers" in script and spec.kwargs["n_workers"] > 0
    memory = spec.kwargs["memory"].replace("GB", "G")
    assert memory in script, script


def test_the_documented_kubernetes_cluster_makes_its_dask_cluster_resource(tmp_path):
    """KubeCluster talks to a Kubernetes API when made; the resource it would create is made by its own
    make_cluster_spec from the same options, and the class resolves."""
    from dask_kubernetes.operator import KubeCluster, make_cluster_spec

    spec = read_cluster_spec(documented("kubernetes", tmp_path))
    assert spec.cluster_class() is KubeCluster
    resource = make_cluster_spec(**spec.kwargs)
    worker = resource["spec"]["worker"]
    assert resource["kind"] == "DaskCluster" and worker["replicas"] == spec.kwargs["n_workers"]
    container = worker["spec"]["containers"][0]
    assert container["image"] == spec.kwargs["image"] and {"name": "EXTRA_PIP_PACKAGES", "value": "volanim"} in \
        container["env"]
    assert container["resources"]["limits"]["memory"] == "3Gi"


def test_a_local_cluster_file_serves_its_dashboard_while_open(tmp_path):
    path = tmp_path / "local.yaml"
    path.write_text(yaml.safe_dump({"version": 1, "module": "distributed", "class": "LocalCluster", "kwargs": {
        "n_workers": 1, "threads_per_worker": 1, "host": "127.0.0.1", "dashboard_address": "127.0.0.1:0"}}))
    said = []
    with started_cluster(path, say=said.append) as client:
        (line,) = said
        link = re.search(r"dashboard (http://\S+)", line)[1]
        with urllib.request.urlopen(link, timeout=30) as page:
            assert page.status == 200
        assert client.submit(sum, [1, 2]).result() == 3
    assert line.startswith(f"started LocalCluster from {path}")


@pytest.mark.slow
def test_a_sequence_on_a_cluster_config_equals_one_worker_s(tmp_path, capsys):
    path = documented("local", tmp_path)  # two workers, the dashboard on a free port
    common = [str(ASSETS / "mannequin.0.50.connect"), str(WALK), "--bones",
              str(ASSETS / "mannequin.bones"), "--frames", "0:240:40", "--mode", "bone"]
    assert main(["sequence", *common, "--workers", "1", "-o", str(tmp_path / "one.zarr")]) == 0
    assert main(["sequence", *common, "--cluster-config", str(path), "-o", str(tmp_path / "dask.zarr")]) == 0
    captured = capsys.readouterr()
    assert f"started LocalCluster from {path}; dashboard http://" in captured.err
    assert "Dask, 2 workers" in captured.out
    one, dask = ((tmp_path / n / "volanim-frames.jsonl").read_text().splitlines() for n in ("one.zarr", "dask.zarr"))
    sha = [[json.loads(r)["sha256"] for r in rows] for rows in (one, dask)]
    assert len(sha[0]) == 6 and sorted(sha[0]) == sorted(sha[1]) and len(set(sha[0])) == 6
    assert np.all(np.asarray(sha[0]) != "")


@pytest.mark.parametrize("text, says", [
    ("version: 1\nmodule: distributed\nclass: [LocalCluster\n",
     r"c\.yaml:4: not YAML: expected ',' or '\]'.*\(while parsing a flow sequence at line 3\)"),
    ("- a list\n", "a YAML mapping, like"),
    ("module: distributed\nclass: LocalCluster\n", "'version' is None: volanim reads version 1"),
    ("version: 1\nclass: LocalCluster\n", "'module' must be a Python module"),
    ("version: 1\nmodule: distributed\nclass: LocalCluster\nn_workers: 2\n", "unknown key.*n_workers.*under kwargs"),
    ("version: 1\nmodule: distributed\nclass: LocalCluster\nkwargs: [2]\n", "'kwargs' must be a mapping"),
    ("version: 1\nmodule: volanim_no_such_module\nclass: SLURMCluster\n",
     "cannot be imported.*pip install volanim_no_such_module"),
    ("version: 1\nmodule: distributed\nclass: LocalClustr\n", "module distributed has no class 'LocalClustr'"),
    ("version: 1\nmodule: distributed\nclass: LocalCluster\n"
     "kwargs: {n_wrkers: 2, dashboard_address: '127.0.0.1:0'}\n",
     "distributed.LocalCluster refused its kwargs.*n_wrkers"),
])
def test_a_bad_cluster_file_is_refused_naming_the_file_and_what_to_write(tmp_path, capsys, text, says):
    path = tmp_path / "c.yaml"
    path.write_text(text, encoding="utf-8")
    args = ["sequence", str(ASSETS / "mannequin.0.50.connect"), str(WALK), "--bones",
            str(ASSETS / "mannequin.bones"), "--frames", "0:20:10", "--mode", "bone", "--cluster-config", str(path),
            "-o", str(tmp_path / "w.zarr")]
    assert main(args) == 2
    error = capsys.readouterr().err.strip().splitlines()
    message = next(line for line in error if "error:" in line) + "\n".join(error)
    assert str(path) in message and re.search(says, message, flags=re.S), message
    assert not (tmp_path / "w.zarr").exists()
    with pytest.raises(FormatError):
        with started_cluster(path, say=lambda _: None):
            pass
